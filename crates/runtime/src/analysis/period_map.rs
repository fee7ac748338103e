//! The period map of a T-periodic system and its orbits.

use crate::analysis::Refusal;
use crate::ode::{AnySystem, Integrator, Method, OdeError, Stats, System};
use crate::registry::Model;
use crate::settings::{method, resolve_axes, Axis, Declared, Range, SettingError, METHODS};
use rayon::prelude::*;
use std::f64::consts::PI;

pub use crate::ode::wrap_angle;

/// Advances `y` by one forcing period. The system is T-periodic, so every
/// period is integrated over [0, T]: no large times, no loss of phase accuracy.
pub fn period_map<S: System<N>, const N: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y: &[f64; N],
) -> Result<[f64; N], OdeError> {
    integrator.advance(system, 0.0, y, period)
}

/// `periods` iterates of the period map from `y0` (y0 first), with the
/// coordinates flagged in `wrap` given in [−π, π) (exact: the field is
/// 2π-periodic in them). With the Taylor method the steps run across the
/// periods' ends (see [`Integrator::stream`]); the state itself is
/// brought back only once it is past ±3π, a change that restarts the step
/// there, so an orbit about π is not cut at every period.
pub fn orbit<S: System<N>, const N: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y0: &[f64; N],
    periods: usize,
    wrap: &[bool],
) -> Result<Vec<[f64; N]>, OdeError> {
    orbit_budget(1, periods, N)?;
    let mut points = Vec::with_capacity(periods + 1);
    points.push(*y0);
    integrator.stream(system, y0, period, periods, &mut |y| {
        points.push(wrapped_point(y, wrap));
        true
    })?;
    Ok(points)
}

/// The point of the map at state `y`, its coordinates flagged in `wrap` in
/// [−π, π); `y`'s own are brought back only once past ±3π (a change of
/// the state restarts the Taylor step: see [`orbit`]).
pub fn wrapped_point<const N: usize>(y: &mut [f64; N], wrap: &[bool]) -> [f64; N] {
    let mut point = *y;
    wrap_point(y, wrap, &mut point);
    point
}

/// [`wrapped_point`] of a state of any length, written into `point`.
pub fn wrap_point(y: &mut [f64], wrap: &[bool], point: &mut [f64]) {
    point.copy_from_slice(y);
    for ((x, p), w) in y.iter_mut().zip(point).zip(wrap) {
        if *w {
            *p = wrap_angle(*p);
            if x.abs() > 3.0 * std::f64::consts::PI {
                *x = *p;
            }
        }
    }
}

/// [`orbit`] of a system of any size, each point (y0 first) handed to
/// `point` instead of kept; `point` says whether to go on.
pub fn stream_orbit(
    integrator: &mut Integrator,
    system: &dyn AnySystem,
    period: f64,
    y0: &[f64],
    periods: usize,
    wrap: &[bool],
    point: &mut dyn FnMut(&[f64]) -> bool,
) -> Result<(), OdeError> {
    if !point(y0) {
        return Ok(());
    }
    let mut wrapped = y0.to_vec();
    system.stream(integrator, y0, period, periods, &mut |y| {
        wrap_point(y, wrap, &mut wrapped);
        point(&wrapped)
    })
}

/// Orbits of many initial conditions in parallel, in input order, each with its statistics.
pub fn orbits<S: System<N> + Sync, const N: usize>(
    method: Method,
    system: &S,
    period: f64,
    initial: &[[f64; N]],
    periods: usize,
    wrap: &[bool],
) -> Result<Vec<Result<(Vec<[f64; N]>, Stats), OdeError>>, OdeError> {
    orbit_budget(initial.len(), periods, N)?;
    Ok(initial
        .par_iter()
        .map(|y0| {
            let mut integrator = Integrator::new(method)?;
            let points = orbit(&mut integrator, system, period, y0, periods, wrap)?;
            Ok((points, integrator.stats))
        })
        .collect())
}

/// Whether `count` orbits of `periods` periods of an `n`-number state fit
/// in the memory a run may keep.
fn orbit_budget(count: usize, periods: usize, n: usize) -> Result<(), OdeError> {
    crate::budget::check(
        || format!("the points of {count} orbit(s) of {periods} periods"),
        count as u128 * (periods as u128 + 1),
        n * std::mem::size_of::<f64>(),
    )?;
    Ok(())
}

crate::declare_settings! {
    /// Orbits of the period map of any model with a fast phase, projected
    /// on two state components.
    pub struct PeriodMapOptions for "period_map" {
        /// The state components [q; p] drawn, by index or name (auto: the
        /// first coordinate and its momentum, or velocity).
        axes: Option<[Axis; 2]> = None, Range::Any;
        /// Initial states [q; p], q,p;q,p (auto: `count` seeds on a line
        /// along the first axis).
        seeds: Option<Vec<Vec<f64>>> = None, Range::Any;
        /// Seeds on the line.
        count: usize = 24, Range::Count { min: 1, max: 100_000 };
        /// The line covers [−p_max, p_max] when the first axis is not an
        /// angle.
        p_max: f64 = 2.5, Range::Positive;
        /// Periods per orbit.
        periods: usize = 500, Range::Count { min: 1, max: 100_000_000 };
        /// The integration method.
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-10, Range::Positive;
        /// Orbits run again at a hundredth of the tolerance, spread over the
        /// seeds, to state the error of their drawn points (0: none).
        check: usize = 24, Range::Count { min: 0, max: 100_000 };
        /// The error wanted on the drawn points (auto: none asked, each
        /// checked orbit states its error). Given, `tol` is tightened a
        /// hundredfold until every checked orbit's points are within it, or
        /// the result says how many periods of each orbit are.
        accuracy: Option<f64> = None, Range::Positive;
    }
}

impl PeriodMapOptions {
    /// The settings of [`portrait`] for `model`, `auto` resolved.
    pub fn resolve(&self, model: &Model) -> Result<PortraitSettings, SettingError> {
        Ok(PortraitSettings {
            axes: resolve_axes(Self::ANALYSIS, model.info, &self.axes)?,
            seeds: self.seeds.clone(),
            count: self.count,
            p_max: self.p_max,
            periods: self.periods,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            check: self.check,
            accuracy: self.accuracy,
        })
    }
}

/// What [`portrait`] computes, resolved for one model from
/// [`PeriodMapOptions`].
#[derive(Clone, Debug)]
pub struct PortraitSettings {
    /// The state components ([q; p] indices) drawn.
    pub axes: [usize; 2],
    /// Initial states (full [q; p]); None: `count` seeds on a line along the
    /// first axis (over [−π, π) for an angle, [−p_max, p_max] otherwise)
    /// through the zero state; for a constrained model, along the second
    /// axis over ±p_max about the model file's start. A constrained model's
    /// seeds are made consistent in the chart of the two axes (their
    /// components held, the others moved onto the constraints).
    pub seeds: Option<Vec<Vec<f64>>>,
    pub count: usize,
    pub p_max: f64,
    pub periods: usize,
    pub method: Method,
    /// Orbits rerun at a hundredth of the tolerance (0: none).
    pub check: usize,
    /// The error wanted on the drawn points (None: stated, not chosen).
    pub accuracy: Option<f64>,
}

/// The error of one orbit's drawn points: twice their largest distance
/// (angles modulo 2π) to the same orbit run at a hundredth of the
/// tolerance.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct OrbitCheck {
    pub orbit: usize,
    pub error: f64,
    /// With an `accuracy`: the periods from the seed over which twice the
    /// distance stays within it (None: the whole orbit, or none asked). On
    /// a chaotic orbit it grows only as the logarithm of the tolerance.
    pub periods_within: Option<usize>,
}

/// An orbit that stopped: its index among the seeds and the integrator's
/// error (in a summary, `[index, "the error's text"]`).
#[derive(Clone, Debug, PartialEq)]
pub struct Stopped {
    pub orbit: usize,
    pub error: OdeError,
}

impl serde::Serialize for Stopped {
    fn serialize<Z: serde::Serializer>(&self, z: Z) -> Result<Z::Ok, Z::Error> {
        (self.orbit, self.error.to_string()).serialize(z)
    }
}

/// Orbits of the period map of any model with a fast phase, projected on
/// two state components (angles in [−π, π)); orbits that left the model's
/// domain are listed with their reason instead.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Portrait {
    pub model: String,
    pub params: std::collections::BTreeMap<String, f64>,
    pub axes: [String; 2],
    /// The axes in the figures' notation (φ₁, p_φ₁, φ₁′).
    #[serde(skip)]
    pub labels: [String; 2],
    pub seeds: Vec<Vec<f64>>,
    pub periods: usize,
    /// Orbits that stopped, with the reason (the others are in `orbits`).
    pub failed: Vec<Stopped>,
    /// The checked orbits' errors (empty: `check` = 0), and the two runs
    /// compared ("taylor, tol 1e-10 against taylor, tol 1e-12").
    pub checks: Vec<OrbitCheck>,
    pub check_runs: String,
    /// Whether the `accuracy` asked for was reached, and by which run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
    pub seconds: f64,
    /// Per seed, the projected points (empty for a failed orbit).
    #[serde(skip)]
    pub orbits: Vec<Vec<(f64, f64)>>,
}

/// Why an analysis of the period map ([`portrait`], the chaos map) cannot run.
#[derive(Debug, thiserror::Error)]
pub enum PeriodMapError {
    /// The analysis does not apply to this kind of model.
    #[error(transparent)]
    Refused(#[from] crate::analysis::Refusal),
    /// The plane's axes are not two different state components.
    #[error("model '{model}': {source}")]
    Plane {
        model: String,
        #[source]
        source: crate::registry::PlaneError,
    },
    /// A seed that cannot be made consistent with the constraints while
    /// its axes' components are held (a chart singular there, or no
    /// consistent state near).
    #[error("model '{model}': the seed {seed:?} cannot be put on the constraints in the chart of the axes: {source}")]
    Inconsistent {
        model: String,
        seed: Vec<f64>,
        #[source]
        source: crate::ode::holonomic::ConstraintError,
    },
    /// Only some tiles of a map were asked for: they are written, there is
    /// no map to return.
    #[error("the tiles asked for are written; run without `only` to merge them into the map")]
    Partial,
    /// The caller said to stop (a page that no longer waits for the map).
    #[error("stopped before the end: nobody waits for the map any more")]
    Cancelled,
    #[error(transparent)]
    Tile(#[from] super::tiles::TileError),
    #[error(transparent)]
    Ode(#[from] OdeError),
    /// A declared setting's value refused.
    #[error(transparent)]
    Setting(#[from] crate::settings::SettingError),
}

/// The iterates `transient + 1 ..= transient + record` of the period map
/// of `model` from each start, the full states (None for an orbit that
/// stopped): the Taylor method's run in the batch lanes, a constrained
/// model's starts put on its constraints first. `done` is called with the
/// number of orbits done as blocks of them end.
pub fn iterates_of_starts(
    model: &Model,
    params: &[f64],
    method: Method,
    starts: &[Vec<f64>],
    transient: usize,
    record: usize,
    done: &(dyn Fn(usize) + Sync),
) -> Result<Vec<Option<Vec<Vec<f64>>>>, PeriodMapError> {
    let systems = crate::analysis::flows(model)?;
    crate::analysis::method_applies(model, method)?;
    let info = systems.info();
    Refusal::named_values(info, params)?;
    let period = fast_phase_period(systems, params)?;
    let dim = systems.periodic_state().len();
    let mut flat = Vec::with_capacity(starts.len() * dim);
    for start in starts {
        if start.len() != dim {
            return Err(Refusal::state_length(info.name, "start", start.len(), dim).into());
        }
        let mut y = start.clone();
        systems
            .consistent(params, &mut y, &[])
            .map_err(|source| PeriodMapError::Inconsistent {
                model: info.name.into(),
                seed: start.clone(),
                source,
            })?;
        flat.extend(y);
    }
    orbit_budget(starts.len(), record, dim)?;
    let recording = crate::registry::Recording {
        transient,
        record,
        settle: None,
        known: None,
        done,
    };
    Ok(systems.iterates(params, method, period, &flat, &recording)?)
}

/// The orbits of `model` with parameter values `params`. With an
/// `accuracy`, the tolerance is tightened a hundredfold until every
/// checked orbit's points are within it.
pub fn portrait(
    model: &Model,
    params: &[f64],
    settings: &PortraitSettings,
) -> Result<Portrait, PeriodMapError> {
    let Some(accuracy) = settings.accuracy else {
        return portrait_once(model, params, settings);
    };
    // The seeds' size: a point is known to a few units of its rounding.
    let magnitude = (settings.seeds.iter().flatten().flatten())
        .map(|x| x.abs())
        .fold(settings.p_max.max(PI), f64::max);
    Refusal::accuracy_within_reach(
        model.info.name,
        "the points of the orbits",
        Some(accuracy),
        magnitude,
    )?;
    let settings = PortraitSettings {
        check: settings.check.max(1),
        ..settings.clone()
    };
    let (mut portrait, method, error, reached) = super::check::until_accurate(
        settings.method,
        accuracy,
        |method| {
            portrait_once(
                model,
                params,
                &PortraitSettings {
                    method,
                    ..settings.clone()
                },
            )
        },
        // No check (at the precision floor): the error is unknown.
        |portrait| match portrait.checks.is_empty() {
            true => f64::INFINITY,
            false => portrait.checks.iter().map(|c| c.error).fold(0.0, f64::max),
        },
    )?;
    let short: Vec<String> = (portrait.checks.iter())
        .filter_map(|c| {
            Some(format!(
                "orbit {} for {} periods",
                c.orbit, c.periods_within?
            ))
        })
        .collect();
    let within = match short.is_empty() {
        true => String::new(),
        false => format!(
            "; within it only {} (an orbit's error grows with its length, on a chaotic one exponentially)",
            short.join(", ")
        ),
    };
    portrait.accuracy = Some(format!(
        "accuracy {accuracy} {} with {}: the checked points within {error:.2e}{within}",
        super::check::reached_text(reached),
        method.describe()
    ));
    Ok(portrait)
}

/// [`portrait`] at the settings' method, its check included.
fn portrait_once(
    model: &Model,
    params: &[f64],
    settings: &PortraitSettings,
) -> Result<Portrait, PeriodMapError> {
    let systems = crate::analysis::flows(model)?;
    crate::analysis::method_applies(model, settings.method)?;
    let info = systems.info();
    let named = Refusal::named_values(info, params)?;
    let period = fast_phase_period(systems, params)?;
    let axes = plane_names(info, settings.axes)?;
    let wrap = systems.periodic_state();
    let constrained = model.constrained.is_some();
    let base = systems.base_state(params);
    let mut seeds = portrait_seeds(info.name, settings, &wrap, constrained.then_some(&base[..]))?;
    for seed in &mut seeds {
        let given = seed.clone();
        systems
            .consistent(params, seed, &settings.axes)
            .map_err(|source| PeriodMapError::Inconsistent {
                model: info.name.into(),
                seed: given,
                source,
            })?;
    }
    orbit_budget(seeds.len(), settings.periods, wrap.len())?;
    let start = std::time::Instant::now();
    let system = systems.exact(params);
    let run = |seeds: &[Vec<f64>], method: Method| -> Vec<Result<Vec<(f64, f64)>, OdeError>> {
        seeds
            .par_iter()
            .map(|y0| {
                let mut integrator = Integrator::new(method)?;
                let mut points = Vec::with_capacity(settings.periods + 1);
                let [a, b] = settings.axes;
                let mut keep = |y: &[f64]| {
                    points.push((y[a], y[b]));
                    true
                };
                stream_orbit(
                    &mut integrator,
                    &*system,
                    period,
                    y0,
                    settings.periods,
                    &wrap,
                    &mut keep,
                )?;
                Ok(points)
            })
            .collect()
    };
    let (mut projected, mut failed) = (Vec::new(), Vec::new());
    for (k, orbit) in run(&seeds, settings.method).into_iter().enumerate() {
        match orbit {
            Ok(points) => projected.push(points),
            Err(e) => {
                failed.push(Stopped { orbit: k, error: e });
                projected.push(Vec::new());
            }
        }
    }
    // The check: orbits spread over the seeds run again more tightly.
    let checked: Vec<usize> = super::check::sample_pixels(seeds.len(), settings.check)
        .into_iter()
        .filter(|&k| !projected[k].is_empty())
        .collect();
    // At the precision floor no tighter run exists: nothing is checked.
    let tighter = settings.method.check_run();
    let checked = if tighter.is_some() {
        checked
    } else {
        Vec::new()
    };
    let chosen: Vec<Vec<f64>> = checked.iter().map(|&k| seeds[k].clone()).collect();
    let wraps = settings.axes.map(|a| wrap[a]);
    let again = tighter.map_or_else(Vec::new, |tighter| run(&chosen, tighter));
    let checks = checked
        .iter()
        .zip(again)
        .filter_map(|(&k, again)| {
            let distances = distances(&projected[k], &again.ok()?, wraps);
            let error = 2.0 * distances.iter().fold(0.0, |m: f64, &d| m.max(d));
            let periods_within = settings
                .accuracy
                .and_then(|a| distances.iter().position(|&d| 2.0 * d > a));
            Some(OrbitCheck {
                orbit: k,
                error,
                periods_within,
            })
        })
        .collect();
    Ok(Portrait {
        model: info.name.into(),
        params: named,
        labels: settings.axes.map(|a| info.label(a)),
        axes,
        seeds,
        periods: settings.periods,
        failed,
        checks,
        check_runs: super::check::runs_compared(settings.method),
        accuracy: None,
        seconds: start.elapsed().as_secs_f64(),
        orbits: projected,
    })
}

/// The distance between two orbits' points, period by period, the
/// components flagged in `wrap` compared modulo 2π (NaN where the second
/// stopped first counts as infinitely far).
fn distances(orbit: &[(f64, f64)], again: &[(f64, f64)], wrap: [bool; 2]) -> Vec<f64> {
    let apart = |a: f64, b: f64, w: bool| if w { wrap_angle(a - b) } else { a - b };
    orbit
        .iter()
        .enumerate()
        .map(|(k, p)| match again.get(k) {
            Some(q) => apart(p.0, q.0, wrap[0]).hypot(apart(p.1, q.1, wrap[1])),
            None => f64::INFINITY,
        })
        .collect()
}

/// The period of the model's fast phase, or the refusal of a model
/// without one (no period map).
pub(crate) fn fast_phase_period(
    systems: &dyn crate::registry::Flows,
    params: &[f64],
) -> Result<f64, Refusal> {
    match systems.phase_period(params) {
        Some(t) if systems.has_fast_phase() => Ok(t),
        _ => Err(Refusal::no_fast_phase(systems.info().name)),
    }
}

/// The names of a plane's two state components, or the error naming the
/// model.
pub(crate) fn plane_names(
    info: &crate::registry::ModelInfo,
    axes: [usize; 2],
) -> Result<[String; 2], PeriodMapError> {
    info.plane(axes).map_err(|source| PeriodMapError::Plane {
        model: info.name.into(),
        source,
    })
}

/// The seeds a portrait asks for (each of the state's length), or `count`
/// of them on a line along the first axis; with a `base` state (a
/// constrained model's start), along the second axis about it.
fn portrait_seeds(
    model: &'static str,
    settings: &PortraitSettings,
    wrap: &[bool],
    base: Option<&[f64]>,
) -> Result<Vec<Vec<f64>>, Refusal> {
    let n = wrap.len();
    if let Some(seeds) = &settings.seeds {
        return match seeds.iter().find(|s| s.len() != n) {
            Some(s) => Err(Refusal::state_length(model, "seed", s.len(), n)),
            None => Ok(seeds.clone()),
        };
    }
    if let Some(base) = base {
        let axis = settings.axes[1];
        return Ok((0..settings.count)
            .map(|k| {
                let mut y = base.to_vec();
                let fraction = (k as f64 + 0.5) / settings.count.max(1) as f64;
                y[axis] += settings.p_max * (2.0 * fraction - 1.0);
                y
            })
            .collect());
    }
    let axis = settings.axes[0];
    let (lo, hi) = if wrap[axis] {
        (-PI, PI)
    } else {
        (-settings.p_max, settings.p_max)
    };
    Ok((0..settings.count)
        .map(|k| {
            let mut y = vec![0.0; n];
            y[axis] = lo + (hi - lo) * (k as f64 + 0.5) / settings.count.max(1) as f64;
            y
        })
        .collect())
}

impl Portrait {
    /// The orbits as dots, a colour per orbit, axes in the model's notation.
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{palette, Figure, PanelSpec};
        let range = |k: usize| {
            let values = self
                .orbits
                .iter()
                .flatten()
                .map(|p| if k == 0 { p.0 } else { p.1 });
            let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
            if lo > hi {
                (-1.0, 1.0)
            } else {
                (
                    lo - 0.05 * (hi - lo).max(1e-9),
                    hi + 0.05 * (hi - lo).max(1e-9),
                )
            }
        };
        let title = format!(
            "{}: period map, {} orbits × {} periods",
            self.model,
            self.orbits.len(),
            self.periods
        );
        let [x, y] = self.labels.clone();
        let mut figure =
            Figure::single(720, 620, PanelSpec::new(&title, &x, &y, range(0), range(1)));
        for (k, orbit) in self.orbits.iter().enumerate() {
            figure.points(0, orbit.iter().copied(), palette(k), 1);
        }
        figure
    }
}

impl crate::outputs::Outputs for Portrait {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        vec![("period_map.png".into(), self.figure())]
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let rows = self
            .orbits
            .iter()
            .enumerate()
            .flat_map(|(k, orbit)| orbit.iter().map(move |(a, b)| (k, *a, *b)));
        let header = ["orbit", self.axes[0].as_str(), self.axes[1].as_str()];
        vec![crate::outputs::Table::new("orbits.csv", &header, rows)]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines: Vec<String> = (self.failed.iter())
            .map(|stopped| format!("orbit {} stopped: {}", stopped.orbit, stopped.error))
            .collect();
        if self.checks.is_empty() && self.check_runs.contains("floor") {
            lines.push(format!(
                "the drawn points' error: not checked ({})",
                self.check_runs
            ));
        }
        if !self.checks.is_empty() {
            let mut errors: Vec<f64> = self.checks.iter().map(|c| c.error).collect();
            errors.sort_by(f64::total_cmp);
            let worst = (self.checks.iter())
                .max_by(|a, b| a.error.total_cmp(&b.error))
                .map_or(0, |c| c.orbit);
            lines.push(format!(
                "the drawn points' error ({} of {} orbits checked, {}): median {:.1e}, largest {:.1e} (orbit {worst})",
                self.checks.len(),
                self.orbits.len(),
                self.check_runs,
                errors[errors.len() / 2],
                errors[errors.len() - 1],
            ));
            // An error as large as the orbit: its points are right in
            // distribution only (a chaotic orbit's error grows exponentially).
            if errors[errors.len() - 1] > 1e-2 {
                lines.push(format!(
                    "orbit {worst}'s points are not individually right over the whole run: an orbit's error grows with its length, on a chaotic orbit exponentially (`accuracy` says for how many periods each is within it)"
                ));
            }
        }
        lines.extend(self.accuracy.clone());
        lines
    }
}
