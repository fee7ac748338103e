//! Exact against averaged systems (the averaging theorems).
//!
//! Theorem 2 of the averaging method: started from the same state, the exact
//! solution of a system with a fast phase of frequency ν and the solution of
//! its averaged system stay within c/ν of each other on times of order one.
//! These functions run both systems from one state on one time grid and
//! measure the deviation.

use super::fit::{log_log, LineFit};
use crate::analysis::Refusal;
use crate::ode::{states_at, AnySystem, Method, OdeError, System};
use crate::registry::{Model, Systems};
use crate::settings::{method, Declared, Range, SettingError, Values, METHODS};
use rayon::prelude::*;

/// Both systems on one time grid, from the same initial state.
#[derive(Clone, Debug)]
pub struct Comparison<const N: usize> {
    pub times: Vec<f64>,
    pub exact: Vec<[f64; N]>,
    pub averaged: Vec<[f64; N]>,
}

impl<const N: usize> Comparison<N> {
    /// max over the grid of |exact − averaged| for each of the components `components`.
    pub fn max_deviation(&self, components: std::ops::Range<usize>) -> Vec<f64> {
        components
            .map(|i| {
                self.exact
                    .iter()
                    .zip(&self.averaged)
                    .map(|(e, a)| (e[i] - a[i]).abs())
                    .fold(0.0, f64::max)
            })
            .collect()
    }
}

/// A grid on [0, t_end] fine enough to resolve the fast oscillation of
/// period `fast_period` (`per_period` samples each), and at least `minimum`.
pub fn time_grid(t_end: f64, fast_period: f64, per_period: usize, minimum: usize) -> Vec<f64> {
    let n = ((t_end / fast_period) * per_period as f64).ceil() as usize;
    let n = n.max(minimum).max(1);
    (0..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

/// Runs the exact and the averaged system from `y0` and samples both on
/// `times` (dense output, so the steps stay those the accuracy needs).
pub fn compare<E: System<N>, A: System<N>, const N: usize>(
    method: Method,
    exact: &E,
    averaged: &A,
    y0: &[f64; N],
    times: &[f64],
) -> Result<Comparison<N>, OdeError> {
    let exact_states = states_at(method, exact, 0.0, y0, times)?;
    let averaged_states = states_at(method, averaged, 0.0, y0, times)?;
    Ok(Comparison {
        times: times.to_vec(),
        exact: exact_states,
        averaged: averaged_states,
    })
}

/// The maximal deviation of each coordinate over [0, t_obs] for each
/// frequency, and the fitted exponent of each coordinate's deviation against
/// the frequency (−1 where Theorem 2 holds). `systems(ν)` builds both systems.
pub struct Convergence {
    pub frequencies: Vec<f64>,
    /// `[coordinate][frequency]`
    pub max_deviation: Vec<Vec<f64>>,
    pub fits: Vec<LineFit>,
}

pub fn deviation_against_frequency(
    method: Method,
    systems: &(dyn Fn(f64) -> (Box<dyn AnySystem>, Box<dyn AnySystem>) + Sync),
    y0: &[f64],
    t_obs: f64,
    frequencies: &[f64],
    coordinates: usize,
) -> Result<Convergence, OdeError> {
    let per_frequency: Vec<Vec<f64>> = frequencies
        .par_iter()
        .map(|&nu| {
            let (exact, averaged) = systems(nu);
            let grid = time_grid(t_obs, 2.0 * std::f64::consts::PI / nu, 32, 2000);
            let exact = exact.states_at(method, 0.0, y0, &grid)?;
            let averaged = averaged.states_at(method, 0.0, y0, &grid)?;
            Ok(largest_deviations(&exact, &averaged, coordinates))
        })
        .collect::<Result<_, OdeError>>()?;
    Ok(fit_deviations(frequencies, per_frequency, coordinates))
}

/// The largest |exact − averaged| of each of the first `coordinates`
/// components over two runs' samples.
fn largest_deviations(exact: &[Vec<f64>], averaged: &[Vec<f64>], coordinates: usize) -> Vec<f64> {
    (0..coordinates)
        .map(|i| {
            exact
                .iter()
                .zip(averaged)
                .map(|(e, a)| (e[i] - a[i]).abs())
                .fold(0.0, f64::max)
        })
        .collect()
}

/// Per coordinate, the deviations against the frequencies and their
/// log–log fit.
fn fit_deviations(
    frequencies: &[f64],
    per_frequency: Vec<Vec<f64>>,
    coordinates: usize,
) -> Convergence {
    let max_deviation: Vec<Vec<f64>> = (0..coordinates)
        .map(|i| per_frequency.iter().map(|d| d[i]).collect())
        .collect();
    let fits = max_deviation
        .iter()
        .map(|devs| {
            let points: Vec<(f64, f64)> = frequencies
                .iter()
                .copied()
                .zip(devs.iter().copied())
                .collect();
            log_log(&points)
        })
        .collect();
    Convergence {
        frequencies: frequencies.to_vec(),
        max_deviation,
        fits,
    }
}

crate::declare_settings! {
    /// Exact against averaged (Theorem 2 on any model): the largest
    /// deviation of each coordinate between the exact and averaged runs
    /// from the same state, against the frequency of the fast phase, and
    /// its fitted slope.
    pub struct AveragingOptions for "averaging" {
        /// The parameter swept to change ν (auto: the one the phase rate
        /// depends on).
        parameter: Option<String> = None, Range::Any;
        /// Its values: a list, or geometric:first,last,count (auto: ν at
        /// 4…64 times the model's frequency).
        values: Option<Values> = None, Range::Any;
        /// The common initial state [q; p] (auto: q = 0.2, −0.1, …, p = 0).
        y0: Option<Vec<f64>> = None, Range::Any;
        /// The deviation is the maximum over [0, t_obs].
        t_obs: f64 = 2.0, Range::Positive;
        /// 1: the averaged system from the same state; 2: the system
        /// averaged to second order, from the transformed state and mapped
        /// back.
        order: usize = 1, Range::Count { min: 1, max: 2 };
        /// The integration method.
        method: String = "dop853".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-11, Range::Positive;
        /// Run the sweep again at a hundredth of the tolerance, to state
        /// each deviation's and slope's numerical error (no: none).
        check: bool = true, Range::Any;
        /// The error wanted on every deviation (auto: none asked; with
        /// `check`, each comes with its error). Given, `tol` is tightened a
        /// hundredfold until every deviation's error is within it, or the
        /// result says why not.
        accuracy: Option<f64> = None, Range::Positive;
    }
}

impl AveragingOptions {
    /// The settings of [`convergence`].
    pub fn resolve(&self) -> Result<ConvergenceSettings, SettingError> {
        Ok(ConvergenceSettings {
            parameter: self.parameter.clone(),
            values: self.values.as_ref().map(Values::values),
            y0: self.y0.clone(),
            t_obs: self.t_obs,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            order: self.order,
            check: self.check,
            accuracy: self.accuracy,
        })
    }
}

/// How [`convergence`] runs, from [`AveragingOptions`].
#[derive(Clone, Debug)]
pub struct ConvergenceSettings {
    /// The parameter swept to change the phase's frequency (None: the one
    /// parameter the model file's phase rate depends on).
    pub parameter: Option<String>,
    /// Its values; the frequency ν = 2π/T of each is measured from the
    /// model. None: the values at which ν is 4, 8, 16, 32 and 64 times the
    /// frequency at the given parameters (for a rate proportional or
    /// inversely proportional to the parameter).
    pub values: Option<Vec<f64>>,
    /// The common initial state [q; p] (None: q = 0.2, −0.1, 0.2, …, p = 0).
    pub y0: Option<Vec<f64>>,
    /// The deviation is the maximum over [0, t_obs].
    pub t_obs: f64,
    pub method: Method,
    /// 1: the averaged system from the same state (deviation O(1/ν));
    /// 2: the system averaged to second order, started from the
    /// transformed state y′ = y − J∇(εχ₁) and mapped back along its run
    /// (deviation O(1/ν²)).
    pub order: usize,
    /// Run again at a hundredth of the tolerance to state the errors.
    pub check: bool,
    /// The error wanted on every deviation (None: stated, not chosen).
    pub accuracy: Option<f64>,
}

/// Theorem 2 on any model by name: the maximal deviation of each coordinate
/// between the exact and averaged runs from the same state, against the
/// frequency of the phase, and its fitted exponent (−1 where the theorem
/// holds).
#[derive(Clone, Debug, serde::Serialize)]
pub struct AveragingConvergence {
    pub model: String,
    pub parameter: String,
    pub values: Vec<f64>,
    pub frequencies: Vec<f64>,
    pub coordinates: Vec<String>,
    pub y0: Vec<f64>,
    pub t_obs: f64,
    /// The order of the averaged system compared (1 or 2).
    pub order: usize,
    /// `[coordinate][value]`
    pub max_deviation: Vec<Vec<f64>>,
    /// ν × max deviation, `[coordinate][value]`: levels off where the
    /// deviation is c/ν.
    pub frequency_times_deviation: Vec<Vec<f64>>,
    /// The fitted exponent of each coordinate's deviation against ν.
    pub slope: Vec<f64>,
    /// The fitted level c in deviation ≈ c ν^slope.
    pub level: Vec<f64>,
    /// The slope between each two neighbouring frequencies, `[coordinate][k]`.
    pub local_slopes: Vec<Vec<f64>>,
    /// The asymptotic exponent, where the sweep has reached it: the last
    /// three local slopes agree to [`SETTLED`]. None where the deviation
    /// still turns between two powers of ν (a coordinate whose 1/ν term
    /// is small at these frequencies, or a chaotic run whose constant grows
    /// like e^(λ t)): raise the frequencies to see it.
    pub settled_slope: Vec<Option<f64>>,
    /// Each deviation's numerical error, `[coordinate][value]`: twice its
    /// distance to the same sweep run at a hundredth of the tolerance
    /// (empty: not checked).
    pub deviation_error: Vec<Vec<f64>>,
    /// Each fitted slope's numerical error, the same way (empty: not
    /// checked).
    pub slope_error: Vec<f64>,
    /// The two runs compared, or why none was.
    pub check: Option<String>,
    /// Whether the `accuracy` asked for was reached, and by which run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
}

/// How closely the last three local slopes agree where the sweep has
/// reached its asymptotic exponent (two agreeing by chance on a 12-link
/// chain's chaotic run gave −0.59 between turns).
pub const SETTLED: f64 = 0.2;

/// The slopes of log d against log ν between neighbouring frequencies.
fn local_slopes(frequencies: &[f64], deviations: &[f64]) -> Vec<f64> {
    frequencies
        .windows(2)
        .zip(deviations.windows(2))
        .map(|(f, d)| (d[1] / d[0]).ln() / (f[1] / f[0]).ln())
        .collect()
}

/// The mean of the last two local slopes where the last three agree to
/// [`SETTLED`].
fn settled(local: &[f64]) -> Option<f64> {
    match local {
        [.., z, a, b] if [z, a, b].iter().all(|x| x.is_finite()) => {
            let (low, high) = (z.min(a.min(*b)), z.max(a.max(*b)));
            (high - low < SETTLED).then_some(0.5 * (a + b))
        }
        _ => None,
    }
}

/// Why [`convergence`] cannot run.
#[derive(Debug, thiserror::Error)]
pub enum AveragingError {
    /// The analysis does not apply to this kind of model.
    #[error(transparent)]
    Refused(#[from] crate::analysis::Refusal),
    /// The swept parameter's values give no fit: `problem` says why.
    #[error("model '{model}': sweeping '{parameter}' {problem}")]
    Sweep {
        model: String,
        parameter: String,
        problem: SweepProblem,
    },
    #[error("model '{0}': the averaged system of order {1} is not derived (order 1 is for every model with a fast phase, order 2 too except for models with a numeric solve of more than 4 degrees of freedom, whose code would grow like n⁴)")]
    Order(String, usize),
    /// Second-order averaging on a flow that is not Hamiltonian here.
    #[error("model '{model}': the averaging to second order is derived for Hamiltonian systems, and this one loses volume at the start (the averaged flow's divergence {divergence:.3e}: friction, or other non-potential forces at these parameters); order 1 applies")]
    Dissipative { model: String, divergence: f64 },
    /// A constrained model whose constraints or mass matrix move with the
    /// fast phase: the averaging with constraints is derived for fixed ones.
    #[error("model '{model}': its constraints or its mass matrix move with the fast phase; the averaging on constraints is derived for fixed ones (`explore` runs the exact motion)")]
    MovingConstraints { model: String },
    /// A constrained run that could not stay on its constraints.
    #[error(transparent)]
    Constrained(#[from] crate::analysis::on_constraints::ConstrainedError),
    #[error(transparent)]
    Ode(#[from] OdeError),
}

/// Why a swept parameter's values give no fit of the averaging error.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SweepProblem {
    #[error("changes the frequency of the phase neither in proportion nor in inverse proportion: give the values to sweep")]
    NotProportional,
    #[error("to {value} gives no finite period of the phase")]
    NoPeriod { value: f64 },
    #[error("does not change the frequency of the phase (or fewer than two values were given): nothing to fit against")]
    FrequencyUnchanged,
}

/// The deviation of each coordinate over `times` between the exact run
/// from `y0` and the second-order averaged run from the transformed state,
/// mapped back: y(t) ≈ y′(t) + shift(y′(t), t), y′(0) = y0 − shift(y0, 0).
pub fn second_order_deviation(
    model: &dyn Systems,
    params: &[f64],
    method: Method,
    y0: &[f64],
    times: &[f64],
) -> Option<Result<Vec<f64>, OdeError>> {
    let averaged = model.averaged2(params)?;
    let shift0 = model.averaged2_shift(params, 0.0, y0)?;
    let start: Vec<f64> = y0.iter().zip(&shift0).map(|(y, s)| y - s).collect();
    let dof = model.info().coordinates.len();
    let run = || -> Result<Vec<f64>, OdeError> {
        let exact = model.exact(params).states_at(method, 0.0, y0, times)?;
        let transformed = averaged.states_at(method, 0.0, &start, times)?;
        let mut worst = vec![0.0f64; dof];
        for ((t, e), y) in times.iter().zip(&exact).zip(&transformed) {
            let shift = model
                .averaged2_shift(params, *t, y)
                .unwrap_or_else(|| vec![0.0; y.len()]);
            for (i, w) in worst.iter_mut().enumerate() {
                *w = w.max((e[i] - y[i] - shift[i]).abs());
            }
        }
        Ok(worst)
    };
    Some(run())
}

/// Runs [`AveragingConvergence`] on `model` with parameter values
/// `params` (declaration order); with `check`, again at a hundredth of
/// the tolerance for the errors; with an `accuracy`, a hundredfold tighter
/// until every deviation's error is within it.
pub fn convergence(
    model: &Model,
    params: &[f64],
    settings: &ConvergenceSettings,
) -> Result<AveragingConvergence, AveragingError> {
    let at = |method: Method| {
        let settings = ConvergenceSettings {
            method,
            ..settings.clone()
        };
        convergence_once(model, params, &settings)
    };
    // The deviations are differences of states of about the start's size.
    let magnitude = (settings.y0.iter().flatten()).fold(1.0, |m: f64, x| m.max(x.abs()));
    Refusal::accuracy_within_reach(
        model.info.name,
        "the deviations",
        settings.accuracy,
        magnitude,
    )?;
    let (mut result, checked) = super::check::checked_run(
        settings.method,
        settings.check,
        settings.accuracy,
        at,
        AveragingConvergence::checked_against,
        AveragingConvergence::worst_error,
    )?;
    if let Some(checked) = checked {
        (result.check, result.accuracy) = (Some(checked.runs), checked.accuracy);
    }
    Ok(result)
}

/// [`convergence`] at the settings' method, unchecked.
fn convergence_once(
    model: &Model,
    params: &[f64],
    settings: &ConvergenceSettings,
) -> Result<AveragingConvergence, AveragingError> {
    if let Some(constrained) = model.constrained {
        return on_constraints(constrained, params, settings);
    }
    let model = crate::analysis::hamiltonian(model)?;
    let info = model.info();
    if !model.has_fast_phase() {
        return Err(AveragingError::Refused(Refusal::no_fast_phase(info.name)));
    }
    Refusal::named_values(info, params)?;
    let dof = info.coordinates.len();
    let y0 = initial_state(model, settings)?;
    let (parameter, index, values, frequencies) = swept(model, params, settings)?;
    let with = |value: f64| {
        let mut p = params.to_vec();
        p[index] = value;
        p
    };
    let run = match settings.order {
        1 => {
            let systems = |nu: f64| {
                let k = frequencies.iter().position(|f| *f == nu).unwrap_or(0);
                let p = with(values[k]);
                let averaged = model
                    .averaged(&p)
                    .expect("a model with a fast phase has an averaged system");
                (model.exact(&p), averaged)
            };
            let (method, t_obs) = (settings.method, settings.t_obs);
            deviation_against_frequency(method, &systems, &y0, t_obs, &frequencies, dof)?
        }
        2 => {
            if model.averaged2(params).is_none() {
                return Err(AveragingError::Order(info.name.into(), 2));
            }
            let averaged = model
                .averaged(params)
                .expect("a model with a fast phase has an averaged system");
            let divergence = divergence_at(averaged.as_ref(), &y0)?;
            if divergence.abs() > 1e-5 {
                return Err(AveragingError::Dissipative {
                    model: info.name.into(),
                    divergence,
                });
            }
            let per_frequency: Vec<Vec<f64>> = frequencies
                .par_iter()
                .zip(&values)
                .map(|(&nu, &value)| {
                    let fast_period = 2.0 * std::f64::consts::PI / nu;
                    let grid = time_grid(settings.t_obs, fast_period, 32, 2000);
                    second_order_deviation(model, &with(value), settings.method, &y0, &grid)
                        .expect("checked above")
                })
                .collect::<Result<_, _>>()?;
            fit_deviations(&frequencies, per_frequency, dof)
        }
        order => return Err(AveragingError::Order(info.name.into(), order)),
    };
    Ok(summarised(info, parameter, values, y0, settings, run))
}

/// The divergence of `system`'s field at `y` (central differences): 0 for
/// a Hamiltonian flow, the rate of volume loss of a damped one.
fn divergence_at(system: &dyn AnySystem, y: &[f64]) -> Result<f64, OdeError> {
    let h = 1e-6;
    let mut sum = 0.0;
    for i in 0..y.len() {
        let (mut up, mut down) = (y.to_vec(), y.to_vec());
        up[i] += h;
        down[i] -= h;
        sum += (system.rhs(0.0, &up)?[i] - system.rhs(0.0, &down)?[i]) / (2.0 * h);
    }
    Ok(sum)
}

/// The sweep's deviations as the analysis reports them: local and fitted
/// slopes, levels, ν × deviation.
fn summarised(
    info: &crate::registry::ModelInfo,
    parameter: String,
    values: Vec<f64>,
    y0: Vec<f64>,
    settings: &ConvergenceSettings,
    run: Convergence,
) -> AveragingConvergence {
    let frequencies = run.frequencies.clone();
    let local: Vec<Vec<f64>> = run
        .max_deviation
        .iter()
        .map(|d| local_slopes(&frequencies, d))
        .collect();
    let frequency_times_deviation = run
        .max_deviation
        .iter()
        .map(|d| d.iter().zip(&frequencies).map(|(d, nu)| d * nu).collect())
        .collect();
    AveragingConvergence {
        model: info.name.into(),
        parameter,
        values,
        frequencies,
        coordinates: info.coordinates.iter().map(|c| c.to_string()).collect(),
        y0,
        t_obs: settings.t_obs,
        order: settings.order,
        frequency_times_deviation,
        max_deviation: run.max_deviation,
        slope: run.fits.iter().map(|f| f.slope).collect(),
        level: run.fits.iter().map(|f| f.intercept.exp()).collect(),
        settled_slope: local.iter().map(|l| settled(l)).collect(),
        local_slopes: local,
        deviation_error: Vec::new(),
        slope_error: Vec::new(),
        check: None,
        accuracy: None,
    }
}

impl AveragingConvergence {
    /// The errors of this sweep from `again`, the same sweep at a
    /// hundredth of the tolerance: twice the distances.
    fn checked_against(&mut self, again: &AveragingConvergence) {
        self.deviation_error = (self.max_deviation.iter())
            .zip(&again.max_deviation)
            .map(|(a, b)| a.iter().zip(b).map(|(x, y)| 2.0 * (x - y).abs()).collect())
            .collect();
        self.slope_error = (self.slope.iter())
            .zip(&again.slope)
            .map(|(a, b)| 2.0 * (a - b).abs())
            .collect();
    }

    /// The largest error of a deviation (∞ unchecked).
    fn worst_error(&self) -> f64 {
        if self.deviation_error.is_empty() {
            return f64::INFINITY;
        }
        (self.deviation_error.iter().flatten()).fold(0.0, |m: f64, &e| m.max(e))
    }
}

/// [`convergence`] on a constrained model with fixed holonomic constraints
/// (first order): the exact run on the constraints against the averaged
/// motion of W = mean V + ½ mean⟨P b, b⟩ from the same consistent state,
/// both projected at every sample. The start defaults to the model file's
/// with its first coordinate moved by 0.2, put on the constraints holding it.
fn on_constraints(
    model: &'static dyn crate::registry::ConstrainedSystems,
    params: &[f64],
    settings: &ConvergenceSettings,
) -> Result<AveragingConvergence, AveragingError> {
    let info = model.info();
    if !model.has_fast_phase() {
        return Err(AveragingError::Refused(Refusal::no_fast_phase(info.name)));
    }
    if settings.order != 1 {
        return Err(AveragingError::Order(info.name.into(), settings.order));
    }
    Refusal::named_values(info, params)?;
    let n = info.coordinates.len();
    let mut y0 = match &settings.y0 {
        Some(y) if y.len() != 2 * n => {
            return Err(Refusal::state_length(info.name, "initial state", y.len(), 2 * n).into())
        }
        Some(y) => y.clone(),
        None => {
            let mut y = model.start(params);
            y[0] += 0.2;
            y
        }
    };
    let held: &[usize] = if settings.y0.is_some() { &[] } else { &[0] };
    model.consistent(params, &mut y0, held).map_err(|source| {
        crate::analysis::on_constraints::ConstrainedError::Constraint {
            model: info.name,
            t: 0.0,
            source,
        }
    })?;
    let (parameter, index, values, frequencies) = swept(model, params, settings)?;
    let per_frequency: Vec<Vec<f64>> = frequencies
        .par_iter()
        .zip(&values)
        .map(|(&nu, &value)| -> Result<Vec<f64>, AveragingError> {
            let mut p = params.to_vec();
            p[index] = value;
            let grid = time_grid(settings.t_obs, 2.0 * std::f64::consts::PI / nu, 32, 2000);
            let averaged = model
                .averaged_states(&p, settings.method, &y0, &grid)?
                .ok_or_else(|| AveragingError::MovingConstraints {
                    model: info.name.into(),
                })?;
            let exact =
                crate::analysis::on_constraints::run(model, &p, Some(&y0), settings.method, &grid)?
                    .states;
            Ok(largest_deviations(&exact, &averaged, n))
        })
        .collect::<Result<_, _>>()?;
    let run = fit_deviations(&frequencies, per_frequency, n);
    Ok(summarised(info, parameter, values, y0, settings, run))
}

/// The start of both runs: the settings', or 0.2, −0.1, 0.2, … in the
/// coordinates and 0 in the momenta.
fn initial_state(model: &dyn Systems, settings: &ConvergenceSettings) -> Result<Vec<f64>, Refusal> {
    let info = model.info();
    let (dof, n) = (info.coordinates.len(), model.periodic_state().len());
    match &settings.y0 {
        Some(y) if y.len() != n => Err(Refusal::state_length(
            info.name,
            "initial state",
            y.len(),
            n,
        )),
        Some(y) => Ok(y.clone()),
        None => Ok((0..n)
            .map(|i| match i {
                i if i < dof && i % 2 == 0 => 0.2,
                i if i < dof => -0.1,
                _ => 0.0,
            })
            .collect()),
    }
}

/// The swept parameter, its index, its values and the phase's frequency at
/// each (checked to change).
#[allow(clippy::type_complexity)]
fn swept(
    model: &dyn crate::registry::Flows,
    params: &[f64],
    settings: &ConvergenceSettings,
) -> Result<(String, usize, Vec<f64>, Vec<f64>), AveragingError> {
    let info = model.info();
    let parameter = match &settings.parameter {
        Some(p) => p.clone(),
        None => info.rate_parameter.map(str::to_string).ok_or_else(|| {
            Refusal::setting(
                info.name,
                "the phase rate depends on more than one parameter: name the one to sweep",
            )
        })?,
    };
    let index = Refusal::parameter_index(info, &parameter)?;
    let bad = |problem: SweepProblem| AveragingError::Sweep {
        model: info.name.into(),
        parameter: parameter.clone(),
        problem,
    };
    let with = |value: f64| {
        let mut p = params.to_vec();
        p[index] = value;
        p
    };
    let frequency = |value: f64| {
        model
            .phase_period(&with(value))
            .filter(|t| t.is_finite() && *t > 0.0)
            .map(|t| 2.0 * std::f64::consts::PI / t)
    };
    let values = match &settings.values {
        Some(values) => values.clone(),
        None => {
            let p0 = params[index];
            let (f1, f2) = (frequency(p0), frequency(2.0 * p0));
            let ratio = f1.zip(f2).map(|(a, b)| b / a).unwrap_or(f64::NAN);
            let factors = [4.0, 8.0, 16.0, 32.0, 64.0];
            if (ratio - 2.0).abs() < 1e-9 {
                factors.map(|k| p0 * k).to_vec()
            } else if (ratio - 0.5).abs() < 1e-9 {
                factors.map(|k| p0 / k).to_vec()
            } else {
                return Err(bad(SweepProblem::NotProportional));
            }
        }
    };
    let mut frequencies = Vec::new();
    for &value in &values {
        frequencies.push(frequency(value).ok_or_else(|| bad(SweepProblem::NoPeriod { value }))?);
    }
    let distinct = frequencies
        .iter()
        .any(|f| (f - frequencies[0]).abs() > 1e-12 * f.abs());
    if !distinct {
        return Err(bad(SweepProblem::FrequencyUnchanged));
    }
    Ok((parameter, index, values, frequencies))
}

impl AveragingConvergence {
    /// Max deviation against ν (log–log, with the fits) and ν × max
    /// deviation.
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{palette, Figure, PanelSpec};
        use crate::registry::display_name;
        let result = self;
        let range = |values: &mut dyn Iterator<Item = f64>| {
            let (lo, hi) = values
                .filter(|v| *v > 0.0)
                .fold((f64::MAX, 0.0f64), |(l, h), v| (l.min(v), h.max(v)));
            (lo / 1.5, hi * 1.5)
        };
        let x = range(&mut result.frequencies.iter().copied());
        let y = range(&mut result.max_deviation.iter().flatten().copied());
        // ν^order × deviation levels off where the deviation is c/ν^order.
        let order = result.order as i32;
        let scaled_of = |k: usize| -> Vec<(f64, f64)> {
            result
                .frequencies
                .iter()
                .zip(&result.max_deviation[k])
                .map(|(nu, d)| (*nu, d * nu.powi(order)))
                .collect()
        };
        let scaled = range(
            &mut (0..result.coordinates.len())
                .flat_map(scaled_of)
                .map(|p| p.1),
        );
        let title = format!(
            "{}: exact against averaged (order {order}), t ≤ {}",
            result.model, result.t_obs
        );
        let (power, scaled_title) = if order == 1 {
            (
                "ν × max deviation".to_string(),
                "ν × max deviation: levels off where the deviation is c/ν".to_string(),
            )
        } else {
            (
                format!("ν^{order} × max deviation"),
                format!("ν^{order} × max deviation: levels off where the deviation is c/ν^{order}"),
            )
        };
        let specs = [
            PanelSpec::new(
                &title,
                "frequency ν of the phase",
                "max |exact − averaged|",
                x,
                y,
            )
            .log_log(),
            PanelSpec::new(
                &scaled_title,
                "frequency ν of the phase",
                &power,
                x,
                (0.0, scaled.1),
            )
            .log_x(),
        ];
        let mut figure = Figure::grid(2, 1, 620, 460, &specs);
        let mut legend = Vec::new();
        for (k, coordinate) in result.coordinates.iter().enumerate() {
            let points: Vec<(f64, f64)> = result
                .frequencies
                .iter()
                .copied()
                .zip(result.max_deviation[k].iter().copied())
                .collect();
            figure.points(0, points.iter().copied(), palette(k), 4);
            let fit: Vec<(f64, f64)> = [x.0 * 1.5, x.1 / 1.5]
                .iter()
                .map(|nu| (*nu, result.level[k] * nu.powf(result.slope[k])))
                .collect();
            figure.line(0, &fit, palette(k));
            let scaled = scaled_of(k);
            figure.line(1, &scaled, palette(k));
            figure.points(1, scaled, palette(k), 4);
            legend.push((
                format!("{}: slope {:.3}", display_name(coordinate), result.slope[k]),
                palette(k),
            ));
        }
        figure.legend_at(0, &legend, true);
        figure.legend_at(1, &legend, true);
        figure
    }
}

impl crate::outputs::Outputs for AveragingConvergence {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        vec![("convergence.png".into(), self.figure())]
    }
    /// Per value and coordinate: the frequency, the largest deviation, and
    /// ν × deviation.
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let rows = self.coordinates.iter().enumerate().flat_map(|(c, name)| {
            (0..self.values.len()).map(move |k| {
                (
                    self.values[k],
                    self.frequencies[k],
                    name.clone(),
                    self.max_deviation[c][k],
                    self.deviation_error.get(c).map_or(f64::NAN, |e| e[k]),
                    self.frequency_times_deviation[c][k],
                )
            })
        });
        let header = [
            self.parameter.as_str(),
            "frequency",
            "coordinate",
            "max_deviation",
            "max_deviation_error",
            "frequency_times_max_deviation",
        ];
        vec![crate::outputs::Table::new("convergence.csv", &header, rows)]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines: Vec<String> = (self.coordinates.iter().zip(&self.slope).enumerate())
            .map(|(k, (c, s))| match self.slope_error.get(k) {
                Some(e) => {
                    format!("{c}: max deviation ∝ ν^{s:.4} (numerical error of the slope {e:.1e})")
                }
                None => format!("{c}: max deviation ∝ ν^{s:.4}"),
            })
            .collect();
        if let Some(check) = &self.check {
            let what = "deviations' numerical error";
            lines.push(super::check::error_line(what, self.worst_error(), check));
        }
        lines.extend(self.accuracy.clone());
        lines
    }
}
