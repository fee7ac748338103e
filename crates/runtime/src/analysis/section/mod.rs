//! Poincaré surfaces of section of autonomous models of two degrees of
//! freedom at a fixed energy: the plane q_c + slope·q_o = value (a linear
//! function of the coordinates) crossed in one direction, each orbit
//! seeded on the plane by a point of its canonical chart with the missing
//! momentum solved from H = E.
//!
//! The chart is that of the linear canonical change Q_c = q_c + slope·q_o,
//! Q_o = q_o, P_c = p_c, P_o = p_o − slope·p_c: the plane is Q_c = value,
//! the section map is area-preserving in (Q_o, P_o), and with slope 0 they
//! are the other coordinate and its momentum. H is quadratic in the
//! momenta (the model files are checked for it), so along P_c it is
//! α P² + β P + γ, read exactly from three values; the root whose rate
//! Q_c' = ∂H/∂P_c = 2αP + β has the crossing's sign is taken. Crossings are
//! located on DOP853's dense output to 10⁻¹² in time (the integrator's
//! event location); each orbit reports how far its points drifted from
//! H = E and from the plane.

mod on_constraints;
mod study;

pub use study::{section_study, SectionOptions, SectionStudy};

use crate::analysis::Refusal;
use crate::ode::{Direction, Event, EventSettings, Integrator, Method, OdeError, Options};
use crate::registry::{Fixed, FixedSize, Model};
use rayon::prelude::*;

/// Where the section lies and how far each orbit is followed.
#[derive(Clone, Debug)]
pub struct SectionSettings {
    /// The plane a·q = value, a linear function of the coordinates, one
    /// coefficient per coordinate ([1, 0]: the first coordinate's plane;
    /// [1, −1]: equal coordinates). A constrained model's plane is one
    /// coordinate's.
    pub plane: Vec<f64>,
    pub value: f64,
    /// Crossings with a·q increasing (else decreasing).
    pub rising: bool,
    /// The energy of every orbit.
    pub energy: f64,
    /// Points per orbit (the seed included).
    pub crossings: usize,
    /// An orbit that has not crossed that often by this time stops there.
    pub t_max: f64,
    /// DOP853's tolerance.
    pub tol: f64,
    /// For a model with a fast phase, a slice of its period map: the
    /// orbit is sampled at the forcing's phase 2πt/T = `phase` (each seed
    /// at t = phase·T/2π), and its points within `slab` of the plane and
    /// moving in the direction asked are kept; `energy` is that of the
    /// averaged Hamiltonian H̄. Not used for autonomous models.
    pub phase: f64,
    pub slab: f64,
}

/// One orbit on the section.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SectionOrbit {
    /// The full state the orbit started from (on the plane, at H = E).
    pub start: Vec<f64>,
    /// (Q_o, P_o) at each crossing, the seed first (in the scene's CSV,
    /// not its summary).
    #[serde(skip)]
    pub points: Vec<[f64; 2]>,
    /// How many.
    pub crossings: usize,
    /// max |H − E| over its crossings (|H̄ − E| with a fast phase: H̄ is
    /// conserved to O(ε) only).
    pub energy_drift: f64,
    /// max |q_c − value| over its crossings (below `slab` for a slice of
    /// the period map).
    pub plane_distance: f64,
    /// Why the orbit ended: an orbit with fewer crossings than asked says why.
    pub end: OrbitEnd,
}

/// How an orbit of a section ended.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum OrbitEnd {
    /// It crossed the plane as often as asked.
    Complete,
    /// It had crossed the plane fewer times than asked by `t_max`.
    TimeLimit { t_max: f64 },
    /// A coordinate ran off past [`ESCAPE`] times the seed's scale: the
    /// orbit leaves along an open branch of the energy surface.
    Escaped {
        t: f64,
        coordinate: String,
        value: f64,
    },
    /// The step collapsed where the mass matrix is (nearly) singular, at
    /// the coordinates `at`: a singular point of the chart (a polar
    /// chart's pole, a rope of no length), which the orbit may pass in
    /// other coordinates but not in these.
    Singular { t: f64, at: Vec<(String, f64)> },
    /// The integrator could not follow it (a blow-up); the crossings
    /// before are kept.
    Failed {
        #[serde(serialize_with = "as_text")]
        error: OdeError,
    },
}

/// How far past the seeds' scale a coordinate (not an angle) may run
/// before its orbit is called escaped.
pub const ESCAPE: f64 = 1e3;

fn as_text<E: std::fmt::Display, Z: serde::Serializer>(e: &E, z: Z) -> Result<Z::Ok, Z::Error> {
    z.collect_str(e)
}

impl std::fmt::Display for OrbitEnd {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OrbitEnd::Complete => write!(f, "all its crossings"),
            OrbitEnd::TimeLimit { t_max } => write!(f, "fewer crossings than asked by t_max = {t_max}"),
            OrbitEnd::Escaped { t, coordinate, value } => write!(
                f,
                "escaped: {coordinate} = {value:.3e} at t = {t:.4} (an open branch of the energy surface)"
            ),
            OrbitEnd::Singular { t, at } => {
                let at: Vec<String> = at.iter().map(|(name, q)| format!("{name} = {q:.3e}")).collect();
                write!(
                    f,
                    "reached a singular point of the coordinates at t = {t:.4} ({}: the mass matrix is singular there)",
                    at.join(", ")
                )
            }
            OrbitEnd::Failed { error } => write!(f, "stopped: {error}"),
        }
    }
}

impl SectionOrbit {
    /// The orbit so far: its seed, as the first point.
    fn from_seed(seed: &[f64; 2], start: &[f64]) -> SectionOrbit {
        SectionOrbit {
            start: start.to_vec(),
            points: vec![*seed],
            crossings: 1,
            energy_drift: 0.0,
            plane_distance: 0.0,
            end: OrbitEnd::Complete,
        }
    }
}

/// Orbits of the section map of one model at one energy.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Section {
    pub model: String,
    /// The energy, of H ("H") or, with a fast phase, of the averaged H̄
    /// ("H̄").
    pub energy: f64,
    pub energy_of: &'static str,
    /// The plane, e.g. "x = 0 (increasing)", and with a fast phase the
    /// period map's phase and slab.
    pub plane: String,
    /// The names of the two axes on the plane, Q_o and P_o.
    pub axes: [String; 2],
    pub orbits: Vec<SectionOrbit>,
    /// max |H − E| and max |q_c − value| over every orbit's crossings.
    pub largest_energy_drift: f64,
    pub largest_plane_distance: f64,
    /// Each orbit's crossings' error: twice their largest distance on the
    /// plane to the same orbit's at a hundredth of the tolerance (∞ where
    /// the two have not as many crossings; empty: not checked).
    pub crossing_errors: Vec<f64>,
    /// The two runs compared, or why none was.
    pub crossing_check: Option<String>,
    /// Whether the `accuracy` asked for was reached, and at which tolerance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
}

impl Section {
    /// The crossings' errors from `again`, the same seeds at a hundredth
    /// of the tolerance.
    pub fn checked_against(&mut self, again: &Section) {
        self.crossing_errors = (self.orbits.iter())
            .zip(&again.orbits)
            .map(|(a, b)| match a.points.len() == b.points.len() {
                true => (a.points.iter().zip(&b.points))
                    .map(|(p, q)| 2.0 * (p[0] - q[0]).hypot(p[1] - q[1]))
                    .fold(0.0, f64::max),
                false => f64::INFINITY,
            })
            .collect();
    }

    /// The largest error of a crossing (∞ unchecked).
    pub fn largest_crossing_error(&self) -> f64 {
        match self.crossing_errors.is_empty() {
            true => f64::INFINITY,
            false => self.crossing_errors.iter().fold(0.0, |m: f64, &e| m.max(e)),
        }
    }
}

impl Section {
    /// The orbits that ended before their crossings, with why (index, end).
    pub fn ended_early(&self) -> impl Iterator<Item = (usize, &OrbitEnd)> {
        self.orbits
            .iter()
            .enumerate()
            .filter(|(_, o)| o.end != OrbitEnd::Complete)
            .map(|(k, o)| (k, &o.end))
    }
}

/// Why a section cannot be drawn.
#[derive(Debug, thiserror::Error)]
pub enum SectionError {
    /// The analysis does not apply to this kind of model.
    #[error(transparent)]
    Refused(#[from] crate::analysis::Refusal),
    /// No seed: where the scene looked, the energy is nowhere accessible on
    /// the plane (or the plane is a singular point of the chart).
    #[error("model {model}: no seeds on the plane (is the energy accessible there, and is the plane not a singular point of the coordinates?)")]
    NoSeeds { model: String },
    /// No momentum puts the seed at the energy on the requested branch.
    #[error("seed ({}, {}): energy {energy} is not accessible there (the least H on the plane at this point is {least})", seed[0], seed[1])]
    Inaccessible {
        seed: [f64; 2],
        energy: f64,
        least: f64,
    },
    /// H is not a convex quadratic in the solved momentum (a coordinate
    /// singularity of the mass matrix at the seed).
    #[error("seed ({}, {}): H is not quadratic and convex in the momentum there (a singular point of the chart?)", seed[0], seed[1])]
    Singular { seed: [f64; 2] },
    /// A constrained model's seed with no consistent state on the plane.
    #[error("seed ({}, {}): no state on the constraints there: {source}", seed[0], seed[1])]
    Constraint {
        seed: [f64; 2],
        source: crate::ode::holonomic::ConstraintError,
    },
    /// A constrained model's start that cannot be put on its constraints.
    #[error("model '{model}': its start is not near its constraints: {source}")]
    Start {
        model: String,
        source: crate::ode::holonomic::ConstraintError,
    },
    #[error(transparent)]
    Plane(#[from] PlaneTextError),
    #[error("method: {0}")]
    Method(#[from] OdeError),
}

/// The section of `model` through `seeds` (other coordinate, its momentum).
pub fn section(
    model: &Model,
    params: &[f64],
    seeds: &[[f64; 2]],
    settings: &SectionSettings,
) -> Result<Section, SectionError> {
    if let Some(systems) = model.constrained {
        return on_constraints::section(model, systems, params, seeds, settings);
    }
    let work = Sections {
        model,
        params,
        seeds,
        settings,
    };
    // Compiled for 2 degrees of freedom only: the event location's
    // instances at the other sizes were compile time for nothing.
    let name = model.info.name.to_string();
    match model.sized {
        Some(FixedSize::Dof2(fixed)) => work.run::<_, 2, 4, 8, 20>(fixed),
        Some(_) if has_fast_phase(model) => Err(Refusal::FastPhase {
            model: name,
            instead: FAST_PHASE_SECTION,
        }
        .into()),
        Some(_) => Err(Refusal::Dimension {
            model: name,
            dof: model.info.coordinates.len(),
            analysis: "a section",
            supported: "2",
        }
        .into()),
        None => Err(SectionError::Refused(Refusal::contact_model(name))),
    }
}

/// The plane's coefficients as a section accepts them.
pub(super) const PLANE_COEFFICIENTS: &str =
    "the plane's coefficients must be finite and not both 0";

/// Why a model with a fast phase gets no seeds by energy.
pub(super) const NO_AVERAGED_HAMILTONIAN: &str =
    "its averaged Hamiltonian, which places seeds at an energy, is not derived";

/// Where a model with a fast phase has its section.
const FAST_PHASE_SECTION: &str = "its section is the period map (scenes period_map, chaos_map); slices of it are drawn for 2 degrees of freedom";

pub(super) fn has_fast_phase(model: &Model) -> bool {
    matches!(
        model.dynamic.kind(),
        crate::registry::Kind::Hamiltonian {
            fast_phase: true,
            ..
        }
    )
}

/// The energy that fixes a section's seeds: H, or the averaged H̄ for a
/// model with a fast phase (None where H̄ is not derived).
pub(super) fn seed_energy<'a>(
    model: &'a Model,
    params: &'a [f64],
) -> Option<impl Fn(&[f64]) -> f64 + Sync + 'a> {
    let fast = has_fast_phase(model);
    let zero = vec![0.0; 2 * model.info.coordinates.len()];
    if fast && model.dynamic.averaged_energy(params, &zero).is_none() {
        return None;
    }
    Some(move |y: &[f64]| match fast {
        true => model.dynamic.averaged_energy(params, y).unwrap_or(f64::NAN),
        false => model.dynamic.energy(params, 0.0, y),
    })
}

/// Where a model with a fast phase is sampled: at its period map's phase.
#[derive(Clone, Copy)]
struct Stroboscope {
    period: f64,
    /// The time of the first sample, phase·T/2π.
    start: f64,
    slab: f64,
}

/// The work of [`section`], run at 2 degrees of freedom.
pub struct Sections<'a> {
    model: &'a Model,
    params: &'a [f64],
    seeds: &'a [[f64; 2]],
    settings: &'a SectionSettings,
}

impl Sections<'_> {
    /// The section on the model at its size (called at 2 degrees of freedom).
    fn run<F: Fixed<D, S, T, V>, const D: usize, const S: usize, const T: usize, const V: usize>(
        self,
        fixed: &'static F,
    ) -> Result<Section, SectionError> {
        let info = fixed.info();
        let name = info.name.to_string();
        if D != 2 {
            return Err(Refusal::Dimension {
                model: name,
                dof: D,
                analysis: "a section",
                supported: "2",
            }
            .into());
        }
        let s = self.settings;
        let bad =
            |requirement: &'static str| SectionError::from(Refusal::setting(&name, requirement));
        if !(s.tol > 0.0 && s.t_max > 0.0 && s.energy.is_finite() && s.value.is_finite()) {
            return Err(bad(
                "the tolerance and t_max must be positive, the energy and value finite",
            ));
        }
        let chart = Chart::new(s, D, &fixed.periodic()).ok_or_else(|| bad(PLANE_COEFFICIENTS))?;
        let stroboscope = match fixed.has_fast_phase() {
            false => None,
            true => match fixed.phase_period(self.params) {
                Some(period) if period > 0.0 && s.phase.is_finite() && s.slab > 0.0 => {
                    Some(Stroboscope {
                        period,
                        start: s.phase / std::f64::consts::TAU * period,
                        slab: s.slab,
                    })
                }
                _ => return Err(bad("a positive slab and a finite phase")),
            },
        };
        let energy =
            seed_energy(self.model, self.params).ok_or_else(|| bad(NO_AVERAGED_HAMILTONIAN))?;
        let energy = |y: &[f64; S]| energy(y);
        let chart = chart.centred(|q| chart.least_energy(&[q, 0.0], &energy), s.energy);
        if self.seeds.is_empty() {
            return Err(SectionError::NoSeeds { model: name });
        }
        crate::budget::check(
            || format!("{} orbits of {} crossings", self.seeds.len(), s.crossings),
            self.seeds.len() as u128 * s.crossings as u128,
            2 * std::mem::size_of::<f64>(),
        )
        .map_err(OdeError::from)?;
        let names = info.state_names();
        let system = fixed.exact(self.params);
        let scale = self
            .seeds
            .iter()
            .flat_map(|seed| seed.iter())
            .fold(1.0, |m: f64, x| m.max(x.abs()));
        let orbit = OrbitRun {
            system: &system,
            chart,
            stroboscope,
            settings: s,
            energy: &energy,
            escape: ESCAPE * scale,
            names: &names[..D],
            periodic: &fixed.periodic(),
            conditioning: &|q: &[f64]| {
                let q: [f64; D] = std::array::from_fn(|i| q[i]);
                conditioning(&fixed.mass_matrix(self.params, &q))
            },
        };
        let orbits = self
            .seeds
            .par_iter()
            .map(|seed| orbit.follow(seed))
            .collect::<Result<Vec<_>, SectionError>>()?;
        let largest = |f: fn(&SectionOrbit) -> f64| orbits.iter().map(f).fold(0.0, f64::max);
        Ok(Section {
            largest_energy_drift: largest(|o| o.energy_drift),
            largest_plane_distance: largest(|o| o.plane_distance),
            crossing_errors: Vec::new(),
            crossing_check: None,
            accuracy: None,
            model: name,
            energy: s.energy,
            energy_of: if stroboscope.is_some() { "H̄" } else { "H" },
            plane: format!(
                "{} = {} ({}{})",
                plane_name(&s.plane, &names),
                short(s.value),
                if s.rising { "increasing" } else { "decreasing" },
                match stroboscope {
                    Some(strobe) =>
                        format!("; period map at phase {}, slab {}", s.phase, strobe.slab),
                    None => String::new(),
                }
            ),
            axes: chart.axes(&names),
            orbits,
        })
    }
}

/// One orbit's work: its system, plane, stroboscope and energy.
struct OrbitRun<'a, Y, const S: usize> {
    system: &'a Y,
    chart: Chart,
    stroboscope: Option<Stroboscope>,
    settings: &'a SectionSettings,
    energy: &'a (dyn Fn(&[f64; S]) -> f64 + Sync),
    /// A coordinate past this has escaped (see [`OrbitEnd::Escaped`]).
    escape: f64,
    /// The coordinates' names, and which are angles (never escaped).
    names: &'a [&'static str],
    periodic: &'a [bool],
    /// The mass matrix's smallest eigenvalue over its largest at q.
    conditioning: &'a (dyn Fn(&[f64]) -> f64 + Sync),
}

/// Below this ratio of a mass matrix's eigenvalues, a collapsed step is
/// put down to a singular point of the coordinates.
const SINGULAR_CONDITIONING: f64 = 1e-8;

/// The smallest eigenvalue of a symmetric 2 × 2 matrix over its largest
/// in magnitude (0 where it is singular, NaN where not finite).
fn conditioning<const D: usize>(m: &[[f64; D]; D]) -> f64 {
    if D != 2 {
        return f64::NAN;
    }
    let (a, b, d) = (m[0][0], 0.5 * (m[0][1] + m[1][0]), m[1][1]);
    let (mean, radius) = (0.5 * (a + d), (0.25 * (a - d) * (a - d) + b * b).sqrt());
    let (small, large) = ((mean - radius).abs(), (mean + radius).abs());
    small.min(large) / small.max(large)
}

impl<Y: crate::ode::System<S> + Sync, const S: usize> OrbitRun<'_, Y, S> {
    /// The crossings of the orbit through `seed`.
    fn follow(&self, seed: &[f64; 2]) -> Result<SectionOrbit, SectionError> {
        let (s, chart) = (self.settings, self.chart);
        let start = on_plane::<S>(seed, &chart, s, self.energy)?;
        if let Some(stroboscope) = self.stroboscope {
            return self.sample(seed, start, stroboscope);
        }
        let condition = move |_: f64, y: &[f64; S]| chart.offset(y);
        let direction = if chart.rising {
            Direction::Rising
        } else {
            Direction::Falling
        };
        let events = [Event::new(&condition).direction(direction).non_terminal()];
        let mut integrator = Integrator::new(Method::parse("dop853", s.tol)?)?;
        let mut orbit = SectionOrbit::from_seed(seed, &start);
        let (mut t, mut y) = (0.0, start);
        let chunk = (s.t_max / 64.0).max(1.0);
        while orbit.crossings < s.crossings && t < s.t_max {
            let t1 = (t + chunk).min(s.t_max);
            let run = match integrator.solve(
                self.system,
                t,
                &y,
                t1,
                Options::default().events(&events, EventSettings::default()),
            ) {
                Ok(run) => run,
                Err(error) => return Ok(self.ended(orbit, error)),
            };
            // A wrapped angle's jump at ±π is a crossing of the other side.
            let on_plane = run
                .hits
                .iter()
                .filter(|hit| chart.offset(&hit.y).abs() < 1e-6);
            for hit in on_plane.take(s.crossings - orbit.crossings) {
                self.keep(&mut orbit, &hit.y);
            }
            (t, y) = (run.t, run.y);
            if let Some(end) = self.escaped(t, &y) {
                orbit.end = end;
                return Ok(orbit);
            }
        }
        if orbit.crossings < s.crossings {
            orbit.end = OrbitEnd::TimeLimit { t_max: s.t_max };
        }
        Ok(orbit)
    }

    /// The orbit ended by the integrator's `error`: at a singular point of
    /// the coordinates, a coordinate run off, or a failure.
    fn ended(&self, mut orbit: SectionOrbit, error: OdeError) -> SectionOrbit {
        let d = self.names.len();
        orbit.end = match &error {
            OdeError::StepSizeUnderflow { t, y, .. }
                if y.len() >= d && (self.conditioning)(&y[..d]) < SINGULAR_CONDITIONING =>
            {
                OrbitEnd::Singular {
                    t: *t,
                    at: self
                        .names
                        .iter()
                        .map(|n| n.to_string())
                        .zip(y[..d].iter().copied())
                        .collect(),
                }
            }
            OdeError::StepSizeUnderflow { t, y, .. } if y.len() == S => {
                let y: [f64; S] = std::array::from_fn(|i| y[i]);
                self.escaped(*t, &y).unwrap_or(OrbitEnd::Failed { error })
            }
            _ => OrbitEnd::Failed { error },
        };
        orbit
    }

    /// The end of an orbit whose coordinate has run off, if one has.
    fn escaped(&self, t: f64, y: &[f64; S]) -> Option<OrbitEnd> {
        let (k, value) = y[..self.names.len()]
            .iter()
            .copied()
            .enumerate()
            .filter(|&(k, _)| !self.periodic[k])
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
        (value.abs() > self.escape).then(|| OrbitEnd::Escaped {
            t,
            coordinate: self.names[k].to_string(),
            value,
        })
    }

    /// Adds a state on the plane to the orbit, with its drifts.
    fn keep(&self, orbit: &mut SectionOrbit, y: &[f64; S]) {
        orbit.points.push(self.chart.point(y));
        orbit.crossings += 1;
        let drift = ((self.energy)(y) - self.settings.energy).abs();
        orbit.energy_drift = orbit.energy_drift.max(drift);
        orbit.plane_distance = orbit.plane_distance.max(self.chart.offset(y).abs());
    }

    /// The slice of the period map through `seed`: the orbit from `start`
    /// at the stroboscope's phase, its points within the slab and moving
    /// the way asked (the plane function's rate from the exact field).
    fn sample(
        &self,
        seed: &[f64; 2],
        start: [f64; S],
        stroboscope: Stroboscope,
    ) -> Result<SectionOrbit, SectionError> {
        let (s, chart) = (self.settings, self.chart);
        let d = S / 2;
        let mut integrator = Integrator::new(Method::parse("dop853", s.tol)?)?;
        let mut orbit = SectionOrbit::from_seed(seed, &start);
        let (mut t, mut y) = (stroboscope.start, start);
        let periods = ((s.t_max / stroboscope.period).ceil() as usize).max(1);
        let chunk = 1000.min(periods);
        let mut done = 0;
        while orbit.crossings < s.crossings && done < periods {
            let count = chunk.min(periods - done);
            let times: Vec<f64> = (1..=count)
                .map(|k| stroboscope.start + (done + k) as f64 * stroboscope.period)
                .collect();
            let states = match integrator
                .solve(
                    self.system,
                    t,
                    &y,
                    times.last().copied().unwrap_or(t),
                    Options::default().times(&times),
                )
                .map(|run| run.samples)
            {
                Ok(states) => states,
                Err(error) => return Ok(self.ended(orbit, error)),
            };
            for (&time, state) in times.iter().zip(&states) {
                if chart.offset(state).abs() >= stroboscope.slab || orbit.crossings == s.crossings {
                    continue;
                }
                let field = self.system.rhs(time, state);
                if (chart.rate(&field[..d]) > 0.0) == chart.rising {
                    self.keep(&mut orbit, state);
                }
            }
            done += count;
            (t, y) = (times[count - 1], states[count - 1]);
            if let Some(end) = self.escaped(t, &y) {
                orbit.end = end;
                return Ok(orbit);
            }
        }
        if orbit.crossings < s.crossings {
            orbit.end = OrbitEnd::TimeLimit { t_max: s.t_max };
        }
        Ok(orbit)
    }
}

/// The plane's canonical chart (module docs): a·q = value divided by a_c,
/// c the coordinate of the larger |a_c| and o the other, is
/// Q_c = q_c + slope·q_o = value, and Q_o = q_o, P_c = p_c,
/// P_o = p_o − slope·p_c.
#[derive(Clone, Copy, Debug)]
pub(super) struct Chart {
    c: usize,
    other: usize,
    slope: f64,
    value: f64,
    /// Q_c increasing (a·q's direction, turned if a_c < 0).
    pub(super) rising: bool,
    dof: usize,
    /// Q_c is an angle (q_c one, and slope a whole multiple of q_o's turn
    /// or 0): its offset from the plane is wrapped to [−π, π).
    wrap_plane: bool,
    /// Q_o is an angle: drawn on its circle about `centre`.
    wrap_other: bool,
    centre: f64,
}

impl Chart {
    /// None for a plane whose coefficients are not finite or both 0.
    pub(super) fn new(s: &SectionSettings, dof: usize, periodic: &[bool]) -> Option<Chart> {
        let a = &s.plane;
        if dof != 2
            || periodic.len() != 2
            || a.len() != 2
            || !a.iter().all(|x| x.is_finite())
            || a.iter().all(|&x| x == 0.0)
        {
            return None;
        }
        let c = if a[0].abs() >= a[1].abs() { 0 } else { 1 };
        let other = 1 - c;
        let slope = a[other] / a[c];
        let whole = slope == slope.round();
        Some(Chart {
            c,
            other,
            slope,
            value: s.value / a[c],
            rising: s.rising == (a[c] > 0.0),
            dof,
            wrap_plane: periodic[c] && (slope == 0.0 || (whole && periodic[other])),
            wrap_other: periodic[other],
            centre: 0.0,
        })
    }

    /// The state at (Q_o, P_o) = `seed` on the plane, with P_c = `p_c`.
    pub(super) fn state<const S: usize>(&self, seed: &[f64; 2], p_c: f64) -> [f64; S] {
        let d = self.dof;
        let mut y = [0.0; S];
        y[self.c] = self.value - self.slope * seed[0];
        y[self.other] = seed[0];
        y[d + self.c] = p_c;
        y[d + self.other] = seed[1] + self.slope * p_c;
        y
    }

    /// Q_c − value: an angle's wrapped to [−π, π), whose jump at ±π is a
    /// crossing of the opposite side (dropped by the callers).
    pub(super) fn offset(&self, y: &[f64]) -> f64 {
        let d = y[self.c] + self.slope * y[self.other] - self.value;
        if self.wrap_plane {
            crate::analysis::period_map::wrap_angle(d)
        } else {
            d
        }
    }

    /// The chart centred where its seeds are searched and its angle Q_o is
    /// drawn, [centre − π, centre + π): 0, or π where Q_o is an angle whose
    /// energy (the least H on the line P_o = 0, `least_at`) is accessible
    /// at π and not at 0, as a pendulum's hanging rod in angles from the
    /// upward vertical (about 0 its region would be cut in two at ±π).
    pub(super) fn centred(mut self, least_at: impl Fn(f64) -> f64, energy: f64) -> Chart {
        let pi = std::f64::consts::PI;
        if self.wrap_other && least_at(0.0) >= energy && least_at(pi) < energy {
            self.centre = pi;
        }
        self
    }

    pub(super) fn centre(&self) -> f64 {
        self.centre
    }

    /// Q_c' from the coordinates' rates q'.
    pub(super) fn rate(&self, q_rate: &[f64]) -> f64 {
        q_rate[self.c] + self.slope * q_rate[self.other]
    }

    /// (Q_o, P_o) of a state, Q_o on its circle about the centre if an
    /// angle.
    pub(super) fn point(&self, y: &[f64]) -> [f64; 2] {
        let d = self.dof;
        let q = match self.wrap_other {
            true => {
                self.centre + crate::analysis::period_map::wrap_angle(y[self.other] - self.centre)
            }
            false => y[self.other],
        };
        [q, y[d + self.other] - self.slope * y[d + self.c]]
    }

    /// [α, β, γ] of H along P_c at `seed`.
    pub(super) fn quadratic<const S: usize>(
        &self,
        seed: &[f64; 2],
        energy: &dyn Fn(&[f64; S]) -> f64,
    ) -> [f64; 3] {
        quadratic(|p| energy(&self.state(seed, p)))
    }

    /// The least H over P_c at `seed`: the energy is accessible there
    /// above it.
    pub(super) fn least_energy<const S: usize>(
        &self,
        seed: &[f64; 2],
        energy: &dyn Fn(&[f64; S]) -> f64,
    ) -> f64 {
        let [alpha, beta, zero] = self.quadratic(seed, energy);
        zero - beta * beta / (4.0 * alpha)
    }

    pub(super) fn axes(&self, names: &[&str]) -> [String; 2] {
        let d = self.dof;
        let momentum = match self.slope {
            0.0 => names[d + self.other].to_string(),
            k => format!(
                "{} {} {}{}",
                names[d + self.other],
                sign(-k),
                factor(k),
                names[d + self.c]
            ),
        };
        [names[self.other].to_string(), momentum]
    }
}

/// a·q as text, "x", "q1 − q2", "2·x + 0.5·y".
fn plane_name(a: &[f64], names: &[&str]) -> String {
    let mut text = String::new();
    for (k, name) in a.iter().zip(names) {
        if *k == 0.0 {
            continue;
        }
        if !text.is_empty() {
            text.push_str(&format!(" {} ", sign(*k)));
        } else if *k < 0.0 {
            text.push('−');
        }
        text.push_str(&factor(*k));
        text.push_str(name);
    }
    text
}

/// A plane written as a linear function of the coordinates' names, as in
/// "x", "q1 - q2", "x + 0.5*y" or "-2*y", as its coefficients.
pub fn parse_plane(text: &str, names: &[&str]) -> Result<Vec<f64>, PlaneTextError> {
    let bad = |problem: PlaneTextProblem| PlaneTextError {
        text: text.to_string(),
        problem,
    };
    let mut a = vec![0.0; names.len()];
    // Split into signed terms at + or − that do not follow an exponent's e.
    let mut terms: Vec<String> = vec![String::new()];
    let chars: Vec<char> = text.chars().filter(|c| !c.is_whitespace()).collect();
    for (i, &ch) in chars.iter().enumerate() {
        let exponent = i > 1 && matches!(chars[i - 1], 'e' | 'E') && chars[i - 2].is_ascii_digit();
        if (ch == '+' || ch == '-' || ch == '−') && i > 0 && !exponent {
            terms.push(String::new());
        }
        terms
            .last_mut()
            .unwrap()
            .push(if ch == '−' { '-' } else { ch });
    }
    for term in terms.iter().filter(|t| !t.is_empty()) {
        let (sign, body) = match term.strip_prefix('-') {
            Some(rest) => (-1.0, rest),
            None => (1.0, term.strip_prefix('+').unwrap_or(term)),
        };
        let (factor, name) = match body.split_once('*') {
            Some((k, name)) => (
                k.parse::<f64>()
                    .map_err(|_| bad(PlaneTextProblem::Coefficient))?,
                name,
            ),
            None => (1.0, body),
        };
        let index = names
            .iter()
            .position(|n| *n == name)
            .ok_or_else(|| bad(PlaneTextProblem::Term))?;
        a[index] += sign * factor;
    }
    if !a.iter().all(|x| x.is_finite()) || a.iter().all(|&x| x == 0.0) {
        return Err(bad(PlaneTextProblem::Zero));
    }
    Ok(a)
}

/// A plane's text that [`parse_plane`] cannot read.
#[derive(Debug, thiserror::Error)]
#[error("plane {text:?}: {problem}")]
pub struct PlaneTextError {
    pub text: String,
    pub problem: PlaneTextProblem,
}

/// What is wrong in a plane's text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PlaneTextProblem {
    #[error("a coefficient is not a number")]
    Coefficient,
    #[error("a term is not a coordinate's name (write k*name)")]
    Term,
    #[error("no coordinate with a finite coefficient other than 0")]
    Zero,
}

/// x to six significant digits at most (π as 3.14159).
pub(super) fn short(x: f64) -> String {
    let text = format!("{x}");
    if text.len() <= 8 {
        text
    } else if x.abs() >= 1e-3 && x.abs() < 1e6 {
        let fixed = format!("{x:.6}");
        fixed
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.5e}")
    }
}

/// "|k|·", or nothing for ±1.
fn factor(k: f64) -> String {
    match k.abs() {
        1.0 => String::new(),
        m => format!("{m}·"),
    }
}

fn sign(k: f64) -> char {
    if k < 0.0 {
        '−'
    } else {
        '+'
    }
}

/// The state on the plane at `seed` (Q_o, P_o) with P_c solved from H = E
/// on the settings' branch.
pub(super) fn on_plane<const S: usize>(
    seed: &[f64; 2],
    chart: &Chart,
    s: &SectionSettings,
    energy: &dyn Fn(&[f64; S]) -> f64,
) -> Result<[f64; S], SectionError> {
    let [alpha, beta, zero] = chart.quadratic(seed, energy);
    if !(alpha > 0.0) || !beta.is_finite() || !zero.is_finite() {
        return Err(SectionError::Singular { seed: *seed });
    }
    let discriminant = beta * beta - 4.0 * alpha * (zero - s.energy);
    if !(discriminant >= 0.0) {
        return Err(SectionError::Inaccessible {
            seed: *seed,
            energy: s.energy,
            least: zero - beta * beta / (4.0 * alpha),
        });
    }
    let root = discriminant.sqrt();
    let p_c = if chart.rising {
        (-beta + root) / (2.0 * alpha)
    } else {
        (-beta - root) / (2.0 * alpha)
    };
    Ok(chart.state(seed, p_c))
}

/// [α, β, γ] of H = α p² + β p + γ along one momentum, from its values at
/// p = −1, 0, 1 (exact: H is quadratic in the momenta).
pub(super) fn quadratic(h: impl Fn(f64) -> f64) -> [f64; 3] {
    quadratic_through([h(-1.0), h(0.0), h(1.0)])
}

/// [α, β, γ] of the quadratic through its values at p = −1, 0, 1.
fn quadratic_through([minus, zero, plus]: [f64; 3]) -> [f64; 3] {
    [0.5 * (plus + minus) - zero, 0.5 * (plus - minus), zero]
}

/// `count` seeds on the line P_o = 0 of the plane, evenly over the
/// stretch around 0 (π for an angle accessible there and not at 0) where
/// the energy is accessible (scanned on [−extent, extent] about it); none
/// where it is nowhere accessible.
pub fn seeds_across(
    model: &Model,
    params: &[f64],
    settings: &SectionSettings,
    extent: f64,
    count: usize,
) -> Vec<[f64; 2]> {
    if let Some(systems) = model.constrained {
        return on_constraints::seeds_across(model, systems, params, settings, extent, count);
    }
    let dof = model.info.coordinates.len();
    let Some(chart) = Chart::new(settings, dof, &model.dynamic.periodic()) else {
        return Vec::new();
    };
    let Some(energy) = seed_energy(model, params) else {
        return Vec::new();
    };
    let energy = |y: &[f64; 4]| energy(y);
    let least = |q: f64| chart.least_energy(&[q, 0.0], &energy);
    let centre = chart.centred(least, settings.energy).centre();
    seeds_on_line(least, centre, extent, settings.energy, count)
}

/// `count` seeds (q, 0) evenly over the stretch of [centre − extent,
/// centre + extent] around the centre where `least`(q) < `energy`, else
/// over its longest such stretch; none where there is none.
fn seeds_on_line(
    least: impl Fn(f64) -> f64,
    centre: f64,
    extent: f64,
    energy: f64,
    count: usize,
) -> Vec<[f64; 2]> {
    let grid = 2001;
    let q = |i: usize| centre - extent + 2.0 * extent * i as f64 / (grid - 1) as f64;
    // The accessible runs of the grid; the one around 0 (else the longest):
    // beyond a barrier the energy may be accessible again on an open branch.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for i in 0..grid {
        if least(q(i)) < energy {
            match runs.last_mut() {
                Some(run) if run.1 + 1 == i => run.1 = i,
                _ => runs.push((i, i)),
            }
        }
    }
    // Runs closed on both sides (by barriers of the energy, or singular
    // points of the chart where the least H is not finite) hold orbits
    // that recur; one that reaches the scan's edge may be open (the
    // swinging Atwood machine's r < 0, where orbits fall off to −∞).
    let closed: Vec<(usize, usize)> = runs
        .iter()
        .copied()
        .filter(|&(first, last)| first > 0 && last < grid - 1)
        .collect();
    let runs = if closed.is_empty() { runs } else { closed };
    let middle = (grid - 1) / 2;
    let Some(&(first, last)) = runs
        .iter()
        .find(|r| r.0 <= middle && middle <= r.1)
        .or_else(|| runs.iter().max_by_key(|r| r.1 - r.0))
    else {
        return Vec::new();
    };
    let (lo, hi) = (q(first), q(last));
    (0..count)
        .map(|k| [lo + (hi - lo) * (k as f64 + 0.5) / count as f64, 0.0])
        .filter(|&[q, _]| least(q) < energy)
        .collect()
}

impl Section {
    /// The orbits' points on the plane, one colour per orbit.
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{Figure, PanelSpec, Rgb};
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in self.orbits.iter().flat_map(|o| &o.points) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let pad = |k: usize| 0.05 * (hi[k] - lo[k]).max(1e-9);
        let title = format!(
            "{}: section {} at {} = {}, {} orbits",
            self.model,
            self.plane,
            self.energy_of,
            self.energy,
            self.orbits.len()
        );
        let [x, y] = [
            crate::registry::display_name(&self.axes[0]),
            crate::registry::display_name(&self.axes[1]),
        ];
        let spec = PanelSpec::new(
            &title,
            &x,
            &y,
            (lo[0] - pad(0), hi[0] + pad(0)),
            (lo[1] - pad(1), hi[1] + pad(1)),
        );
        let mut figure = Figure::grid(1, 1, 820, 720, &[spec]);
        for (k, orbit) in self.orbits.iter().enumerate() {
            let hue = k as f64 / self.orbits.len().max(1) as f64;
            let color = Rgb(
                (60.0 + 180.0 * hue) as u8,
                (40.0 + 120.0 * (1.0 - hue)) as u8,
                (200.0 - 150.0 * hue) as u8,
            );
            figure.points(0, orbit.points.iter().map(|p| (p[0], p[1])), color, 1);
        }
        // Orbits that ended early, counted by why, beside the picture.
        let count =
            |kind: fn(&OrbitEnd) -> bool| self.ended_early().filter(|(_, e)| kind(e)).count();
        let ends = [
            (
                count(|e| matches!(e, OrbitEnd::Singular { .. })),
                "reached a singular point of the coordinates",
            ),
            (
                count(|e| matches!(e, OrbitEnd::Escaped { .. })),
                "escaped along an open branch",
            ),
            (
                count(|e| matches!(e, OrbitEnd::TimeLimit { .. })),
                "had fewer crossings by t_max",
            ),
            (
                count(|e| matches!(e, OrbitEnd::Failed { .. })),
                "stopped by the integrator",
            ),
        ];
        let lines: Vec<(String, Rgb)> = ends
            .iter()
            .filter(|(n, _)| *n > 0)
            .map(|(n, why)| {
                (
                    format!("{n} of {} orbits {why}", self.orbits.len()),
                    Rgb(90, 90, 90),
                )
            })
            .collect();
        if !lines.is_empty() {
            figure.legend(0, &lines);
        }
        figure
    }
}
