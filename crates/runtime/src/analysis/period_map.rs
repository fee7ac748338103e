//! The period map of a T-periodic system and its orbits.

use crate::analysis::Refusal;
use crate::ode::{Integrator, Method, OdeError, Stats, System};
use crate::registry::Model;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Wraps an angle into [−π, π).
pub fn wrap_angle(x: f64) -> f64 {
    // Already in range: unchanged (the shift by π would round it).
    if (-PI..PI).contains(&x) {
        return x;
    }
    let two_pi = std::f64::consts::TAU;
    let w = (x + std::f64::consts::PI).rem_euclid(two_pi) - std::f64::consts::PI;
    // rem_euclid can return two_pi for tiny negative inputs.
    if w >= std::f64::consts::PI {
        w - two_pi
    } else {
        w
    }
}

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
    for ((x, p), w) in y.iter_mut().zip(&mut point).zip(wrap) {
        if *w {
            *p = wrap_angle(*p);
            if x.abs() > 3.0 * std::f64::consts::PI {
                *x = *p;
            }
        }
    }
    point
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

/// What [`portrait`] computes.
#[derive(Clone, Debug)]
pub struct PortraitSettings {
    /// The state components ([q; p] indices) drawn.
    pub axes: [usize; 2],
    /// Initial states (full [q; p]); None: `count` seeds on a line along the
    /// first axis (over [−π, π) for an angle, [−p_max, p_max] otherwise)
    /// through the zero state.
    pub seeds: Option<Vec<Vec<f64>>>,
    pub count: usize,
    pub p_max: f64,
    pub periods: usize,
    pub method: Method,
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
    pub seeds: Vec<Vec<f64>>,
    pub periods: usize,
    /// Orbits that stopped, with the reason (the others are in `orbits`).
    pub failed: Vec<Stopped>,
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
}

/// The orbits of `model` with parameter values `params`.
pub fn portrait(
    model: &Model,
    params: &[f64],
    settings: &PortraitSettings,
) -> Result<Portrait, PeriodMapError> {
    crate::registry::with_fixed(model, Portraits { params, settings })
        .ok_or_else(|| PeriodMapError::Refused(Refusal::contact_model(model.info.name)))?
}

/// The work of [`portrait`] at one size.
pub struct Portraits<'a> {
    params: &'a [f64],
    settings: &'a PortraitSettings,
}

impl crate::registry::WithFixed for Portraits<'_> {
    type Output = Result<Portrait, PeriodMapError>;
    fn run<
        F: crate::registry::Fixed<D, S, T, V>,
        const D: usize,
        const S: usize,
        const T: usize,
        const V: usize,
    >(
        self,
        model: &'static F,
    ) -> Self::Output {
        let info = model.info();
        let settings = self.settings;
        let params = Refusal::named_values(info, self.params)?;
        let period = match model.phase_period(self.params) {
            Some(t) if model.has_fast_phase() => t,
            _ => return Err(PeriodMapError::Refused(Refusal::no_fast_phase(info.name))),
        };
        let axes = info
            .plane(settings.axes)
            .map_err(|source| PeriodMapError::Plane {
                model: info.name.into(),
                source,
            })?;
        let wrap = model.periodic_state();
        let seeds: Vec<[f64; S]> = match &settings.seeds {
            Some(seeds) => seeds
                .iter()
                .map(|s| {
                    s.as_slice()
                        .try_into()
                        .map_err(|_| Refusal::state_length(info.name, "seed", s.len(), S))
                })
                .collect::<Result<_, _>>()?,
            None => {
                let axis = settings.axes[0];
                let (lo, hi) = if wrap[axis] {
                    (-PI, PI)
                } else {
                    (-settings.p_max, settings.p_max)
                };
                (0..settings.count)
                    .map(|k| {
                        let mut y = [0.0; S];
                        y[axis] = lo + (hi - lo) * (k as f64 + 0.5) / settings.count.max(1) as f64;
                        y
                    })
                    .collect()
            }
        };
        let start = std::time::Instant::now();
        let runs = orbits(
            settings.method,
            &model.exact(self.params),
            period,
            &seeds,
            settings.periods,
            &wrap,
        )?;
        let (mut projected, mut failed) = (Vec::new(), Vec::new());
        for (k, run) in runs.into_iter().enumerate() {
            match run {
                Ok((points, _)) => projected.push(
                    points
                        .iter()
                        .map(|y| (y[settings.axes[0]], y[settings.axes[1]]))
                        .collect(),
                ),
                Err(e) => {
                    failed.push(Stopped { orbit: k, error: e });
                    projected.push(Vec::new());
                }
            }
        }
        Ok(Portrait {
            model: info.name.into(),
            params,
            axes,
            seeds: seeds.iter().map(|s| s.to_vec()).collect(),
            periods: settings.periods,
            failed,
            seconds: start.elapsed().as_secs_f64(),
            orbits: projected,
        })
    }
}

impl Portrait {
    /// The orbits as dots, a colour per orbit, axes in the model's notation.
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{palette, Figure, PanelSpec};
        use crate::registry::display_name;
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
        let (x, y) = (display_name(&self.axes[0]), display_name(&self.axes[1]));
        let mut figure =
            Figure::single(720, 620, PanelSpec::new(&title, &x, &y, range(0), range(1)));
        for (k, orbit) in self.orbits.iter().enumerate() {
            figure.points(0, orbit.iter().copied(), palette(k), 1);
        }
        figure
    }
}
