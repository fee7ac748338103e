//! Running and analysing constrained models on their constraints: runs
//! with projection at each output time and their reactions, and the
//! Floquet multipliers on the constraints' tangent space
//! ([`monodromy_on_constraints`]); stabilisation by vibration in
//! [`vibration`] (the attractor of a period map on the constraints is
//! `analysis::attractor::on_constraints`).

pub mod steady;
pub mod vibration;

use nalgebra::DMatrix;

use crate::constrained::PASSING_TOLERANCE;
use crate::ode::holonomic::{restricted_monodromy, ConstraintError};
use crate::ode::{AnyOptions, AnySolution, AnySystem, Integrator, Method, OdeError};
use crate::registry::{ConstrainedSystems, ParameterError};

/// The monodromy matrix of the periodic orbit through the consistent state
/// `y0` restricted to the constraints' tangent space (2(n − k) for k
/// holonomic constraints): Zᵀ Φ Z with Z an orthonormal basis there, whose
/// eigenvalues are the Floquet multipliers on the constraints, without the
/// spurious ones of the directions the constraints forbid. Also the state
/// after the period.
pub fn monodromy_on_constraints(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    method: Method,
    period: f64,
    y0: &[f64],
) -> Result<(Vec<f64>, DMatrix<f64>), ConstrainedError> {
    let name = model.info().name;
    let mut integrator = Integrator::new(method)?;
    let (end, full) = model.monodromy(params, &mut integrator, period, y0)?;
    let basis =
        model
            .tangent_basis(params, 0.0, y0)?
            .ok_or_else(|| ConstrainedError::Constraint {
                model: name,
                t: 0.0,
                source: ConstraintError::Singular { q: y0.to_vec() },
            })?;
    Ok((end, restricted_monodromy(&full, &basis)))
}

/// Why a constrained run stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConstrainedError {
    #[error(transparent)]
    Ode(#[from] OdeError),
    /// No consistent state near the start, or degenerate constraints on
    /// the way (with the time).
    #[error("model '{model}' at t = {t}: {source}")]
    Constraint {
        model: &'static str,
        t: f64,
        source: ConstraintError,
    },
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// Output times that do not increase from the start.
    #[error("the output times must increase from t0 = {t0} and be finite")]
    Times { t0: f64 },
    /// The integration stopped where the constraints lose rank: a singular
    /// position of the mechanism (a four-bar's links aligned), which even
    /// the equations that pass them did not pass.
    #[error("model '{model}' stopped at t = {t}, at a singular position: its constraints' Jacobian, of rank {rank} at the start (smallest singular value {at_start:.1e}), has one of {smallest:.1e} there, so its rank drops; the equations made to pass singular positions did not pass this one ({source})")]
    SingularPosition {
        model: &'static str,
        t: f64,
        /// The constraints' rank at the start, and their singular value of
        /// that rank there and where the run stopped.
        rank: usize,
        at_start: f64,
        smallest: f64,
        source: OdeError,
    },
}

/// The constraints' rank at a regular state (singular values of G above
/// 1e-10 of the largest) and the smallest of those singular values.
fn regular_rank(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    t: f64,
    y: &[f64],
) -> Option<(usize, f64)> {
    let values = model.constraint_singular_values(params, t, y).ok()?;
    let largest = values.first().copied().filter(|v| *v > 0.0)?;
    let rank = values.iter().take_while(|&&v| v > 1e-10 * largest).count();
    Some((rank, values[rank - 1]))
}

/// A step size that underflowed, or a state that stopped being finite,
/// where the constraints have (nearly) lost rank, their `rank`-th singular
/// value below 1e-4 of its value at the start, is named as a singular
/// position; any other error is passed on.
fn named_singularity(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    regular: Option<(usize, f64)>,
    error: OdeError,
) -> ConstrainedError {
    let stopped = match &error {
        OdeError::StepSizeUnderflow { t, y, .. } => Some((*t, &y[..])),
        OdeError::NonFinite { t, y } => Some((*t, &y[..])),
        _ => None,
    };
    if let (Some((t, y)), Some((rank, at_start))) = (stopped, regular) {
        if let Ok(values) = model.constraint_singular_values(params, t, y) {
            let smallest = values.get(rank - 1).copied().unwrap_or(0.0);
            if smallest < 1e-4 * at_start {
                return ConstrainedError::SingularPosition {
                    model: model.info().name,
                    t,
                    smallest,
                    at_start,
                    rank,
                    source: error,
                };
            }
        }
    }
    error.into()
}

/// A run on the constraints: at each output time the state (projected),
/// the reactions, the energy function, and the residuals the integration
/// had left before that projection (the drift one segment allows).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ConstrainedRun {
    pub model: &'static str,
    pub constraint_names: Vec<&'static str>,
    /// The start after its projection onto the constraints.
    pub start: Vec<f64>,
    pub times: Vec<f64>,
    pub states: Vec<Vec<f64>>,
    pub reactions: Vec<Vec<f64>>,
    pub energy: Vec<f64>,
    /// Largest (|g|, |G q' + c_t|) found at a segment's end before its
    /// projection.
    pub largest_drift: (f64, f64),
    /// Largest residuals after the projections.
    pub largest_residual: (f64, f64),
    pub steps: u64,
    /// Redundant constraints (at the start) whose reactions the motion does
    /// not determine: their multipliers are reported as 0, one choice of
    /// many (the mechanism is statically indeterminate there).
    pub indeterminate: Vec<&'static str>,
    /// The intervals of time the run spent near singular positions of the
    /// mechanism (its constraints' rank dropping), run by the equations
    /// that pass them ([`crate::constrained::PassingSingular`]); empty if
    /// it met none.
    pub near_singular: Vec<[f64; 2]>,
}

/// Runs `model` from `y0` (the model file's start at rest if None; made
/// consistent by projection) at t0 = times[0] through the output `times`:
/// every reported state is projected onto the constraints, with its
/// reactions and energy, and so is the integrated state every 16 output
/// times.
pub fn run(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    y0: Option<&[f64]>,
    method: Method,
    times: &[f64],
) -> Result<ConstrainedRun, ConstrainedError> {
    let name = model.info().name;
    let mut result = ConstrainedRun {
        model: name,
        constraint_names: model.constraint_names().to_vec(),
        start: Vec::new(),
        times: Vec::new(),
        states: Vec::new(),
        reactions: Vec::new(),
        energy: Vec::new(),
        largest_drift: (0.0, 0.0),
        largest_residual: (0.0, 0.0),
        steps: 0,
        indeterminate: Vec::new(),
        near_singular: Vec::new(),
    };
    let followed = follow(model, params, y0, method, times, &mut |ts, mut sample| {
        let output = model.output(params, ts, &mut sample).map_err(|source| {
            ConstrainedError::Constraint {
                model: name,
                t: ts,
                source,
            }
        })?;
        result.largest_drift = larger(result.largest_drift, output.drift);
        let left = output.projection;
        let residual = (left.position_residual, left.velocity_residual);
        result.largest_residual = larger(result.largest_residual, residual);
        result.times.push(ts);
        result.reactions.push(output.reactions);
        result.energy.push(output.energy);
        result.states.push(sample);
        Ok(())
    })?;
    let t0 = times.first().copied().unwrap_or(0.0);
    let names = model.constraint_names();
    result.indeterminate = model
        .indeterminate_reactions(params, t0, &followed.start)?
        .into_iter()
        .map(|i| names[i])
        .collect();
    result.start = followed.start;
    result.steps = followed.steps;
    result.near_singular = followed.near_singular;
    Ok(result)
}

/// The states alone of [`run`] (each projected onto the constraints): what
/// an orbit by name returns, without the reactions and energies a run
/// reports at every output.
pub fn states(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    y0: &[f64],
    method: Method,
    times: &[f64],
) -> Result<Vec<Vec<f64>>, ConstrainedError> {
    let name = model.info().name;
    let mut states = Vec::with_capacity(times.len());
    follow(
        model,
        params,
        Some(y0),
        method,
        times,
        &mut |ts, mut sample| {
            model.project(params, ts, &mut sample).map_err(|source| {
                ConstrainedError::Constraint {
                    model: name,
                    t: ts,
                    source,
                }
            })?;
            states.push(sample);
            Ok(())
        },
    )?;
    Ok(states)
}

/// The integration of [`run`]: through groups of output times with dense
/// output, the integrated state projected at each group's end; each
/// output (not yet projected) goes to `report`. Returns the start after
/// its projection and the steps taken.
///
/// Near a singular position (the constraints' singular value of their
/// regular rank below [`NEAR_SINGULAR`] of its value at the start) the run
/// goes on with the equations that pass them
/// ([`crate::constrained::PassingSingular`], by DOP853 at the method's
/// tolerance, at most [`PASSING_TOLERANCE`]: they have no recurrences and
/// are noisy there), and back with the method's own equations past
/// [`CLEAR_OF_SINGULAR`]. Where branches of the constraints cross, the
/// regular equations can step onto the wrong one without their step size
/// collapsing, so the switch is made by an event before, not after a
/// collapse (which still sends the run to the passing equations); one that
/// stops even so says so.
fn follow(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    y0: Option<&[f64]>,
    method: Method,
    times: &[f64],
    report: &mut dyn FnMut(f64, Vec<f64>) -> Result<(), ConstrainedError>,
) -> Result<Followed, ConstrainedError> {
    let name = model.info().name;
    let t0 = times.first().copied().unwrap_or(0.0);
    if times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| !(w[1] > w[0])) {
        return Err(ConstrainedError::Times { t0 });
    }
    let mut y = match y0 {
        Some(y0) => y0.to_vec(),
        None => model.start(params),
    };
    if y.iter().any(|x| !x.is_finite()) {
        return Err(OdeError::NonFiniteInitialState { t: t0, y }.into());
    }
    let project = |t: f64, y: &mut Vec<f64>| {
        model
            .project(params, t, y)
            .map(|_| ())
            .map_err(|source| ConstrainedError::Constraint {
                model: name,
                t,
                source,
            })
    };
    // The file's start holds the rates it gives; the others follow.
    let held = model.start_held();
    match y0 {
        None if !held.is_empty() => model.consistent(params, &mut y, &held).map_err(|source| {
            ConstrainedError::Constraint {
                model: name,
                t: t0,
                source,
            }
        })?,
        _ => project(t0, &mut y)?,
    }
    let start = y.clone();
    let mut modes = Modes::new(model, params, method, t0, &start)?;
    // Each reported state is projected too (a step cut short at every
    // output time cost the pendulum's run twice its steps).
    let mut t = t0;
    for group in times.chunks(OUTPUTS_PER_PROJECTION) {
        let t1 = group[group.len() - 1];
        if t1 <= t {
            // The first output is the start itself.
            for &ts in group {
                report(ts, y.clone())?;
            }
            continue;
        }
        let mut pending = group;
        while t < t1 {
            let solution = modes.solve(t, &y, t1, pending)?;
            let (reported, rest) = pending.split_at(solution.samples.len());
            for (&ts, sample) in reported.iter().zip(solution.samples) {
                report(ts, sample)?;
            }
            pending = rest;
            (t, y) = (solution.t, solution.y);
            if solution.stopped {
                project(t, &mut y)?;
                modes.switch(t)?;
            }
        }
        project(t1, &mut y)?;
    }
    Ok(modes.followed(start, t))
}

/// Below this fraction of its value at the start, the constraints'
/// singular value of their regular rank sends a run to the equations that
/// pass singular positions; the regular equations' noise there is about
/// δ/σ² for a drift δ of the integrated state.
pub const NEAR_SINGULAR: f64 = 0.05;

/// Above this fraction of its value at the start, the singular value sends
/// a run back to the method's own equations.
pub const CLEAR_OF_SINGULAR: f64 = 0.1;

/// The two sets of equations of [`follow`] and which one runs.
struct Modes<'m> {
    method: Method,
    distance: SingularDistance<'m>,
    regular: Box<dyn AnySystem>,
    /// The equations that pass singular positions, their windows taken
    /// from the start's constraints.
    passing_equations: Box<dyn AnySystem>,
    integrator: Integrator,
    passing: bool,
    /// The steps of the integrators switched from.
    steps_before: u64,
    /// The intervals run by the passing equations (an open one ends at the
    /// run's end).
    near_singular: Vec<[f64; 2]>,
}

impl<'m> Modes<'m> {
    /// The regular equations at the start (the singular value's ratio is
    /// 1 there by its definition).
    fn new(
        model: &'m dyn ConstrainedSystems,
        params: &'m [f64],
        method: Method,
        t0: f64,
        start: &[f64],
    ) -> Result<Self, ConstrainedError> {
        let distance = SingularDistance {
            model,
            params,
            regular: regular_rank(model, params, t0, start),
        };
        Ok(Modes {
            method,
            distance,
            regular: model.exact(params),
            passing_equations: model.passing_singular(params, t0, start)?,
            integrator: Integrator::new(method)?,
            passing: false,
            steps_before: 0,
            near_singular: Vec::new(),
        })
    }

    /// From the regular equations to the passing ones at t, or back.
    fn switch(&mut self, t: f64) -> Result<(), ConstrainedError> {
        self.steps_before += self.integrator.stats.steps;
        self.passing = !self.passing;
        if self.passing {
            self.integrator = Integrator::new(self.method.dop853_at_least(PASSING_TOLERANCE))?;
            self.near_singular.push([t, f64::NAN]);
        } else {
            self.integrator = Integrator::new(self.method)?;
            if let Some(interval) = self.near_singular.last_mut() {
                interval[1] = t;
            }
        }
        Ok(())
    }

    /// From (t, y) towards t1 through the output `times`, stopped where
    /// the singular value crosses into (or out of) the passing equations'
    /// range; a regular run whose step size collapses at a singular
    /// position is run again from (t, y) with the passing equations.
    fn solve(
        &mut self,
        t: f64,
        y: &[f64],
        t1: f64,
        times: &[f64],
    ) -> Result<AnySolution, ConstrainedError> {
        let distance = &self.distance;
        let entering = |t: f64, y: &[f64]| distance.ratio(t, y) - NEAR_SINGULAR;
        let leaving = |t: f64, y: &[f64]| CLEAR_OF_SINGULAR - distance.ratio(t, y);
        let condition: &dyn Fn(f64, &[f64]) -> f64 = match self.passing {
            false => &entering,
            true => &leaving,
        };
        let options = AnyOptions::default().times(times).stop_below(condition);
        let named = |e| named_singularity(distance.model, distance.params, distance.regular, e);
        let system = match self.passing {
            false => &self.regular,
            true => &self.passing_equations,
        };
        match system.solve(&mut self.integrator, t, y, t1, options) {
            Ok(solution) => Ok(solution),
            Err(error) => match (named(error), self.passing) {
                (ConstrainedError::SingularPosition { .. }, false) => {
                    self.switch(t)?;
                    self.solve(t, y, t1, times)
                }
                (other, _) => Err(other),
            },
        }
    }

    /// What [`follow`] found, at its end t.
    fn followed(mut self, start: Vec<f64>, t: f64) -> Followed {
        if let Some(interval) = self.near_singular.last_mut().filter(|i| i[1].is_nan()) {
            interval[1] = t;
        }
        Followed {
            start,
            steps: self.steps_before + self.integrator.stats.steps,
            near_singular: self.near_singular,
        }
    }
}

/// How far a state is from a singular position.
struct SingularDistance<'m> {
    model: &'m dyn ConstrainedSystems,
    params: &'m [f64],
    /// The regular rank and its singular value at the start.
    regular: Option<(usize, f64)>,
}

impl SingularDistance<'_> {
    /// The constraints' singular value of their regular rank at (t, y) over
    /// its value at the start (infinite with no constraint to lose rank).
    fn ratio(&self, t: f64, y: &[f64]) -> f64 {
        let Some((rank, at_start)) = self.regular else {
            return f64::INFINITY;
        };
        match self.model.constraint_singular_values(self.params, t, y) {
            Ok(values) => values.get(rank - 1).copied().unwrap_or(0.0) / at_start,
            Err(_) => f64::NAN,
        }
    }
}

/// What [`follow`] found besides the outputs.
struct Followed {
    /// The start after its projection.
    start: Vec<f64>,
    steps: u64,
    /// See [`ConstrainedRun::near_singular`].
    near_singular: Vec<[f64; 2]>,
}

/// Output times per projection of the integrated state.
const OUTPUTS_PER_PROJECTION: usize = 16;

fn larger(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0.max(b.0), a.1.max(b.1))
}
