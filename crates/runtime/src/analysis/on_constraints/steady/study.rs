//! The steady-motion analysis by name (`steady_motion`): what to hold and
//! what to linearise, found from the model where the user does not say,
//! then the linearisation at one speed and against the speed.
//!
//! Found, not guessed: starting from no shape and the speed alone, each
//! refusal of [`steady_motion`] names what is missing. A coordinate whose
//! move changes the motion (`NotSymmetric`) joins the shape; a rate the
//! constraints leave free (`Undetermined`) is held at its value in the
//! model file's start (0 for a motion that goes straight) and linearised
//! with the rest. The loop ends in the linearisation or in a refusal that
//! no addition mends (a state that is not steady, a position the
//! constraints do not fix).

use serde::Serialize;

use super::{
    free, speed_sweep, steady_motion, sweep_with, SpeedSweep, SteadyMotion, SteadyMotionError,
    SteadySettings,
};
use crate::analysis::Refusal;
use crate::registry::{ConstrainedSystems, Kind, Model};
use crate::settings::{Declared, Range, SettingError};

crate::declare_settings! {
    /// The linearisation of a steady motion (a bicycle riding upright, a
    /// sleigh gliding straight, a disk rolling upright, a top precessing
    /// steadily): the eigenvalues with their errors and the verdict at one
    /// speed, then against the speed with the stability boundaries.
    pub struct SteadyMotionOptions for "steady_motion" {
        /// The coordinate whose rate is the family's speed (auto: the
        /// first for which a steady motion is found).
        speed: Option<String> = None, Range::Any;
        /// That rate on the motion linearised (auto: its value in `rates`,
        /// or 1 where that is 0).
        at: Option<f64> = None, Range::Any;
        /// The coordinates' rates on the motion, the speed's replaced by
        /// `at` and the shape's by 0 (auto: all 0): a top's spin.
        rates: Option<Vec<f64>> = None, Range::Any;
        /// The configuration (auto: the model file's start; without
        /// constraints 0.3, 0.5, 0.7, …). A constrained model's is taken as
        /// it is; a model without constraints has its shape moved from it
        /// by Newton's method until the motion is steady.
        start: Option<Vec<f64>> = None, Range::Any;
        /// The shape: the coordinates that stay still along the motion and
        /// on which its equations depend (auto: found by moving each).
        shape: Option<Vec<String>> = None, Range::Any;
        /// Speeds in the sweep (0: none).
        sweep: usize = 101, Range::Count { min: 0, max: 100_000 };
        /// The sweep's first and last speed (auto: from −2 to 2 times `at`).
        sweep_range: Option<[f64; 2]> = None, Range::Any;
        /// The error wanted on the eigenvalues (auto: none asked; each
        /// comes with its error). The linearisation is exact to rounding,
        /// so nothing can tighten it: the result says whether the errors
        /// are within it, and a request below double precision's reach is
        /// refused.
        accuracy: Option<f64> = None, Range::Positive;
    }
}

/// The steady motion linearised at one speed and along the family.
#[derive(Clone, Debug, Serialize)]
pub struct SteadyStudy {
    pub model: &'static str,
    /// The coordinate whose rate is the speed.
    pub speed: String,
    /// Its rate on the motion linearised.
    pub at: f64,
    /// The shape, given or found.
    pub shape: Vec<String>,
    /// The other rates held (at their start values) because the
    /// constraints leave them free.
    pub held: Vec<String>,
    pub motion: SteadyMotion,
    /// With an `accuracy`, whether every eigenvalue's error is within it.
    pub accuracy: Option<String>,
    pub sweep: Option<SpeedSweep>,
}

/// Why the steady-motion analysis gave no result.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SteadyError {
    #[error(transparent)]
    Motion(#[from] SteadyMotionError),
    #[error(transparent)]
    Setting(#[from] SettingError),
    #[error(transparent)]
    Refused(#[from] Refusal),
    /// A model without constraints whose every coordinate moves its
    /// equations: no cyclic coordinate to advance.
    #[error("model '{model}': every coordinate moves the model's equations: no cyclic coordinate's rate can be a steady motion's speed (its equilibria: `explore`)")]
    NoCyclic { model: &'static str },
    /// No coordinate's rate gives a steady motion from the start: the
    /// last coordinate tried and why.
    #[error("model '{model}': no coordinate's rate gives a steady motion from the model file's start (name one with `speed`); the last tried, '{tried}': {reason}")]
    NoSpeed {
        model: &'static str,
        tried: String,
        reason: Box<SteadyMotionError>,
    },
}

/// What both kinds of model's families are found from: the parameters,
/// the settings, the shape and speed given (None: to be found), the
/// rates, the speed's rate on the motion linearised (by coordinate) and
/// the sweep's speeds (around that rate).
struct Request<'a> {
    params: &'a [f64],
    options: &'a SteadyMotionOptions,
    shape: Option<Vec<usize>>,
    speed: Option<usize>,
    rates: &'a [f64],
    at_of: &'a dyn Fn(usize) -> f64,
    speeds: &'a dyn Fn(f64) -> Vec<f64>,
}

/// A family of steady motions found: its speed, shape and held rates,
/// the linearisation at `at`, and the sweep.
struct Family {
    speed: usize,
    shape: Vec<usize>,
    held: Vec<usize>,
    motion: SteadyMotion,
    sweep: Option<SpeedSweep>,
}

/// The steady-motion analysis of `options` on `model`.
pub fn steady_study(
    model: &'static Model,
    params: &[f64],
    options: &SteadyMotionOptions,
) -> Result<SteadyStudy, SteadyError> {
    let info = model.info;
    let names = info.coordinates;
    let index = |name: &str, setting: &'static str| {
        names
            .iter()
            .position(|c| *c == name)
            .ok_or_else(|| SettingError::UnknownCoordinate {
                analysis: SteadyMotionOptions::ANALYSIS,
                name: setting,
                value: name.to_string(),
                model: info.name,
                known: names,
            })
    };
    let shape = match &options.shape {
        Some(given) => Some(
            given
                .iter()
                .map(|c| index(c, "shape"))
                .collect::<Result<Vec<_>, _>>()?,
        ),
        None => None,
    };
    let speed = options
        .speed
        .as_deref()
        .map(|s| index(s, "speed"))
        .transpose()?;
    for (name, given) in [("rates", &options.rates), ("start", &options.start)] {
        if let Some(values) = given.as_ref().filter(|v| v.len() != names.len()) {
            return Err(SettingError::OutOfRange {
                analysis: SteadyMotionOptions::ANALYSIS,
                name,
                value: format!("{values:?}"),
                range: format!("one value per coordinate ({})", names.join(", ")),
            }
            .into());
        }
    }
    let rates = options
        .rates
        .clone()
        .unwrap_or_else(|| vec![0.0; names.len()]);
    let at_of = |i: usize| {
        options
            .at
            .unwrap_or(if rates[i] != 0.0 { rates[i] } else { 1.0 })
    };
    let speeds = |at: f64| -> Vec<f64> {
        let [first, last] = options
            .sweep_range
            .unwrap_or([-2.0 * at.abs(), 2.0 * at.abs()]);
        let count = options.sweep;
        (0..count)
            .map(|k| first + (last - first) * k as f64 / (count.max(2) - 1) as f64)
            .collect()
    };
    let request = Request {
        params,
        options,
        shape,
        speed,
        rates: &rates,
        at_of: &at_of,
        speeds: &speeds,
    };
    let family = match (model.constrained, model.dynamic.kind()) {
        (Some(constrained), _) => {
            constrained_family(constrained, &request)?
        }
        (None, Kind::Hamiltonian { fast_phase: true, .. }) => {
            return Err(Refusal::Setting {
                model: info.name.into(),
                requirement: "steady_motion needs equations that do not change with time, and this model has a fast phase (its periodic orbits: `continuation`, `stability`)",
            }
            .into())
        }
        (None, Kind::Hamiltonian { .. }) => {
            free_family(model, &request)?
        }
        (None, _) => {
            return Err(Refusal::Setting {
                model: info.name.into(),
                requirement: "steady_motion does not run on a contact model (its motions switch between sticking and slipping)",
            }
            .into())
        }
    };
    let at = at_of(family.speed);
    let accuracy = match options.accuracy {
        None => None,
        Some(wanted) => Some(accuracy_reached(info.name, &family.motion, wanted)?),
    };
    Ok(SteadyStudy {
        model: info.name,
        speed: names[family.speed].into(),
        at,
        shape: family.shape.iter().map(|&i| names[i].to_string()).collect(),
        held: family.held.iter().map(|&i| names[i].to_string()).collect(),
        motion: family.motion,
        accuracy,
        sweep: family.sweep,
    })
}

/// A constrained model's family: its configuration as given, the shape
/// and the rates to hold found from the refusals ([`found`]).
fn constrained_family(
    model: &dyn ConstrainedSystems,
    request: &Request,
) -> Result<Family, SteadyError> {
    let (params, options, at_of) = (request.params, request.options, request.at_of);
    let (shape, speed) = (request.shape.clone(), request.speed);
    let n = model.info().coordinates.len();
    let q = options
        .start
        .clone()
        .unwrap_or_else(|| model.start(params)[..n].to_vec());
    let find = |speed: usize| {
        let held = vec![(speed, at_of(speed))];
        found(model, params, &q, request.rates, shape.clone(), held)
    };
    let (speed, (shape, held, motion)) = match speed {
        Some(speed) => (speed, find(speed)?),
        None => first_speed(model, shape.as_deref(), &find)?,
    };
    let sweep = match options.sweep {
        0 => None,
        _ => {
            let mut held = held.clone();
            held[0].1 = 1.0; // the sweep scales the speed's rate
            let settings = SteadySettings {
                q: &q,
                shape: &shape,
                held: &held,
            };
            Some(speed_sweep(
                model,
                params,
                &settings,
                &(request.speeds)(at_of(speed)),
            )?)
        }
    };
    Ok(Family {
        speed,
        held: held[1..].iter().map(|h| h.0).collect(),
        shape,
        motion,
        sweep,
    })
}

/// A model without constraints: the shape the coordinates its equations
/// depend on, the speed the first cyclic one, the shape moved by Newton's
/// method until steady ([`free::free_steady_motion`]); the sweep follows
/// the family from each speed's motion to the next.
fn free_family(model: &Model, request: &Request) -> Result<Family, SteadyError> {
    let (params, at_of, rates) = (request.params, request.at_of, request.rates);
    let shape = request.shape.clone();
    let n = model.info.coordinates.len();
    let guess = request
        .options
        .start
        .clone()
        .unwrap_or_else(|| (0..n).map(|i| 0.3 + 0.2 * i as f64).collect());
    let shape = match shape {
        Some(shape) => shape,
        None => {
            let probe = free::with_rates(model, params, &guess, rates)?;
            free::dependent_coordinates(model, params, &probe)?
        }
    };
    let Some(speed) = request
        .speed
        .or_else(|| (0..n).find(|i| !shape.contains(i)))
    else {
        return Err(SteadyError::NoCyclic {
            model: model.info.name,
        });
    };
    let rates_at = |v: f64| {
        let mut r = rates.to_vec();
        r[speed] = v;
        shape.iter().for_each(|&i| r[i] = 0.0);
        r
    };
    let motion = free::free_steady_motion(model, params, &guess, &rates_at(at_of(speed)), &shape)?;
    let sweep = match request.options.sweep {
        0 => None,
        _ => {
            // From the last speed's motion, else from the motion at `at`
            // (a family that ended on the way may go on past a gap).
            let anchor = motion.state[..n].to_vec();
            let last = std::cell::RefCell::new(anchor.clone());
            let at = |v: f64| {
                let from_last = last.borrow().clone();
                let found =
                    free::free_steady_motion(model, params, &from_last, &rates_at(v), &shape)
                        .or_else(|_| {
                            free::free_steady_motion(model, params, &anchor, &rates_at(v), &shape)
                        })?;
                *last.borrow_mut() = found.state[..n].to_vec();
                Ok(found)
            };
            Some(sweep_with(&at, &(request.speeds)(at_of(speed)))?)
        }
    };
    Ok(Family {
        speed,
        held: (0..n)
            .filter(|i| *i != speed && !shape.contains(i))
            .collect(),
        shape,
        motion,
        sweep,
    })
}

/// What [`found`] finds: the shape, the held rates (the speed first) and
/// the linearisation.
type Found = (Vec<usize>, Vec<(usize, f64)>, SteadyMotion);

/// The first coordinate (outside a given shape) whose rate `find` turns
/// into a steady motion, with what it found; or the last refusal.
fn first_speed(
    model: &dyn ConstrainedSystems,
    shape: Option<&[usize]>,
    find: &dyn Fn(usize) -> Result<Found, SteadyMotionError>,
) -> Result<(usize, Found), SteadyError> {
    let names = model.info().coordinates;
    let mut last = None;
    for speed in (0..names.len()).filter(|i| shape.is_none_or(|s| !s.contains(i))) {
        match find(speed) {
            Ok(found) => return Ok((speed, found)),
            Err(e) => last = Some((speed, e)),
        }
    }
    let (tried, reason) = last.expect("a model has coordinates outside its shape");
    Err(SteadyError::NoSpeed {
        model: model.info().name,
        tried: names[tried].into(),
        reason: Box::new(reason),
    })
}

/// Whether every eigenvalue's error is within `wanted` (refused below
/// what double precision resolves on the linearisation's entries).
fn accuracy_reached(
    model: &'static str,
    motion: &SteadyMotion,
    wanted: f64,
) -> Result<String, Refusal> {
    let magnitude = motion.matrix.amax();
    Refusal::accuracy_within_reach(model, "the eigenvalues", Some(wanted), magnitude)?;
    let worst = motion.errors.iter().fold(0.0_f64, |m, e| m.max(*e));
    Ok(if worst <= wanted {
        format!("accuracy {wanted:e} reached: every eigenvalue's error is at most {worst:.1e}")
    } else {
        format!("accuracy {wanted:e} NOT reached: an eigenvalue's error is {worst:.1e} (ill-conditioned; the linearisation is already exact to rounding)")
    })
}

/// The linearisation with the speed held, the shape given or found and
/// every rate the constraints leave free held at its start value (see the
/// module's comment).
fn found(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    q: &[f64],
    start_rates: &[f64],
    given_shape: Option<Vec<usize>>,
    mut held: Vec<(usize, f64)>,
) -> Result<Found, SteadyMotionError> {
    let names = model.info().coordinates;
    let searching = given_shape.is_none();
    let mut shape = given_shape.unwrap_or_default();
    let index = |name: &str| names.iter().position(|c| *c == name);
    // Each pass adds one coordinate to the shape or one held rate.
    for _ in 0..=2 * names.len() {
        let settings = SteadySettings {
            q,
            shape: &shape,
            held: &held,
        };
        let refusal = match steady_motion(model, params, &settings) {
            Ok(motion) => return Ok((shape, held, motion)),
            Err(e) => e,
        };
        let new = |name: &str| {
            index(name).filter(|i| !shape.contains(i) && held.iter().all(|h| h.0 != *i))
        };
        match &refusal {
            SteadyMotionError::NotSymmetric { coordinate, .. } if searching => {
                // A held rate's coordinate may join the shape (its rate is
                // then the shape's); the speed's may not.
                let Some(i) = index(coordinate).filter(|i| !shape.contains(i) && *i != held[0].0)
                else {
                    return Err(refusal);
                };
                held.retain(|h| h.0 != i);
                shape.push(i);
            }
            SteadyMotionError::Undetermined { coordinate, .. } => {
                let Some(i) = new(coordinate) else {
                    return Err(refusal);
                };
                held.push((i, start_rates[i]));
            }
            _ => return Err(refusal),
        }
    }
    unreachable!("each pass adds a coordinate to the shape or the held rates")
}

impl SteadyStudy {
    /// The shape for titles: its coordinates, or that it has none.
    fn shape_text(&self) -> String {
        match self.shape.is_empty() {
            true => "no shape coordinate".into(),
            false => format!("shape {}", self.shape.join(", ")),
        }
    }
}

impl crate::outputs::Outputs for SteadyStudy {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        let Some(sweep) = &self.sweep else {
            return Vec::new();
        };
        let title = format!(
            "{}: linearised eigenvalues of the steady motion ({})",
            self.model,
            self.shape_text()
        );
        let label = format!("rate of {}", self.speed);
        vec![("eigenvalues.png".into(), sweep.figure(&title, &label))]
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let mut tables = vec![crate::outputs::Table::new(
            "linearisation.csv",
            &["re", "im", "error"],
            self.motion
                .eigenvalues
                .iter()
                .zip(&self.motion.errors)
                .map(|(&(re, im), &e)| (re, im, e)),
        )];
        if let Some(sweep) = &self.sweep {
            let rows = sweep
                .speeds
                .iter()
                .zip(sweep.eigenvalues.iter().zip(&sweep.errors))
                .flat_map(|(&v, (values, errors))| {
                    values
                        .iter()
                        .zip(errors)
                        .map(move |(&(re, im), &e)| (v, re, im, e))
                });
            let header = [self.speed.as_str(), "re", "im", "error"];
            tables.push(crate::outputs::Table::new("eigenvalues.csv", &header, rows));
        }
        tables
    }
    fn lines(&self) -> Vec<String> {
        let motion = &self.motion;
        let values: Vec<String> = motion
            .eigenvalues
            .iter()
            .zip(&motion.errors)
            .map(|((re, im), e)| format!("{re:.12} {im:+.12}i ± {e:.1e}"))
            .collect();
        let mut lines = vec![
            format!(
                "{}: steady motion at {}' = {} ({}; reduced state {}): {}",
                self.model,
                self.speed,
                self.at,
                self.shape_text(),
                motion.reduced.join(", "),
                motion.verdict
            ),
            format!("eigenvalues: {}", values.join(", ")),
        ];
        lines.extend(self.accuracy.clone());
        if let Some(sweep) = &self.sweep {
            lines.extend(sweep.boundaries.iter().map(|b| {
                let side = if b.unstable_below {
                    "unstable below, not above"
                } else {
                    "unstable above, not below"
                };
                format!(
                    "boundary at {}' = {:.12} ± {:.1e} ({side})",
                    self.speed, b.speed, b.error
                )
            }));
        }
        lines
    }
}
