//! One orbit, or many, of any model by name, sampled at given times (the
//! exact system's dense output): what a notebook integrates. A constrained
//! model's start is put on its constraints and so is each state reported.

use rayon::prelude::*;

use crate::analysis::on_constraints::{states, ConstrainedError};
use crate::analysis::Refusal;
use crate::ode::{Method, OdeError};
use crate::registry::Model;

/// Why no orbit can be run.
#[derive(Debug, thiserror::Error)]
pub enum StatesError {
    #[error(transparent)]
    Refused(#[from] Refusal),
    /// Output times that are not finite or go back.
    #[error("the output times must be finite and increase (the first is the start's time)")]
    Times,
    /// A constrained model's start with no consistent state near it.
    #[error("model '{model}': the start is not near its constraints: {source}")]
    Start {
        model: &'static str,
        source: crate::ode::holonomic::ConstraintError,
    },
    /// A run that reached a point where the mass matrix is singular: the
    /// coordinates are a singular chart there (Euler angles at θ = 0).
    #[error("model '{model}' reached a singular chart at t = {t}, q = {q:?}: the mass matrix is singular there along the momenta {momenta:?}, so these coordinates cannot carry the motion through it (give the model other coordinates)")]
    SingularChart {
        model: &'static str,
        t: f64,
        q: Vec<f64>,
        momenta: Vec<usize>,
    },
    #[error(transparent)]
    Constrained(#[from] ConstrainedError),
    #[error(transparent)]
    Ode(#[from] OdeError),
}

/// The states of `model` at `times` from `y0` at times[0].
pub fn states_at(
    model: &Model,
    params: &[f64],
    method: Method,
    y0: &[f64],
    times: &[f64],
) -> Result<Vec<Vec<f64>>, StatesError> {
    check(
        model,
        params,
        method,
        std::slice::from_ref(&y0.to_vec()),
        times,
    )?;
    orbit(model, params, method, y0, times)
}

/// The states of `model` at `times` from each start, in parallel (the
/// Taylor method's in the batch lanes); an orbit that stops keeps its
/// error, the others go on.
pub fn states_of_starts(
    model: &Model,
    params: &[f64],
    method: Method,
    starts: &[Vec<f64>],
    times: &[f64],
) -> Result<Vec<Result<Vec<Vec<f64>>, StatesError>>, StatesError> {
    check(model, params, method, starts, times)?;
    crate::budget::check(
        || format!("{} orbits of {} states", starts.len(), times.len()),
        starts.len() as u128 * times.len() as u128,
        starts.first().map_or(0, Vec::len) * std::mem::size_of::<f64>(),
    )
    .map_err(OdeError::from)?;
    if model.constrained.is_some() {
        return Ok(starts
            .par_iter()
            .map(|y0| orbit(model, params, method, y0, times))
            .collect());
    }
    let flat: Vec<f64> = starts.iter().flatten().copied().collect();
    let runs = crate::analysis::flows(model)?.states_of_starts(params, method, &flat, times)?;
    Ok(runs
        .into_iter()
        .map(|run| run.map_err(StatesError::from))
        .collect())
}

/// The model, its parameters, the starts and the times as an orbit needs them.
fn check(
    model: &Model,
    params: &[f64],
    method: Method,
    starts: &[Vec<f64>],
    times: &[f64],
) -> Result<(), StatesError> {
    let flows = crate::analysis::flows(model)?;
    crate::analysis::method_applies(model, method)?;
    Refusal::named_values(model.info, params)?;
    let dim = flows.periodic_state().len();
    for y0 in starts {
        if y0.len() != dim {
            return Err(Refusal::state_length(model.info.name, "start", y0.len(), dim).into());
        }
        if y0.iter().any(|x| !x.is_finite()) {
            return Err(OdeError::NonFiniteInitialState {
                t: times.first().copied().unwrap_or(0.0),
                y: y0.clone(),
            }
            .into());
        }
    }
    if times.is_empty()
        || times.iter().any(|t| !t.is_finite())
        || times.windows(2).any(|w| !(w[1] > w[0]))
    {
        return Err(StatesError::Times);
    }
    Ok(())
}

fn orbit(
    model: &Model,
    params: &[f64],
    method: Method,
    y0: &[f64],
    times: &[f64],
) -> Result<Vec<Vec<f64>>, StatesError> {
    if let Some(constrained) = model.constrained {
        let mut start = y0.to_vec();
        constrained
            .project(params, times[0], &mut start)
            .map_err(|source| StatesError::Start {
                model: model.info.name,
                source,
            })?;
        return Ok(states(constrained, params, &start, method, times)?);
    }
    let system = crate::analysis::flows(model)?.exact(params);
    system
        .states_from(method, y0, times)
        .map_err(|error| singular_chart(model, params, error))
}

/// A run that became non-finite where the mass matrix is singular is
/// named a singular chart; any other error is passed on.
fn singular_chart(model: &Model, params: &[f64], error: OdeError) -> StatesError {
    if let OdeError::NonFinite { t, y } | OdeError::NonFiniteInitialState { t, y } = &error {
        let q = &y[..y.len() / 2];
        let momenta = crate::analysis::equilibria::singular_momenta(model.dynamic, params, q);
        if !momenta.is_empty() {
            return StatesError::SingularChart {
                model: model.info.name,
                t: *t,
                q: q.to_vec(),
                momenta,
            };
        }
    }
    error.into()
}

crate::declare_settings! {
    /// The states of a run at given times (`integrate`, `integrate_many`
    /// in Python): the method and its tolerance.
    pub struct IntegrateOptions for "integrate" {
        /// The integration method.
        method: String = "dop853".into(), crate::settings::Range::OneOf(crate::settings::METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-10, crate::settings::Range::Positive;
    }
}

crate::declare_settings! {
    /// The period map's iterates from many starts (`iterates` in Python;
    /// the Taylor method runs them in the batch lanes).
    pub struct IteratesOptions for "iterates" {
        /// Periods dropped before the first recorded iterate.
        transient: usize = 0, crate::settings::Range::Count { min: 0, max: 100_000_000 };
        /// The integration method.
        method: String = "taylor".into(), crate::settings::Range::OneOf(crate::settings::METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-10, crate::settings::Range::Positive;
    }
}

impl IntegrateOptions {
    /// The method these settings name.
    pub fn resolve(&self) -> Result<Method, crate::settings::SettingError> {
        crate::settings::method(
            <Self as crate::settings::Declared>::ANALYSIS,
            &self.method,
            self.tol,
        )
    }
}

impl IteratesOptions {
    /// The method these settings name.
    pub fn resolve(&self) -> Result<Method, crate::settings::SettingError> {
        crate::settings::method(
            <Self as crate::settings::Declared>::ANALYSIS,
            &self.method,
            self.tol,
        )
    }
}

/// The declarations of the calls that are not analyses (no scene, no
/// studio route): Python's `integrate`, `integrate_many` and `iterates`.
pub fn call_schemas() -> Vec<crate::settings::Schema> {
    use crate::settings::Schema;
    vec![
        Schema::of::<IntegrateOptions>(),
        Schema::of::<IteratesOptions>(),
    ]
}
