//! How the periodic orbits of a forced or vibrated model change with a
//! parameter: fixed points of the period map (and of its iterates P^k)
//! continued by pseudo-arclength (the equilibria of a model without a
//! fast phase likewise, with the eigenvalues of the Jacobian and Hopf
//! points), their Floquet multipliers along the
//! branch, folds, branch points (pitchforks), period doublings and
//! Neimark–Sacker points located on the branch, new branches switched to
//! at period doublings (a cascade is followed to a requested period) and at
//! branch points; beside it the brute-force orbit diagram, the attractor of
//! P against the parameter, for comparison.
//!
//! The numerics (`branch`) see the model only through `FamilyMap`, one
//! period of the map and its monodromy matrix at a parameter value, so
//! they are compiled once, not once per model size.

mod branch;
mod chart;
mod diagram;

pub use branch::BranchEnd;
pub use diagram::OrbitDiagram;

use crate::analysis::floquet::{multipliers_of, Verdict};
use crate::analysis::Refusal;
use crate::ode::{AnyOptions, Integrator, Method, OdeError};
use crate::registry::{Model, Systems};
use crate::settings::{method, Declared, Range, SettingError, METHODS};
use branch::{Origin, Solution, Steps};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

crate::declare_settings! {
    /// Periodic orbits of the period map continued in a parameter (the
    /// equilibria of a model without a fast phase), their Floquet
    /// multipliers and bifurcations, with the orbit diagram beside them.
    pub struct ContinuationOptions for "continuation" {
        /// The parameter continued in, from its value to `to` (auto: the
        /// model file's [fast_phase] amplitude).
        parameter: Option<String> = None, Range::Any;
        /// The other end of the parameter's interval (auto: 1.8 times its
        /// value, 1 where it is 0).
        to: Option<f64> = None, Range::Any;
        /// A guess of the first periodic orbit's state at t = 0, zeros
        /// appended (auto: 1,0; a constrained model's start, its components
        /// replaced by those given).
        start: Option<Vec<f64>> = None, Range::Any;
        /// The first branch is of fixed points of P^period.
        period: usize = 1, Range::Count { min: 1, max: 1024 };
        /// Switch at period doublings up to this period.
        max_period: usize = 16, Range::Count { min: 1, max: 1 << 20 };
        /// Also switch at branch points (pitchforks).
        switch_branch_points: bool = true, Range::Any;
        /// At most this many branches.
        branches: usize = 12, Range::Count { min: 1, max: 1000 };
        /// At most this many points per branch.
        points: usize = 3000, Range::Count { min: 2, max: 1_000_000 };
        /// The first step in arclength.
        step: f64 = 0.005, Range::Positive;
        /// A branch ends where the step falls below this.
        min_step: f64 = 1e-8, Range::Positive;
        /// The largest step.
        max_step: f64 = 0.02, Range::Positive;
        /// Parameter values of the orbit diagram beside the branches (0:
        /// none).
        diagram: usize = 400, Range::Count { min: 0, max: 100_000 };
        /// Periods of the orbit diagram dropped first.
        transient: usize = 300, Range::Count { min: 0, max: 1_000_000 };
        /// Periods of the orbit diagram drawn.
        iterates: usize = 100, Range::Count { min: 1, max: 1_000_000 };
        /// A constrained model's chart: the components of [q; q'] that are
        /// the branches' coordinates (auto: those that parametrise its
        /// constraints best at the start).
        chart: Option<Vec<usize>> = None, Range::Any;
        /// The error wanted on the bifurcations' parameters (auto: none
        /// asked, each comes with its error). Given, the continuation is
        /// run again a hundredfold tighter until every error is within it,
        /// or the result says why not.
        accuracy: Option<f64> = None, Range::Positive;
        /// The integration method.
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-12, Range::Positive;
    }
    interactive {
        max_period: 4,
        switch_branch_points: false,
        branches: 4,
        points: 1500,
        step: 0.01,
        max_step: 0.05,
        diagram: 0,
    }
}

impl ContinuationOptions {
    /// The settings of [`continuation`] for `model` at the parameter
    /// values `params`, `auto` resolved.
    pub fn resolve(
        &self,
        model: &Model,
        params: &[f64],
    ) -> Result<ContinuationSettings, ContinuationError> {
        let info = model.info;
        let parameter = match (&self.parameter, info.amplitude) {
            (Some(p), _) => p.clone(),
            (None, Some(amplitude)) => amplitude.to_string(),
            (None, None) => {
                return Err(SettingError::NoAmplitude {
                    analysis: Self::ANALYSIS,
                    name: "parameter",
                    model: info.name,
                    known: info.parameter_names,
                }
                .into())
            }
        };
        Ok(ContinuationSettings {
            to: self
                .to
                .unwrap_or_else(|| default_end(info, params, &parameter)),
            parameter,
            // A constrained model starts at its file's start unless told.
            start: match (&self.start, model.constrained) {
                (Some(start), _) => start.clone(),
                (None, Some(_)) => Vec::new(),
                (None, None) => vec![1.0, 0.0],
            },
            period: self.period,
            max_period: self.max_period,
            switch_branch_points: self.switch_branch_points,
            max_branches: self.branches,
            points: self.points,
            step: self.step,
            min_step: self.min_step,
            max_step: self.max_step,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            accuracy: self.accuracy,
            diagram: (self.diagram > 0).then_some(DiagramSettings {
                values: self.diagram,
                transient: self.transient,
                iterates: self.iterates,
            }),
            chart: self.chart.clone(),
        })
    }
}

/// What to continue, and how far, resolved for one model from
/// [`ContinuationOptions`].
#[derive(Clone, Debug)]
pub struct ContinuationSettings {
    /// The parameter continued in; it starts at the model's value.
    pub parameter: String,
    /// The other end of the interval [start, to] the branches are followed in.
    pub to: f64,
    /// A guess of the state of the first fixed point (zeros are appended up
    /// to the state's size).
    pub start: Vec<f64>,
    /// The first branch is of fixed points of P^period.
    pub period: usize,
    /// Period doublings are switched at while the new period is at most this.
    pub max_period: usize,
    /// Also switch to the branches crossing at branch points (pitchforks).
    pub switch_branch_points: bool,
    /// At most this many branches in all.
    pub max_branches: usize,
    /// At most this many points per branch.
    pub points: usize,
    /// The first step in arclength, and its bounds.
    pub step: f64,
    pub min_step: f64,
    pub max_step: f64,
    pub method: Method,
    /// The error wanted on the bifurcations' parameters (None: reported,
    /// not chosen).
    pub accuracy: Option<f64>,
    /// The orbit diagram beside the branches, if any.
    pub diagram: Option<DiagramSettings>,
    /// A constrained model's chart: the components of [q; q'] that are
    /// the branches' coordinates, as many as the constraint manifold's
    /// dimension (None: those that parametrise it best at the start).
    /// Other models ignore it.
    pub chart: Option<Vec<usize>>,
}

/// The other end of a continuation in `parameter` when none is given:
/// 1.8 times its value, 1 where it is 0 (or not a parameter of the model).
pub fn default_end(info: &crate::registry::ModelInfo, params: &[f64], parameter: &str) -> f64 {
    let at = info.parameter_names.iter().position(|p| *p == parameter);
    match at.and_then(|i| params.get(i)) {
        Some(0.0) | None => 1.0,
        Some(value) => 1.8 * value,
    }
}

impl ContinuationSettings {
    /// The arclength steps' first value and bounds.
    fn steps(&self) -> Steps {
        Steps {
            initial: self.step,
            min: self.min_step,
            max: self.max_step,
        }
    }
}

/// The brute-force orbit diagram's sampling.
#[derive(Clone, Debug)]
pub struct DiagramSettings {
    /// Parameter values, evenly over the interval.
    pub values: usize,
    /// Periods dropped, then periods drawn, from the settings' start.
    pub transient: usize,
    pub iterates: usize,
}

/// Why a continuation cannot run.
#[derive(Debug, thiserror::Error)]
pub enum ContinuationError {
    /// The analysis does not apply to this kind of model.
    #[error(transparent)]
    Refused(#[from] crate::analysis::Refusal),
    /// M − I is singular at the start: the guess sits on a bifurcation (or a
    /// degenerate orbit), where the branch's direction is not defined.
    #[error("the Jacobian P'(y) − I is singular at the start (parameter {parameter}): the start is a bifurcation, or one of a continuous family of fixed points (a symmetry or a conserved quantity, as a nonholonomic model's rest anywhere); start at another parameter value, or continue orbits that are isolated")]
    SingularJacobian { parameter: f64 },
    #[error("Newton found no fixed point of the period map from {guess:?} at parameter {parameter}: give a better `start`")]
    NoFixedPoint { guess: Vec<f64>, parameter: f64 },
    /// The integration failed during Newton's search for the first point
    /// (a start at a singular point of the model, an orbit that leaves).
    #[error("model '{model}': the orbit from the start {guess:?} (parameter {parameter}) could not be followed while searching for the first point ({source}); start elsewhere")]
    Start {
        model: String,
        guess: Vec<f64>,
        parameter: f64,
        source: OdeError,
    },
    #[error("the first branch has no second point: the step collapsed at parameter {parameter} (step {step:e}); try a smaller `step` or `min_step`")]
    StepCollapse { parameter: f64, step: f64 },
    #[error(transparent)]
    Ode(#[from] OdeError),
    /// A declared setting's value refused.
    #[error(transparent)]
    Setting(#[from] SettingError),
}

/// The kinds of points located on a branch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BifurcationKind {
    /// A turning point of the branch in the parameter (multiplier +1).
    Fold,
    /// Multiplier +1 where the branch goes on: another branch crosses
    /// (a pitchfork in a symmetric system, else transcritical).
    BranchPoint,
    /// Multiplier −1: a branch of twice the period is born.
    PeriodDoubling,
    /// A complex pair of multipliers on the unit circle (dissipative maps
    /// of dimension ≥ 4): an invariant circle is born.
    NeimarkSacker,
    /// A pair of eigenvalues of an equilibrium's Jacobian on the imaginary
    /// axis (dissipative flows): a periodic orbit is born.
    Hopf,
}

/// One point of a branch.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BranchPoint {
    pub parameter: f64,
    /// The fixed point of P^k.
    pub state: Vec<f64>,
    /// The k points of the cycle (the state first).
    #[serde(skip)]
    pub cycle: Vec<Vec<f64>>,
    /// The multipliers (re, im) of P^k (the eigenvalues of the Jacobian for
    /// an equilibrium of a flow), largest modulus first.
    pub multipliers: Vec<(f64, f64)>,
    pub stable: bool,
}

/// A branch of fixed points of P^period.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Branch {
    pub period: usize,
    /// The bifurcation (index into `bifurcations`) it was switched to at.
    pub born_at: Option<usize>,
    pub points: Vec<BranchPoint>,
    pub end: BranchEnd,
    /// The states' numerical error: at up to 8 points spread over the
    /// branch, the fixed point found again at the same parameter with runs
    /// at a hundredth of the tolerance; twice the largest distance, plus
    /// the corrector's convergence (None: not checked, or Newton did not
    /// converge at any of them, as at a fold).
    pub state_error: Option<f64>,
}

/// A located bifurcation.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Bifurcation {
    pub kind: BifurcationKind,
    /// The branch (index) it lies on, and that branch's period.
    pub branch: usize,
    pub period: usize,
    pub parameter: f64,
    /// The parameter's numerical error: twice its distance to the same
    /// bifurcation located from the same bracket with runs at a hundredth
    /// of the tolerance, plus the locating's convergence, 10⁻¹² (1 + |p|)
    /// (None where either was not located).
    pub parameter_error: Option<f64>,
    pub state: Vec<f64>,
    pub multipliers: Vec<(f64, f64)>,
    /// The distance of the critical multiplier from +1 or −1 (or of the
    /// pair's product from 1) at the located point.
    pub residual: f64,
    /// False where the locating corrector failed: the point is then the
    /// end of the bracketing interval.
    pub located: bool,
    /// The branch switched to here, if any.
    pub switched_to: Option<usize>,
    /// A period doubling's: from the side of the parameter the new branch
    /// is born on (None where the old branch is stable or unstable on both
    /// sides, or no branch was switched to).
    pub criticality: Option<Criticality>,
}

/// Where a period doubling's new branch lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Criticality {
    /// Beside the old orbit where it has lost its stability: the new orbit
    /// takes it over (a soft onset, as in Feigenbaum's cascade).
    Supercritical,
    /// Beside the old orbit where it is still stable: the new orbit is the
    /// boundary of its basin, and past the point the motion jumps.
    Subcritical,
}

/// The criticality of a period doubling at p_star whose new branch goes
/// on at p_next, from the old branch's stability on either side.
fn criticality(p_star: f64, p_next: f64, sides: [(f64, bool); 2]) -> Option<Criticality> {
    if sides[0].1 == sides[1].1 {
        return None;
    }
    let born_side = sides
        .iter()
        .find(|(p, _)| (p - p_star).signum() == (p_next - p_star).signum())?;
    Some(match born_side.1 {
        false => Criticality::Supercritical,
        true => Criticality::Subcritical,
    })
}

/// The result (and summary) of a continuation.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Continuation {
    pub model: String,
    pub parameter: String,
    pub params: BTreeMap<String, f64>,
    pub from: f64,
    pub to: f64,
    /// Whether the branches are of equilibria of a flow (a model without
    /// a fast phase), with eigenvalues of the Jacobian for multipliers.
    pub flow: bool,
    /// Whether the map contracts area (det M ≠ 1; for a flow, trace J ≠ 0):
    /// an area-preserving map has no Neimark–Sacker test, a Hamiltonian
    /// flow no Hopf test.
    pub dissipative: bool,
    pub branches: Vec<Branch>,
    pub bifurcations: Vec<Bifurcation>,
    /// The period doublings of the cascade from the first branch, in order
    /// (each on the branch born at the one before).
    pub cascade: Vec<f64>,
    /// (p₂ − p₁)/(p₃ − p₂), … of the cascade (Feigenbaum's δ = 4.6692… in
    /// the limit).
    pub feigenbaum_ratios: Vec<f64>,
    /// Periods of the map integrated (with and without tangents).
    pub map_evaluations: u64,
    pub seconds: f64,
    pub diagram: Option<OrbitDiagram>,
    /// A constrained model's chart: the components of [q; q'] that the
    /// branches' states are (None: the full state).
    pub chart: Option<Vec<usize>>,
    /// Whether the `accuracy` asked for was reached, and by which run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
    /// The state's names, for the figure.
    #[serde(skip)]
    pub state_names: Vec<&'static str>,
}

/// The period map of a model as a function of one parameter, its sizes
/// erased: what the continuation needs of the model.
trait FamilyMap: Sync {
    /// The model with one parameter free.
    fn family(&self) -> &Family;
    /// Which state components are angles.
    fn periodic(&self) -> &[bool];
    /// Whether the branches are of equilibria of a flow (a model without a
    /// fast phase) rather than of fixed points of a period map.
    fn flow(&self) -> bool {
        !self.family().model.has_fast_phase()
    }
    /// The flow's field f(y; p) and its Jacobian ∂f/∂y.
    fn field(&self, y: &[f64], p: f64) -> (Vec<f64>, DMatrix<f64>);
    /// Whether the model accepts this value of the parameter.
    fn parameter_allowed(&self, p: f64) -> bool {
        self.family().parameter_allowed(p)
    }
    /// One period of the map from `y` at the parameter value p and, if
    /// `jacobian`, its monodromy matrix.
    fn once(
        &self,
        y: &[f64],
        p: f64,
        jacobian: bool,
    ) -> Result<(Vec<f64>, Option<DMatrix<f64>>), OdeError>;
    /// The orbit diagram: for each parameter value, the iterates after the
    /// transient from `start`.
    fn diagram(
        &self,
        values: &[f64],
        start: &[f64],
        transient: usize,
        iterates: usize,
    ) -> Vec<Result<Vec<Vec<f64>>, OdeError>>;
    /// Periods integrated so far.
    fn evaluations(&self) -> u64 {
        self.family().evaluations.load(Ordering::Relaxed)
    }
}

/// Continues the periodic orbits of `model` at `params` (declaration
/// order) in the parameter `settings.parameter`.
pub fn continuation(
    model: &Model,
    params: &[f64],
    settings: &ContinuationSettings,
) -> Result<Continuation, ContinuationError> {
    let Some(accuracy) = settings.accuracy else {
        return continuation_once(model, params, settings);
    };
    let what = "the bifurcations' parameters";
    Refusal::accuracy_within_reach(model.info.name, what, Some(accuracy), settings.to.abs())?;
    let (mut result, method, error, reached) = crate::analysis::check::until_accurate(
        settings.method,
        accuracy,
        |method| {
            continuation_once(
                model,
                params,
                &ContinuationSettings {
                    method,
                    ..settings.clone()
                },
            )
        },
        |result| {
            // A bifurcation without an error (not located again) leaves the
            // accuracy unknown.
            result
                .bifurcations
                .iter()
                .map(|b| b.parameter_error.unwrap_or(f64::INFINITY))
                .fold(0.0, f64::max)
        },
    )?;
    result.accuracy = Some(format!(
        "accuracy {accuracy:e} {} with {}: the largest error of a bifurcation's parameter is {error:.1e}",
        crate::analysis::check::reached_text(reached),
        method.describe()
    ));
    Ok(result)
}

/// [`continuation`] at `settings.method`, without an accuracy asked.
fn continuation_once(
    model: &Model,
    params: &[f64],
    settings: &ContinuationSettings,
) -> Result<Continuation, ContinuationError> {
    if let Some(constrained) = model.constrained {
        crate::analysis::method_applies(model, settings.method)?;
        return on_constraints(constrained, params, settings);
    }
    let systems = crate::analysis::hamiltonian(model)?;
    let info = systems.info();
    let name = info.name.to_string();
    let index = Refusal::parameter_index(info, &settings.parameter)?;
    let named = Refusal::named_values(info, params)?;
    let map = AtModel::new(systems, params, index, settings.method);
    // No tighter run at the precision floor: the errors are not stated.
    let tighter = (settings.method.check_run()).map(|m| AtModel::new(systems, params, index, m));
    let tighter = tighter.as_ref().map(|t| t as &dyn FamilyMap);
    let mut result = run(&map, tighter, params[index], settings, &name)?;
    result.params = named;
    result.state_names = info.state_names();
    Ok(result)
}

/// [`continuation`] of a constrained model, in the chart of its
/// constraints that parametrises them best at the start: `settings.start`
/// is a full state [q; q'] (the model file's start where it is shorter),
/// the branches' states are the chart's coordinates, named.
fn on_constraints(
    model: &'static dyn crate::registry::ConstrainedSystems,
    params: &[f64],
    settings: &ContinuationSettings,
) -> Result<Continuation, ContinuationError> {
    let info = model.info();
    let name = info.name.to_string();
    let index = Refusal::parameter_index(info, &settings.parameter)?;
    let named = Refusal::named_values(info, params)?;
    let mut start = model.base_state(params);
    if settings.start.len() > start.len() || !settings.start.iter().all(|x| x.is_finite()) {
        return Err(Refusal::setting(
            info.name,
            "`start` must be finite, with at most one value per state component",
        )
        .into());
    }
    start[..settings.start.len()].copy_from_slice(&settings.start);
    let held = settings.chart.as_deref();
    let map = chart::ChartMap::new(model, params, index, settings.method, &start, held).map_err(
        |source| ContinuationError::Start {
            model: name.clone(),
            guess: start.clone(),
            parameter: params[index],
            source,
        },
    )?;
    let in_chart = ContinuationSettings {
        start: map.chart(map.start()),
        ..settings.clone()
    };
    let tighter = (settings.method.check_run())
        .map(|m| chart::ChartMap::new(model, params, index, m, &start, Some(map.held())))
        .transpose()
        .map_err(|source| ContinuationError::Start {
            model: name.clone(),
            guess: start.clone(),
            parameter: params[index],
            source,
        })?;
    let tighter = tighter.as_ref().map(|t| t as &dyn FamilyMap);
    let mut result = run(&map, tighter, params[index], &in_chart, &name)?;
    result.params = named;
    let names = info.state_names();
    result.state_names = map.held().iter().map(|&i| names[i]).collect();
    result.chart = Some(map.held().to_vec());
    Ok(result)
}

/// A periodic orbit followed in one parameter for `stability`: the states
/// along its branch and the first interval where it is stable.
pub(crate) struct OrbitBranch {
    /// (parameter, state) of every point, by increasing parameter.
    pub states: Vec<(f64, Vec<f64>)>,
    /// Each edge the located stability change; None above: stable up to
    /// the interval's end. None: never stable.
    pub window: Option<[Option<f64>; 2]>,
}

/// The branch in the parameter `index` of the periodic orbit through
/// `start` (a fixed point of P at the parameter's value in `params`),
/// followed down to `bounds.0` and up to `bounds.1`, and its window. For
/// the orbits of `stability` that the vibration moves off an equilibrium,
/// followed from amplitude 0, where the equilibrium is one.
pub(crate) fn orbit_branch(
    model: &'static dyn Systems,
    params: &[f64],
    index: usize,
    method: Method,
    start: &[f64],
    bounds: (f64, f64),
) -> Result<OrbitBranch, ContinuationError> {
    let map = AtModel::new(model, params, index, method);
    let p0 = params[index];
    let name = model.info().name;
    // (parameter, stable, state) along the branch, and the located changes.
    let mut along: Vec<(f64, bool, Vec<f64>)> = Vec::new();
    let mut changes: Vec<f64> = Vec::new();
    for to in [bounds.0, bounds.1] {
        if to == p0 {
            continue;
        }
        let settings = ContinuationSettings {
            parameter: model.info().parameter_names[index].into(),
            to,
            start: start.to_vec(),
            period: 1,
            max_period: 1,
            switch_branch_points: false,
            max_branches: 1,
            points: 2000,
            step: 0.01,
            min_step: 1e-9,
            max_step: 0.05 * (bounds.1 - bounds.0).max(1e-3),
            method,
            accuracy: None,
            diagram: None,
            chart: None,
        };
        let result = run(&map, None, p0, &settings, name)?;
        along.extend(
            result.branches[0]
                .points
                .iter()
                .map(|p| (p.parameter, p.stable, p.state.clone())),
        );
        changes.extend(result.bifurcations.iter().map(|b| b.parameter));
    }
    // Only the branch within the bounds: past a fold it may go on below
    // the lower bound (to negative amplitudes), where a stability change
    // is no edge of the window on (bounds.0, bounds.1].
    let inside = |p: f64| (bounds.0..=bounds.1).contains(&p);
    along.retain(|p| inside(p.0));
    changes.retain(|&p| inside(p));
    along.sort_by(|a, b| a.0.total_cmp(&b.0));
    changes.sort_by(f64::total_cmp);
    // The change between two points of the branch (their midpoint if none
    // was located there).
    let edge = |a: f64, b: f64| {
        changes
            .iter()
            .copied()
            .find(|c| *c >= a.min(b) && *c <= a.max(b))
            .unwrap_or(0.5 * (a + b))
    };
    let states = along.iter().map(|(p, _, y)| (*p, y.clone())).collect();
    let Some(first) = along.iter().position(|p| p.1) else {
        return Ok(OrbitBranch {
            states,
            window: None,
        });
    };
    // Stable from the lowest point: from the bound (the branch's last step
    // may overshoot it).
    let lower = match first {
        0 => bounds.0,
        _ => edge(along[first - 1].0, along[first].0),
    };
    let upper = along[first..]
        .windows(2)
        .find(|w| !w[1].1)
        .map(|w| edge(w[0].0, w[1].0))
        .filter(|&p| p <= bounds.1);
    Ok(OrbitBranch {
        states,
        window: Some([Some(lower.max(bounds.0)), upper]),
    })
}

/// A model at fixed values of all parameters but one: what both family
/// maps share (the parameters, the method, the periods integrated).
struct Family {
    model: &'static dyn crate::registry::Flows,
    params: Vec<f64>,
    index: usize,
    method: Method,
    evaluations: AtomicU64,
}

impl Family {
    fn new(
        model: &'static dyn crate::registry::Flows,
        params: &[f64],
        index: usize,
        method: Method,
    ) -> Self {
        Family {
            model,
            params: params.to_vec(),
            index,
            method,
            evaluations: AtomicU64::new(0),
        }
    }

    /// The parameters at the free one's value p.
    fn with(&self, p: f64) -> Vec<f64> {
        let mut params = self.params.clone();
        params[self.index] = p;
        params
    }

    fn period(&self, params: &[f64]) -> Result<f64, OdeError> {
        match self.model.phase_period(params) {
            Some(t) if t.is_finite() && t > 0.0 => Ok(t),
            t => Err(OdeError::InvalidSetting {
                what: "period of the phase at this parameter value",
                value: t.unwrap_or(f64::NAN),
            }),
        }
    }

    /// One period at p counted: the parameters, the period, an integrator.
    fn period_at(&self, p: f64) -> Result<(Vec<f64>, f64, Integrator), OdeError> {
        self.count(1);
        let params = self.with(p);
        let period = self.period(&params)?;
        Ok((params, period, Integrator::new(self.method)?))
    }

    fn count(&self, periods: usize) {
        self.evaluations
            .fetch_add(periods as u64, Ordering::Relaxed);
    }

    fn parameter_allowed(&self, p: f64) -> bool {
        let info = self.model.info();
        info.check_parameter(info.parameter_names[self.index], p)
            .is_ok()
    }
}

/// A Hamiltonian model's period map (or flow) in one parameter.
struct AtModel {
    model: &'static dyn Systems,
    family: Family,
    periodic: Vec<bool>,
}

impl AtModel {
    /// The model at `params`, its parameter `index` free: a map if it has
    /// a fast phase, a flow if not.
    fn new(model: &'static dyn Systems, params: &[f64], index: usize, method: Method) -> Self {
        AtModel {
            model,
            family: Family::new(model, params, index, method),
            periodic: model.periodic_state(),
        }
    }
}

impl FamilyMap for AtModel {
    fn family(&self) -> &Family {
        &self.family
    }

    fn periodic(&self) -> &[bool] {
        &self.periodic
    }

    fn field(&self, y: &[f64], p: f64) -> (Vec<f64>, DMatrix<f64>) {
        self.family.count(1);
        let system = self.model.exact(&self.family.with(p));
        let n = system.dim();
        let f = system.rhs(0.0, y).expect("a state of the model's length");
        let jacobian = system
            .jacobian(0.0, y)
            .expect("a state of the model's length");
        let jacobian = jacobian.unwrap_or_else(|| DMatrix::from_element(n, n, f64::NAN));
        (f, jacobian)
    }

    fn once(
        &self,
        y: &[f64],
        p: f64,
        jacobian: bool,
    ) -> Result<(Vec<f64>, Option<DMatrix<f64>>), OdeError> {
        let (params, period, mut integrator) = self.family.period_at(p)?;
        if jacobian {
            let (image, m) = self.model.monodromy(&params, &mut integrator, period, y)?;
            Ok((image, Some(m)))
        } else {
            let system = self.model.exact(&params);
            let end = system.solve(&mut integrator, 0.0, y, period, AnyOptions::default())?;
            Ok((end.y, None))
        }
    }

    fn diagram(
        &self,
        values: &[f64],
        start: &[f64],
        transient: usize,
        iterates: usize,
    ) -> Vec<Result<Vec<Vec<f64>>, OdeError>> {
        let problems: Vec<_> = values
            .iter()
            .map(|&p| {
                let params = self.family.with(p);
                let period = self.family.period(&params);
                (self.model.exact(&params), period)
            })
            .collect();
        self.family.count(values.len() * (transient + iterates));
        let (method, wrap) = (self.family.method, &self.periodic);
        diagram::iterates(method, &problems, start, wrap, transient, iterates)
    }
}

/// A branch to follow: its period, its first point (with the direction to
/// go in as its tangent) and where it was born.
struct Job {
    period: usize,
    start: Solution,
    born_at: Option<usize>,
    origin: Origin,
    /// (parameter, stable) of the parent branch's points on either side of
    /// the bifurcation, to tell a period doubling's criticality.
    sides: [(f64, bool); 2],
}

/// The continuation proper, on the erased map (and, where given, the same
/// at a hundredth of the tolerance, which locates each bifurcation again
/// for its error).
fn run(
    map: &dyn FamilyMap,
    tighter: Option<&dyn FamilyMap>,
    p0: f64,
    settings: &ContinuationSettings,
    model: &str,
) -> Result<Continuation, ContinuationError> {
    let clock = std::time::Instant::now();
    let n = map.periodic().len();
    check(settings, p0, n, model)?;
    let mut guess = settings.start.clone();
    guess.resize(n, 0.0);
    let forward = settings.to > p0;
    let bounds = (p0.min(settings.to), p0.max(settings.to));
    let (first, dissipative) = first_orbit(map, settings.period, &guess, p0, forward, model)?;
    let steps = settings.steps();
    let mut branches: Vec<Branch> = Vec::new();
    let mut bifurcations: Vec<Bifurcation> = Vec::new();
    let mut jobs = std::collections::VecDeque::from([Job {
        period: settings.period,
        start: first,
        born_at: None,
        origin: Origin::Start,
        sides: [(f64::NAN, false); 2],
    }]);
    while let Some(job) = jobs.pop_front() {
        if branches.len() >= settings.max_branches {
            break;
        }
        // A bubble's branch already followed from its other end.
        let rejoined = |b: &Branch| match b.end {
            BranchEnd::Rejoined { parameter } => {
                b.period == job.period
                    && (parameter - job.start.p).abs() < 1e-6 * (1.0 + parameter.abs())
            }
            _ => false,
        };
        if let Some(same) = branches.iter().position(rejoined) {
            if let Some(at) = job.born_at {
                bifurcations[at].switched_to = Some(same);
            }
            continue;
        }
        let index = branches.len();
        let k = job.period;
        if let Some(at) = job.born_at {
            bifurcations[at].switched_to.get_or_insert(index);
        }
        let followed = branch::follow(
            map,
            k,
            job.start,
            job.origin,
            steps,
            bounds,
            settings.points,
        );
        if let (Some(at), Origin::PeriodDoubling) = (job.born_at, job.origin) {
            let first = bifurcations[at].criticality.is_none();
            if let (true, Some(next)) = (first, followed.points.get(1)) {
                let born = followed.points[0].p;
                bifurcations[at].criticality = criticality(born, next.p, job.sides);
            }
        }
        if index == 0 && followed.points.len() < 2 {
            if let BranchEnd::StepCollapse { parameter, step } = followed.end {
                return Err(ContinuationError::StepCollapse { parameter, step });
            }
        }
        let changes = branch::sign_changes(&followed.points, dissipative, job.born_at.is_some());
        for (i, kind, test) in changes {
            let pair = [&followed.points[i], &followed.points[i + 1]];
            let at = Located {
                map,
                tighter,
                k,
                branch: index,
                kind,
                test,
            };
            at.record(pair, settings, &branches, &mut jobs, &mut bifurcations);
        }
        branches.push(Branch {
            period: k,
            born_at: job.born_at,
            points: followed.points.iter().map(branch_point).collect(),
            end: followed.end,
            state_error: tighter.and_then(|t| state_error(t, k, &followed.points)),
        });
    }
    let cascade = cascade(&branches, &bifurcations);
    let feigenbaum_ratios = feigenbaum_ratios(&cascade);
    // A flow has no period map to draw the attractor of.
    let diagram = settings
        .diagram
        .as_ref()
        .filter(|_| !map.flow())
        .map(|d| diagram::orbit_diagram(map, bounds, &guess, d));
    Ok(Continuation {
        model: model.into(),
        parameter: settings.parameter.clone(),
        params: BTreeMap::new(),
        from: p0,
        to: settings.to,
        flow: map.flow(),
        dissipative,
        branches,
        bifurcations,
        cascade,
        feigenbaum_ratios,
        map_evaluations: map.evaluations(),
        seconds: clock.elapsed().as_secs_f64(),
        diagram,
        chart: None,
        accuracy: None,
        state_names: Vec::new(),
    })
}

/// (p₂ − p₁)/(p₃ − p₂) of each three successive period doublings.
fn feigenbaum_ratios(cascade: &[f64]) -> Vec<f64> {
    (cascade.windows(3))
        .map(|w| (w[1] - w[0]) / (w[2] - w[1]))
        .collect()
}

/// The error of a branch's states ([`Branch::state_error`]) from the
/// `tighter` map.
fn state_error(tighter: &dyn FamilyMap, k: usize, points: &[Solution]) -> Option<f64> {
    let periodic = tighter.periodic();
    let distances: Vec<f64> = crate::analysis::check::sample_pixels(points.len(), 8)
        .into_par_iter()
        .filter_map(|i| {
            let point = &points[i];
            let again = branch::first_point(tighter, k, point.y.as_slice(), point.p, true).ok()?;
            let apart = (point.y.iter().zip(again.y.iter()).zip(periodic))
                .map(|((a, b), &angle)| match angle {
                    true => crate::ode::wrap_angle(a - b).abs(),
                    false => (a - b).abs(),
                })
                .fold(0.0, f64::max);
            Some(2.0 * apart + 1e-11 * (1.0 + point.y.norm()))
        })
        .collect();
    distances.into_iter().reduce(f64::max)
}

/// A bifurcation between two points of branch `branch` (of period `k`),
/// found by the sign change of `test`.
struct Located<'a> {
    map: &'a dyn FamilyMap,
    tighter: Option<&'a dyn FamilyMap>,
    k: usize,
    branch: usize,
    kind: BifurcationKind,
    test: branch::TestFunction,
}

impl Located<'_> {
    /// Locates the bifurcation between the points `[a, b]`, queues the
    /// branches to switch to and records it.
    fn record(
        &self,
        [a, b]: [&Solution; 2],
        settings: &ContinuationSettings,
        branches: &[Branch],
        jobs: &mut std::collections::VecDeque<Job>,
        bifurcations: &mut Vec<Bifurcation>,
    ) {
        let Located {
            map, k, kind, test, ..
        } = *self;
        let (point, located) = branch::locate(map, k, a, b, test);
        let parameter_error = self
            .tighter
            .filter(|_| located)
            .map(|tighter| branch::locate(tighter, k, a, b, test))
            .and_then(|(again, found)| {
                // (Plus the locating's own convergence, 10⁻¹² (1 + |p|).)
                found.then(|| 2.0 * (again.p - point.p).abs() + 1e-12 * (1.0 + point.p.abs()))
            });
        let at = bifurcations.len();
        let before = &a.tangent;
        let stable = |s: &Solution| branch_point(s).stable;
        let sides = [(a.p, stable(a)), (b.p, stable(b))];
        for (period, start) in switch(k, &point, before, kind, settings, branches, jobs) {
            let origin = if period == k {
                Origin::BranchPoint
            } else {
                Origin::PeriodDoubling
            };
            jobs.push_back(Job {
                period,
                start,
                born_at: Some(at),
                origin,
                sides,
            });
        }
        bifurcations.push(Bifurcation {
            kind,
            branch: self.branch,
            period: k,
            parameter: point.p,
            parameter_error,
            state: point.y.iter().copied().collect(),
            multipliers: multipliers_of(&point.monodromy),
            residual: residual(&point, kind),
            located,
            switched_to: None,
            criticality: None,
        });
    }
}

/// The first periodic orbit (of period `period`), from the user's `guess`
/// at `p0`, and whether the map is dissipative there.
fn first_orbit(
    map: &dyn FamilyMap,
    period: usize,
    guess: &[f64],
    p0: f64,
    forward: bool,
    model: &str,
) -> Result<(Solution, bool), ContinuationError> {
    let first = branch::first_point(map, period, guess, p0, forward).map_err(|e| match e {
        ContinuationError::Ode(source) => ContinuationError::Start {
            model: model.into(),
            guess: guess.to_vec(),
            parameter: p0,
            source,
        },
        other => other,
    })?;
    // An area-preserving map has det M = 1, a Hamiltonian flow trace J = 0.
    let dissipative = if map.flow() {
        first.monodromy.trace().abs() > 1e-8 * (1.0 + first.monodromy.amax())
    } else {
        (first.monodromy.determinant() - 1.0).abs() > 1e-6
    };
    Ok((first, dissipative))
}

/// The settings' sanity, as named errors.
fn check(
    settings: &ContinuationSettings,
    p0: f64,
    n: usize,
    model: &str,
) -> Result<(), ContinuationError> {
    let bad = |requirement: &'static str| Err(Refusal::setting(model, requirement).into());
    if !settings.to.is_finite() || settings.to == p0 {
        return bad("`to` must be finite and differ from the parameter's value");
    }
    if settings.start.len() > n || !settings.start.iter().all(|x| x.is_finite()) {
        return bad("`start` must be finite, with at most one value per state component");
    }
    if settings.period == 0 || settings.max_period < settings.period {
        return bad("period ≥ 1 and max_period ≥ period");
    }
    let steps_ok = settings.min_step > 0.0
        && settings.min_step <= settings.step
        && settings.step <= settings.max_step
        && settings.max_step.is_finite();
    if !steps_ok {
        return bad("0 < min_step ≤ step ≤ max_step < ∞");
    }
    if settings.points < 2 {
        return bad("points ≥ 2");
    }
    Ok(())
}

/// The first points of the branches to switch to at a bifurcation (none
/// if none): at a period doubling (new period ≤ max_period) the branch of
/// P^{2k} along the eigenvector of −1; at a branch point (if asked) the
/// crossing branch both ways. Not where a branch was already switched to
/// at the same point (a branch that comes back to it).
fn switch(
    k: usize,
    point: &Solution,
    before: &DVector<f64>,
    kind: BifurcationKind,
    settings: &ContinuationSettings,
    branches: &[Branch],
    queued: &std::collections::VecDeque<Job>,
) -> Vec<(usize, Solution)> {
    let near =
        |p: f64, y: &DVector<f64>| (p - point.p).abs() < 1e-7 && (y - &point.y).amax() < 1e-6;
    let seen = branches
        .iter()
        .filter_map(|b| b.points.first())
        .any(|q| near(q.parameter, &DVector::from_column_slice(&q.state)))
        || queued.iter().any(|j| near(j.start.p, &j.start.y));
    if seen {
        return Vec::new();
    }
    // The new branch's direction: at a period doubling (v, 0) itself (the
    // branch of P^{2k} is tangent to it); at a branch point the part of
    // (v, 0) across the old branch (its tangent before the point: at the
    // point itself the tangent is not defined), so that the corrector's
    // hyperplane does not hold the old branch's next point.
    let away = |direction: DVector<f64>, period: usize, monodromy: DMatrix<f64>| {
        let t = before;
        let direction = if period == k {
            &direction - t * t.dot(&direction)
        } else {
            direction
        };
        let norm = direction.norm();
        (norm > 1e-8).then(|| Solution {
            y: point.y.clone(),
            p: point.p,
            tangent: direction / norm,
            monodromy,
            cycle: point.cycle.iter().cycle().take(period).cloned().collect(),
            flow: point.flow,
        })
    };
    let n = point.y.len();
    let padded = |v: DVector<f64>| DVector::from_fn(n + 1, |i, _| if i < n { v[i] } else { 0.0 });
    match kind {
        BifurcationKind::PeriodDoubling if 2 * k <= settings.max_period => {
            let v = branch::eigenvector_near(&point.monodromy, -1.0);
            let m2 = &point.monodromy * &point.monodromy;
            away(padded(v), 2 * k, m2).map_or_else(Vec::new, |s| vec![(2 * k, s)])
        }
        BifurcationKind::BranchPoint if settings.switch_branch_points => {
            // The null vector of M − I (of J for a flow).
            let target = if point.flow { 0.0 } else { 1.0 };
            let v = branch::eigenvector_near(&point.monodromy, target);
            let Some(forward) = away(padded(v), k, point.monodromy.clone()) else {
                return Vec::new();
            };
            let mut backward = forward.clone();
            backward.tangent = -backward.tangent;
            vec![(k, forward), (k, backward)]
        }
        _ => Vec::new(),
    }
}

/// The period doublings of the cascade that starts on the first branch.
fn cascade(branches: &[Branch], bifurcations: &[Bifurcation]) -> Vec<f64> {
    let mut values = Vec::new();
    let mut branch = 0;
    loop {
        let Some(pd) = bifurcations
            .iter()
            .find(|b| b.branch == branch && b.kind == BifurcationKind::PeriodDoubling)
        else {
            return values;
        };
        values.push(pd.parameter);
        match pd.switched_to {
            Some(next) if next < branches.len() => branch = next,
            _ => return values,
        }
    }
}

/// How far the critical multiplier is from where the bifurcation puts it.
fn residual(point: &Solution, kind: BifurcationKind) -> f64 {
    let values = multipliers_of(&point.monodromy);
    let nearest = |target: f64| {
        values
            .iter()
            .map(|(re, im)| (re - target).hypot(*im))
            .fold(f64::INFINITY, f64::min)
    };
    match kind {
        BifurcationKind::Fold | BifurcationKind::BranchPoint if point.flow => nearest(0.0),
        BifurcationKind::Fold | BifurcationKind::BranchPoint => nearest(1.0),
        BifurcationKind::PeriodDoubling => nearest(-1.0),
        BifurcationKind::NeimarkSacker => values
            .iter()
            .filter(|(_, im)| im.abs() > 0.0)
            .map(|(re, im)| (re.hypot(*im) - 1.0).abs())
            .fold(f64::INFINITY, f64::min),
        BifurcationKind::Hopf => values
            .iter()
            .filter(|(_, im)| im.abs() > 0.0)
            .map(|(re, _)| re.abs())
            .fold(f64::INFINITY, f64::min),
    }
}

fn branch_point(s: &Solution) -> BranchPoint {
    let multipliers = multipliers_of(&s.monodromy);
    // An equilibrium is stable with no eigenvalue right of the imaginary
    // axis (beyond round-off), a fixed point with no multiplier outside
    // the unit circle.
    let stable = if s.flow {
        let scale = 1.0 + s.monodromy.amax();
        multipliers.iter().all(|(re, _)| *re <= 1e-7 * scale)
    } else {
        // Per iteration of the map (a damped map's growth rate per
        // iterate): the criterion of the exact windows, which holds however
        // short the forcing period.
        Verdict::of_monodromy(&s.monodromy, 1.0) != Verdict::Unstable
    };
    BranchPoint {
        parameter: s.p,
        state: s.y.iter().copied().collect(),
        cycle: s.cycle.clone(),
        multipliers,
        stable,
    }
}
