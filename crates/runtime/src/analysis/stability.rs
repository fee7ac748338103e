//! Stabilisation by vibration for any model with a fast phase, by name: the
//! equilibria of the system without vibration that stay equilibria of the
//! averaged system, the roots λ of det(C − λA) = 0, the threshold of the
//! vibration's amplitude from the averaged system, and the exact system's
//! stability window in the amplitude from its Floquet multipliers.
//!
//! The threshold needs no scan: V_vibr is quadratic in the amplitude a (it
//! is ½ mean(bᵀA⁻¹b) and b is linear in the base's velocity), so the Hessian
//! of V + V_vibr at an equilibrium is C + a²K. The equilibrium is stable in
//! the averaged system iff C + a²K is positive definite; with K positive
//! definite that is a² > μ_max, the largest root of det(−C − μK) = 0. The
//! generated Hessian is evaluated at a = 0, 1, 2 to find C and K, and the
//! quadratic dependence is checked (else the reason is given).

use super::continuation::{orbit_branch, OrbitBranch};
use super::equilibria::cyclic_coordinates;
use super::floquet::{
    first_onset_in_batches, multipliers_of, spectral_radius, stability_margin, window_in_batches,
};
use super::tiles::{fingerprint, run_tiles, TileError, Tiles};
use super::vibrational_stability::generalized_eigenvalues_of;
use crate::analysis::period_map::wrap_angle;
use crate::analysis::Refusal;
use crate::ode::{Method, OdeError};
use crate::registry::{DynamicModel, Model, Systems};
use crate::settings::{method, Declared, Range, SettingError, SettingValue, METHODS};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use std::cell::RefCell;
use std::collections::BTreeMap;

crate::declare_settings! {
    /// Stabilisation by vibration: for every equilibrium of the system
    /// without vibration, the averaged threshold a* of the amplitude and
    /// the exact system's window of Floquet stability.
    pub struct StabilityOptions for "stability" {
        /// The parameter that scales the vibration (auto: the model file's
        /// [fast_phase] amplitude).
        amplitude: Option<String> = None, Range::Any;
        /// Amplitudes sampled on (0, a_max] to bracket the exact window's
        /// edges.
        samples: usize = 40, Range::Count { min: 2, max: 100_000 };
        /// The largest amplitude of the exact window (auto: 3 a*).
        a_max: Option<f64> = None, Range::Positive;
        /// At most this many equilibria get an exact window (a Floquet
        /// sweep each), `first` first.
        max_windows: usize = MAX_WINDOWS, Range::Count { min: 0, max: 1_000_000 };
        /// The equilibria that get an exact window first: lowest (the lowest
        /// thresholds a*), highest (the one of greatest potential energy:
        /// a chain held upside down), or coordinates q1,q2;q1,q2 (each the
        /// equilibrium found nearest).
        first: FirstWindows = FirstWindows::Lowest, Range::Any;
        /// The window's edges (and a chart's boundaries) are bisected to
        /// this.
        edge_tolerance: f64 = 1e-9, Range::Positive;
        /// The error wanted on the exact window's edges (auto: none asked,
        /// each edge comes with the error of the run at `tol`). Given, the
        /// edges are bisected to a quarter of it and `tol` is tightened a
        /// hundredfold until their error is within it, or the result says
        /// why it cannot be.
        accuracy: Option<f64> = None, Range::Positive;
        /// The integration method of the monodromy matrices.
        method: String = "dop853".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-10, Range::Positive;
    }
}

impl StabilityOptions {
    /// The settings of [`stability`] for `model`, `auto` resolved.
    pub fn resolve(&self, model: &Model) -> Result<Settings, SettingError> {
        let info = model.info;
        let amplitude = match (&self.amplitude, info.amplitude) {
            (Some(a), _) => a.clone(),
            (None, Some(a)) => a.to_string(),
            (None, None) => {
                return Err(SettingError::NoAmplitude {
                    analysis: Self::ANALYSIS,
                    name: "amplitude",
                    model: info.name,
                    known: info.parameter_names,
                })
            }
        };
        Ok(Settings {
            amplitude,
            a_max: self.a_max,
            samples: self.samples,
            edge_tolerance: self.edge_tolerance,
            accuracy: self.accuracy,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            max_windows: self.max_windows,
            first: self.first.clone(),
        })
    }
}

/// Which equilibria get an exact window first.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum FirstWindows {
    /// Those with the lowest thresholds a*.
    #[default]
    Lowest,
    /// The one of greatest potential energy V (a chain held upside down).
    Highest,
    /// The equilibria found nearest these coordinates.
    At(Vec<Vec<f64>>),
}

impl SettingValue for FirstWindows {
    const KIND: &'static str = "lowest, highest, or coordinates q1,q2;…";
    const PYTHON: &'static str = "str | Sequence[Sequence[float]]";
    fn from_text(text: &str) -> Option<Self> {
        match text.trim() {
            "lowest" => Some(FirstWindows::Lowest),
            "highest" => Some(FirstWindows::Highest),
            states => states
                .split(';')
                .map(Vec::<f64>::from_text)
                .collect::<Option<_>>()
                .map(FirstWindows::At),
        }
    }
    fn from_json(value: &serde_json::Value) -> Option<Self> {
        match value {
            serde_json::Value::String(s) => Self::from_text(s),
            serde_json::Value::Array(states) => states
                .iter()
                .map(Vec::<f64>::from_json)
                .collect::<Option<_>>()
                .map(FirstWindows::At),
            _ => None,
        }
    }
    fn to_json(&self) -> serde_json::Value {
        match self {
            FirstWindows::At(states) => serde_json::json!(states),
            _ => serde_json::Value::String(self.to_text()),
        }
    }
    fn to_text(&self) -> String {
        match self {
            FirstWindows::Lowest => "lowest".into(),
            FirstWindows::Highest => "highest".into(),
            FirstWindows::At(states) => states
                .iter()
                .map(|q| q.to_text())
                .collect::<Vec<_>>()
                .join(";"),
        }
    }
    fn within(&self, _: &Range) -> bool {
        true
    }
}

/// How the analysis runs, resolved for one model from
/// [`StabilityOptions`].
#[derive(Clone, Debug)]
pub struct Settings {
    /// The parameter that scales the vibration.
    pub amplitude: String,
    /// The exact window is searched on (0, a_max]; None: 3 a* (3 times the
    /// amplitude's value where there is no a*).
    pub a_max: Option<f64>,
    /// Equal steps on (0, a_max] that bracket the window's edges.
    pub samples: usize,
    /// The edges are bisected to this (absolute) tolerance.
    pub edge_tolerance: f64,
    /// The error wanted on the edges (None: the error of `method` is
    /// reported, not chosen).
    pub accuracy: Option<f64>,
    /// Integration method of the monodromy matrices.
    pub method: Method,
    /// At most this many equilibria get an exact window (a sweep of Floquet
    /// multipliers each): those with the lowest thresholds, then those the
    /// vibration moves; the others say why they have none.
    pub max_windows: usize,
    /// Which equilibria come first for their window.
    pub first: FirstWindows,
}

/// The default of [`Settings::max_windows`]: every equilibrium of a chain of
/// up to 6 links.
pub const MAX_WINDOWS: usize = 64;

/// What the analysis says about one equilibrium.
#[derive(Clone, Debug, Serialize)]
pub struct EquilibriumStability {
    pub q: Vec<f64>,
    /// Roots of det(C − λA) = 0, ascending.
    pub lambdas: Vec<f64>,
    pub stable_without_vibration: bool,
    /// The amplitude above which the averaged system is stable here.
    pub a_star: Option<f64>,
    /// The same threshold from the system averaged to second order in
    /// ε = 1/rate at the given rate (null where it is not derived or not
    /// found): it moves a* by O(ε²) towards the exact lower edge.
    pub a_star_second_order: Option<f64>,
    /// Why there is no a*, when there is none.
    pub reason: Option<String>,
    /// The first interval of the amplitude on which the exact system is
    /// stable at (q, 0): [lower, upper] (upper null if beyond a_max).
    pub exact_window: Option<[Option<f64>; 2]>,
    /// Each edge's numerical error: its distance to the same edge found
    /// with the run of `exact_window_check`, plus both bisections' half
    /// brackets (null where that run finds no edge near it).
    pub exact_window_error: Option<[Option<f64>; 2]>,
    /// The runs the window and its error come from, and whether the
    /// `accuracy` asked for was reached.
    pub exact_window_check: Option<String>,
    /// Why there is no exact window, when there is none.
    pub exact_reason: Option<String>,
    /// (a, spectral radius of the monodromy matrix) where it was computed.
    pub spectral_radius: Vec<[f64; 2]>,
    /// At a pole of the chart (the mass matrix singular along cyclic
    /// coordinates only, as the azimuth at a pole of spherical
    /// coordinates): those coordinates, whose rows and columns are dropped
    /// from A, C and K. Their momenta are conserved, and at 0 the reduced
    /// system's potential is V + V_vibr itself, so the roots, a* and the
    /// verdict are the reduced system's, the ones `explore` gives.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub reduced_by: Vec<usize>,
}

/// The result (and summary) of the analysis.
#[derive(Clone, Debug, Serialize)]
pub struct Stability {
    pub model: String,
    /// The model's coordinates, for the figure's titles.
    #[serde(skip)]
    pub coordinates: &'static [&'static str],
    pub amplitude: String,
    pub params: BTreeMap<String, f64>,
    pub equilibria: Vec<EquilibriumStability>,
    /// Equilibria of the system without vibration that the vibration moves
    /// (not equilibria of the averaged system, or (q, 0) not a solution of
    /// the exact one: its periodic orbit nearby is not analysed yet).
    pub moved_by_vibration: Vec<MovedEquilibrium>,
    /// Why `equilibria` is empty, when it is.
    #[serde(serialize_with = "as_text")]
    pub none_because: Option<NoEquilibria>,
    /// The search for equilibria, where it sampled its grid of starts (more
    /// than 8 degrees of freedom): equilibria may be missing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub search_sampled: Option<super::equilibria::Search>,
}

impl Stability {
    /// What a scene prints: the equilibria the vibration moves, why none
    /// was analysed or how the search sampled, and the first `limit`
    /// equilibria with their thresholds and windows (or why they have none).
    pub fn report(&self, limit: usize) -> Vec<String> {
        let mut lines: Vec<String> = self
            .moved_by_vibration
            .iter()
            .map(|moved| match (&moved.periodic_orbit, moved.verdict) {
                (Some(orbit), Some(verdict)) => format!(
                    "q = {:?}: moved by the vibration; the periodic orbit near it at amplitude {} starts at {orbit:?}, multipliers {:?} (± {}): {verdict}; stable for amplitudes {:?} {}",
                    moved.q,
                    moved.amplitude,
                    moved.multipliers,
                    moved.multipliers_error.map_or("?".into(), |e| format!("{e:.1e}")),
                    moved.exact_window,
                    moved.exact_reason.as_deref().unwrap_or(""),
                ),
                _ => format!(
                    "q = {:?}: moved by the vibration, no periodic orbit found near it ({})",
                    moved.q,
                    moved.exact_reason.as_deref().unwrap_or("Newton did not converge"),
                ),
            })
            .collect();
        if let Some(reason) = &self.none_because {
            lines.push(format!("no equilibrium analysed: {reason}"));
        }
        if let Some(search) = &self.search_sampled {
            lines.push(format!("equilibria searched from {search}"));
        }
        if self.equilibria.len() > limit {
            let more = self.equilibria.len() - limit;
            lines.push(format!(
                "{more} equilibria beyond the first {limit} are in summary.json"
            ));
        }
        lines.extend(self.equilibria.iter().take(limit).map(|e| {
            let reason = e.reason.as_deref().unwrap_or("");
            let exact_reason = e.exact_reason.as_deref().unwrap_or("");
            let pole = match e.reduced_by.is_empty() {
                true => String::new(),
                false => format!(" (a pole: reduced by the coordinates {:?})", e.reduced_by),
            };
            let window = match (e.exact_window, e.exact_window_error) {
                (Some(edges), Some(errors)) => {
                    let edge = |k: usize| match (edges[k], errors[k]) {
                        (Some(a), Some(error)) => format!("{a} ± {error:.1e}"),
                        (Some(a), None) => format!("{a} (error unknown)"),
                        (None, _) => "beyond a_max".into(),
                    };
                    let check = e.exact_window_check.as_deref().unwrap_or("");
                    format!("[{}, {}] ({check})", edge(0), edge(1))
                }
                (window, _) => format!("{window:?}"),
            };
            format!(
                "q = {:?}{pole}: λ = {:?}, a* = {:?} {reason}, exact window {window} {exact_reason}",
                e.q, e.lambdas, e.a_star
            )
        }));
        lines
    }

    /// (equilibrium's index, amplitude, spectral radius) wherever a
    /// monodromy matrix was computed.
    pub fn spectral_radius_rows(&self) -> impl Iterator<Item = (usize, f64, f64)> + '_ {
        self.equilibria
            .iter()
            .enumerate()
            .flat_map(|(k, e)| e.spectral_radius.iter().map(move |p| (k, p[0], p[1])))
    }
}

/// An equilibrium without vibration that the vibration moves, and the
/// periodic orbit of the exact system near it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MovedEquilibrium {
    pub q: Vec<f64>,
    /// The amplitude the exact system was taken at (the given one, or 1
    /// where it is 0).
    pub amplitude: f64,
    /// The periodic orbit's state at t = 0 (Newton on the period map from
    /// (q, 0) with the monodromy matrix); None where Newton does not
    /// converge or where (q, 0) is not an equilibrium of the averaged system
    /// (the vibration moves it by more than a small amount).
    pub periodic_orbit: Option<Vec<f64>>,
    /// Its Floquet multipliers (re, im), largest modulus first, and the
    /// verdict they give.
    pub multipliers: Vec<(f64, f64)>,
    /// The multipliers' numerical error: twice the largest distance of one
    /// to the nearest of those of the same orbit found with a run at a
    /// hundredth of the tolerance (None where that run finds no orbit).
    pub multipliers_error: Option<f64>,
    pub verdict: Option<&'static str>,
    /// The first interval of the amplitude on which that orbit is stable,
    /// its edges the located stability changes along its branch (followed
    /// from amplitude 0, where it is the equilibrium, to a_max; upper null
    /// if stable up to a_max).
    pub exact_window: Option<[Option<f64>; 2]>,
    /// Why there is no exact window, when there is none.
    pub exact_reason: Option<String>,
}

/// Why a stability analysis lists no equilibrium.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NoEquilibria {
    #[error("Newton found no equilibrium of V from {starts} starts (a degenerate one, where the Hessian vanishes, converges too slowly to be found)")]
    NoneFound { starts: usize },
    #[error("every equilibrium is moved by the vibration (see moved_by_vibration)")]
    AllMoved,
}

fn as_text<S: serde::Serializer>(e: &Option<NoEquilibria>, s: S) -> Result<S::Ok, S::Error> {
    match e {
        Some(e) => s.serialize_str(&e.to_string()),
        None => s.serialize_none(),
    }
}

/// Why the analysis cannot run.
#[derive(Debug, thiserror::Error)]
pub enum StabilityError {
    /// The analysis does not apply to this kind of model.
    #[error(transparent)]
    Refused(#[from] crate::analysis::Refusal),
    #[error(
        "model '{model}' has no parameter '{name}' to use as the amplitude (parameters: {known})"
    )]
    UnknownAmplitude {
        model: String,
        name: String,
        known: String,
    },
    #[error("model '{model}' names no amplitude ([fast_phase] amplitude in its file): choose the parameter that scales the vibration with --set amplitude=<name> (parameters: {known})")]
    NoAmplitude { model: String, known: String },
    #[error("{0} parameter values for model '{1}'")]
    ParameterCount(usize, String),
    /// A chart of an equilibrium that the vibration moves: (q, 0) is no
    /// periodic solution, so it has no monodromy matrix.
    #[error("(q = {q:?}, p = 0) is not a solution of the exact system of model '{model}': the vibration moves it, so it has no stability chart (`stability` lists the equilibria the vibration keeps)")]
    MovedByVibration { model: String, q: Vec<f64> },
    /// Only some tiles of a chart were asked for: they are written, there
    /// is no chart to return.
    #[error("the tiles asked for are written; run without `only` to merge them into the chart")]
    Partial,
    #[error(transparent)]
    Tile(#[from] TileError),
    #[error(transparent)]
    Ode(#[from] OdeError),
    /// `first` names coordinates where no equilibrium was found.
    #[error("model '{model}': no equilibrium (of those `stability` analyses) within 1e-3 of q = {q:?} for `first`")]
    NoEquilibriumNear { model: String, q: Vec<f64> },
    /// A declared setting's value refused.
    #[error(transparent)]
    Setting(#[from] SettingError),
}

/// Runs the analysis on `model` with parameter values `params`
/// (declaration order).
pub fn stability(
    model: &Model,
    params: &[f64],
    settings: &Settings,
) -> Result<Stability, StabilityError> {
    let dynamic = model.dynamic;
    let model = crate::analysis::hamiltonian(model)?;
    analyse(model, dynamic, params, settings)
}

/// [`stability`] on the model's systems (`dynamic` tells its cyclic
/// coordinates).
fn analyse(
    model: &'static dyn Systems,
    dynamic: &dyn DynamicModel,
    params: &[f64],
    settings: &Settings,
) -> Result<Stability, StabilityError> {
    {
        let info = model.info();
        let named = vibrating_model(model, params)?;
        let amplitude = parameter_index(info, &settings.amplitude)?;
        let mut result = Stability {
            model: info.name.into(),
            coordinates: info.coordinates,
            amplitude: settings.amplitude.clone(),
            params: named,
            equilibria: Vec::new(),
            moved_by_vibration: Vec::new(),
            none_because: None,
            search_sampled: None,
        };
        let (found, search) = equilibria_without_vibration(model, params);
        result.search_sampled = search.sampled().then_some(search);
        // The exact system is probed at the given amplitude (1 where it is 0).
        let mut probe = params.to_vec();
        if probe[amplitude] == 0.0 {
            probe[amplitude] = 1.0;
        }
        // Cheap verdicts first; the exact windows and the moved equilibria's
        // orbits (each a sweep of Floquet multipliers) after, for at most
        // `max_windows` equilibria: those with the lowest thresholds a*,
        // then those the vibration moves.
        let mut moved: Vec<(Vec<f64>, bool)> = Vec::new();
        for q in &found {
            if let Some(along) = singular_chart(model, params, q) {
                // One entry per pole: the same point at every value of the
                // coordinates the chart loses there.
                let same_pole = |e: &EquilibriumStability| {
                    (e.reason.as_deref() == Some(SINGULAR_CHART) || !e.reduced_by.is_empty())
                        && (0..q.len()).all(|i| along.contains(&i) || (e.q[i] - q[i]).abs() < 1e-9)
                };
                if !result.equilibria.iter().any(same_pole) {
                    let cyclic = cyclic_coordinates(dynamic, params, q.len());
                    let pole = !along.is_empty() && along.iter().all(|i| cyclic.contains(i));
                    result.equilibria.push(match pole {
                        true => at_pole(model, params, amplitude, q, cyclic),
                        false => at_singular_chart(q),
                    });
                }
                continue;
            }
            let y0 = model.at_rest(q);
            let averaged = stays_in_averaged_system(model, params, q);
            if !averaged || moved_by_vibration(model, &probe, &y0) {
                moved.push((q.clone(), averaged));
                continue;
            }
            result
                .equilibria
                .push(averaged_verdict(model, params, amplitude, q));
        }
        let with_threshold = window_order(model, params, amplitude, &result.equilibria, settings)?;
        let budget = settings.max_windows;
        let costly = with_threshold.len() + moved.len();
        let skipped = format!(
            "not computed: {costly} equilibria need an exact sweep, and the {budget} with the lowest thresholds (or named by `first`) come first (--set max_windows=N for more)"
        );
        for (rank, &k) in with_threshold.iter().enumerate() {
            let e = &mut result.equilibria[k];
            if rank >= budget {
                e.exact_reason = Some(skipped.clone());
                continue;
            }
            let q = e.q.clone();
            checked_window(model, params, amplitude, &q, settings, e)?;
        }
        for e in result.equilibria.iter_mut() {
            if e.a_star.is_none() && e.exact_reason.is_none() {
                let q = e.q.clone();
                checked_window(model, params, amplitude, &q, settings, e)?;
            }
        }
        for (rank, (q, averaged)) in moved.into_iter().enumerate() {
            result
                .moved_by_vibration
                .push(if with_threshold.len() + rank >= budget {
                    MovedEquilibrium {
                        q: q.to_vec(),
                        amplitude: probe[amplitude],
                        periodic_orbit: None,
                        multipliers: Vec::new(),
                        multipliers_error: None,
                        verdict: None,
                        exact_window: None,
                        exact_reason: Some(skipped.clone()),
                    }
                } else {
                    moved_equilibrium(model, &probe, amplitude, settings, &q, averaged)
                });
        }
        if result.equilibria.is_empty() {
            result.none_because = Some(if found.is_empty() {
                NoEquilibria::NoneFound {
                    starts: search.starts,
                }
            } else {
                NoEquilibria::AllMoved
            });
        }
        Ok(result)
    }
}

/// An equilibrium without vibration that the vibration moves: its orbit's
/// branch from amplitude 0 and the periodic orbit near it at the probed
/// amplitude `probe` (`averaged`: whether the averaged system keeps it).
fn moved_equilibrium(
    model: &'static dyn Systems,
    probe: &[f64],
    amplitude: usize,
    settings: &Settings,
    q: &[f64],
    averaged: bool,
) -> MovedEquilibrium {
    let y0 = model.at_rest(q);
    let a_max = settings.a_max.unwrap_or(3.0 * probe[amplitude]);
    let branch = averaged.then(|| {
        let mut at_rest = probe.to_vec();
        at_rest[amplitude] = 0.0;
        orbit_branch(
            model,
            &at_rest,
            amplitude,
            settings.method,
            &y0,
            (0.0, a_max),
        )
    });
    // Newton at the probed amplitude from the branch's nearest point (from
    // (q, 0) where the branch could not be had).
    let near: Vec<f64> = match &branch {
        Some(Ok(b)) => b
            .states
            .iter()
            .min_by(|x, y| {
                (x.0 - probe[amplitude])
                    .abs()
                    .total_cmp(&(y.0 - probe[amplitude]).abs())
            })
            .map_or(y0.clone(), |(_, y)| y.clone()),
        _ => y0.clone(),
    };
    let orbit = if averaged {
        periodic_orbit_near(model, probe, &near, &settings.method)
    } else {
        None
    };
    let (exact_window, exact_reason) = match branch {
        None => (None, Some("the averaged system moves it too".to_string())),
        Some(Ok(OrbitBranch {
            window: Some(window),
            ..
        })) => (Some(window), None),
        Some(Ok(_)) => (
            None,
            Some(format!(
                "its orbit is not stable for any amplitude up to {a_max}"
            )),
        ),
        Some(Err(e)) => (
            None,
            Some(format!(
                "its orbit could not be followed from amplitude 0: {e}"
            )),
        ),
    };
    let period = model.phase_period(probe).unwrap_or(f64::NAN);
    let (periodic_orbit, multipliers, verdict) = match orbit {
        Some((y, m)) => {
            let multipliers = multipliers_of(&m);
            let verdict = super::floquet::Verdict::of_monodromy(&m, period);
            (Some(y), multipliers, Some(verdict.name()))
        }
        None => (None, Vec::new(), None),
    };
    // The same orbit found again with a run at a hundredth of the
    // tolerance, from the orbit found: twice the multipliers' distance, as
    // the edges' error (the tighter run has an error of its own).
    let multipliers_error = periodic_orbit.as_ref().and_then(|y| {
        let (_, m) = periodic_orbit_near(model, probe, y, &settings.method.check_run()?)?;
        Some(2.0 * multipliers_distance(&multipliers, &multipliers_of(&m)))
    });
    MovedEquilibrium {
        q: q.to_vec(),
        amplitude: probe[amplitude],
        periodic_orbit,
        multipliers,
        multipliers_error,
        verdict,
        exact_window,
        exact_reason,
    }
}

/// The largest distance from a multiplier of `a` to the nearest of `b`
/// (each of `b` matched once, nearest pairs first).
fn multipliers_distance(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    let mut free: Vec<(f64, f64)> = b.to_vec();
    let mut largest: f64 = 0.0;
    for &(re, im) in a {
        let nearest = (0..free.len()).min_by(|&i, &j| {
            let d = |k: usize| (free[k].0 - re).hypot(free[k].1 - im);
            d(i).total_cmp(&d(j))
        });
        match nearest {
            Some(k) => {
                let (r, i) = free.swap_remove(k);
                largest = largest.max((r - re).hypot(i - im));
            }
            None => return f64::INFINITY,
        }
    }
    largest
}

/// The equilibria with a threshold a*, in the order their exact windows
/// are computed: those `first` names, then by a* ascending.
fn window_order(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    equilibria: &[EquilibriumStability],
    settings: &Settings,
) -> Result<Vec<usize>, StabilityError> {
    let mut order: Vec<usize> = (0..equilibria.len())
        .filter(|&k| equilibria[k].a_star.is_some() && equilibria[k].exact_reason.is_none())
        .collect();
    let a = |k: usize| equilibria[k].a_star.unwrap_or(f64::INFINITY);
    order.sort_by(|&x, &y| a(x).total_cmp(&a(y)));
    let chosen = chosen_first(model, params, amplitude, equilibria, &settings.first)?;
    order.sort_by_key(|k| !chosen.contains(k));
    Ok(order)
}

/// The equilibria (indices into `equilibria`) that `first` names: the one
/// of greatest V (the amplitude set to 0, V_vibr vanishing with it), or
/// those nearest the given coordinates (angles compared modulo 2π).
fn chosen_first(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    equilibria: &[EquilibriumStability],
    first: &FirstWindows,
) -> Result<Vec<usize>, StabilityError> {
    match first {
        FirstWindows::Lowest => Ok(Vec::new()),
        FirstWindows::Highest => {
            let mut still = params.to_vec();
            still[amplitude] = 0.0;
            let v = |e: &EquilibriumStability| model.effective_potential(&still, &e.q);
            Ok((0..equilibria.len())
                .max_by(|&a, &b| v(&equilibria[a]).total_cmp(&v(&equilibria[b])))
                .into_iter()
                .collect())
        }
        FirstWindows::At(states) => {
            let periodic = model.periodic_state();
            let distance = |a: &[f64], b: &[f64]| -> f64 {
                a.iter()
                    .zip(b)
                    .zip(&periodic)
                    .map(|((x, y), &angle)| match angle {
                        true => wrap_angle(x - y).abs(),
                        false => (x - y).abs(),
                    })
                    .fold(0.0, f64::max)
            };
            states
                .iter()
                .map(|q| {
                    let nearest = (0..equilibria.len()).min_by(|&a, &b| {
                        distance(&equilibria[a].q, q).total_cmp(&distance(&equilibria[b].q, q))
                    });
                    nearest
                        .filter(|&k| {
                            q.len() == equilibria[k].q.len() && distance(&equilibria[k].q, q) < 1e-3
                        })
                        .ok_or_else(|| StabilityError::NoEquilibriumNear {
                            model: model.info().name.into(),
                            q: q.clone(),
                        })
                })
                .collect()
        }
    }
}

/// The index of the parameter `name` of the model, or an error listing them.
fn parameter_index(info: &crate::registry::ModelInfo, name: &str) -> Result<usize, StabilityError> {
    if name.is_empty() || name == "none" {
        return Err(StabilityError::NoAmplitude {
            model: info.name.into(),
            known: info.parameter_names.join(", "),
        });
    }
    info.parameter_names
        .iter()
        .position(|p| *p == name)
        .ok_or_else(|| StabilityError::UnknownAmplitude {
            model: info.name.into(),
            name: name.into(),
            known: info.parameter_names.join(", "),
        })
}

/// The averaged analysis at one equilibrium `q` of the system without
/// vibration (roots, a*, the second-order threshold; no exact window).
pub fn averaged_stability(
    model: &Model,
    params: &[f64],
    amplitude: &str,
    q: &[f64],
) -> Result<EquilibriumStability, StabilityError> {
    let model = crate::analysis::hamiltonian(model)?;
    let info = model.info();
    vibrating_model(model, params)?;
    let amplitude = parameter_index(info, amplitude)?;
    if q.len() != info.coordinates.len() {
        return Err(StabilityError::ParameterCount(q.len(), info.name.into()));
    }
    Ok(averaged_verdict(model, params, amplitude, q))
}

/// Equilibria of the potential V without vibration: the shared finder
/// ([`super::equilibria`]) on the generated ∂V/∂q with the generated C;
/// duplicates merged (angles modulo 2π). Also how much of the grid of
/// starts was searched.
fn equilibria_without_vibration(
    model: &dyn Systems,
    params: &[f64],
) -> (Vec<Vec<f64>>, super::equilibria::Search) {
    use super::equilibria::{newton, starts, wrapped, Convergence};
    let dof = model.info().coordinates.len();
    let periodic = &model.periodic_state()[..dof];
    let gradient = |q: &[f64]| model.potential_gradient(params, q);
    let hessian = |q: &[f64]| model.potential_hessian(params, q);
    let starts = starts(periodic);
    let mut found: Vec<Vec<f64>> = Vec::new();
    for start in &starts.points {
        let Some(q) = newton(gradient, hessian, start.clone(), Convergence::Exact) else {
            continue;
        };
        let q = wrapped(q, periodic);
        let same = |e: &Vec<f64>| {
            (0..dof).all(|i| {
                let d = if periodic[i] {
                    wrap_angle(e[i] - q[i])
                } else {
                    e[i] - q[i]
                };
                d.abs() < 1e-7
            })
        };
        if !found.iter().any(same) {
            found.push(q);
        }
    }
    found.sort_by(|a, b| {
        a.iter()
            .zip(b)
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    (found, starts.search)
}

/// Whether ∇(V + V_vibr) vanishes at q too (central differences of the
/// generated V + V_vibr, relative to its Hessian's scale).
fn stays_in_averaged_system(model: &dyn Systems, params: &[f64], q: &[f64]) -> bool {
    let scale = 1.0
        + model
            .effective_potential_hessian(params, q)
            .iter()
            .map(|x| x.abs())
            .fold(0.0, f64::max);
    (0..q.len()).all(|i| {
        let h = 1e-5;
        let (mut up, mut down) = (q.to_vec(), q.to_vec());
        up[i] += h;
        down[i] -= h;
        let slope = (model.effective_potential(params, &up)
            - model.effective_potential(params, &down))
            / (2.0 * h);
        slope.abs() < 1e-6 * scale
    })
}

/// Why an equilibrium at a singular point of the chart gets no verdict.
const SINGULAR_CHART: &str = "singular chart: the mass matrix is singular here along a coordinate that is not cyclic, so C + a²K and the exact system's orbits in this chart say nothing; other coordinates judge it";

/// The coordinates along which the mass matrix vanishes at q (a zero
/// diagonal entry: the azimuth at a pole of spherical coordinates), if its
/// determinant vanishes there; None where it is regular.
fn singular_chart(model: &dyn Systems, params: &[f64], q: &[f64]) -> Option<Vec<usize>> {
    let a = model.mass_matrix(params, q);
    let d = q.len();
    let m = DMatrix::from_fn(d, d, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let scale = 1.0 + m.amax();
    // Its smallest eigenvalue against its largest: the determinant against
    // scaleᴰ would call a long chain's regular mass matrix singular (det 1
    // against 13¹² for 12 links).
    let eigenvalues = m.symmetric_eigenvalues();
    let largest = eigenvalues.amax();
    (eigenvalues.amin() <= 1e-12 * largest).then(|| {
        (0..d)
            .filter(|&i| a[(i, i)].abs() <= 1e-12 * scale)
            .collect()
    })
}

/// The entry of an equilibrium at a singular point of the chart.
fn at_singular_chart(q: &[f64]) -> EquilibriumStability {
    EquilibriumStability {
        q: q.to_vec(),
        lambdas: Vec::new(),
        stable_without_vibration: false,
        a_star: None,
        a_star_second_order: None,
        reason: Some(SINGULAR_CHART.into()),
        exact_window: None,
        exact_window_error: None,
        exact_window_check: None,
        exact_reason: Some(SINGULAR_CHART.into()),
        spectral_radius: Vec::new(),
        reduced_by: Vec::new(),
    }
}

/// The roots λ, the verdict without vibration and a* from C + a²K.
fn averaged_verdict(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    q: &[f64],
) -> EquilibriumStability {
    let all: Vec<usize> = (0..q.len()).collect();
    reduced_verdict(model, params, amplitude, q, &all)
}

/// [`averaged_verdict`] on the coordinates `kept` (A, C and K with the
/// other rows and columns dropped); the second-order threshold on the
/// whole system only.
fn reduced_verdict(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    q: &[f64],
    kept: &[usize],
) -> EquilibriumStability {
    let c = reduce(&model.potential_hessian(params, q), kept);
    let a = reduce(&model.mass_matrix(params, q), kept);
    let lambdas = generalized_eigenvalues_of(&a, &c).unwrap_or_default();
    let stable_without_vibration = !lambdas.is_empty() && lambdas.iter().all(|l| *l > 0.0);
    let (a_star, reason) = threshold(model, params, amplitude, q, kept, stable_without_vibration);
    let whole = kept.len() == q.len();
    let a_star_second_order = a_star
        .filter(|_| whole)
        .and_then(|a| second_order_threshold(model, params, amplitude, q, a));
    EquilibriumStability {
        q: q.to_vec(),
        lambdas,
        stable_without_vibration,
        a_star,
        a_star_second_order,
        reason,
        exact_window: None,
        exact_window_error: None,
        exact_window_check: None,
        exact_reason: None,
        spectral_radius: Vec::new(),
        reduced_by: Vec::new(),
    }
}

/// Why a pole has no exact window.
const POLE_EXACT: &str = "a pole of the chart: the exact system is singular here in these coordinates, so it has no monodromy matrix; the averaged verdict is the reduced system's";

/// The verdict at a pole of the chart, on the system reduced by the cyclic
/// coordinates `cyclic` (taken at 0, as `explore` reports the family).
fn at_pole(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    q: &[f64],
    cyclic: Vec<usize>,
) -> EquilibriumStability {
    let mut q = q.to_vec();
    for &i in &cyclic {
        q[i] = 0.0;
    }
    let kept: Vec<usize> = (0..q.len()).filter(|i| !cyclic.contains(i)).collect();
    let mut verdict = reduced_verdict(model, params, amplitude, &q, &kept);
    verdict.exact_reason = Some(POLE_EXACT.into());
    verdict.reduced_by = cyclic;
    verdict
}

/// The rows and columns `kept` of a square matrix.
fn reduce(m: &DMatrix<f64>, kept: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(kept.len(), kept.len(), |i, j| m[(kept[i], kept[j])])
}

fn hessian_at(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    a: f64,
    q: &[f64],
    kept: &[usize],
) -> DMatrix<f64> {
    let mut p = params.to_vec();
    p[amplitude] = a;
    let m = reduce(&model.effective_potential_hessian(&p, q), kept);
    (&m + m.transpose()) * 0.5
}

fn positive_definite(m: &DMatrix<f64>) -> bool {
    m.clone().cholesky().is_some()
}

/// a* with C + a*²K on the edge of positive definiteness, or why none.
fn threshold(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    q: &[f64],
    kept: &[usize],
    stable_without_vibration: bool,
) -> (Option<f64>, Option<String>) {
    let name = model.info().parameter_names[amplitude];
    let c = hessian_at(model, params, amplitude, 0.0, q, kept);
    let k = hessian_at(model, params, amplitude, 1.0, q, kept) - &c;
    let k2 = hessian_at(model, params, amplitude, 2.0, q, kept) - &c;
    let scale = 1.0 + c.amax() + k.amax();
    if (&k2 - &k * 4.0).amax() > 1e-8 * scale {
        return (
            None,
            Some(format!(
                "V + V_vibr is not C + {name}²K: V_vibr is not quadratic in '{name}'"
            )),
        );
    }
    if stable_without_vibration {
        return (None, Some("stable without vibration".into()));
    }
    if k.amax() <= 1e-12 * scale {
        return (
            None,
            Some(format!(
                "V_vibr has no curvature here (its Hessian does not change with '{name}', e.g. an isotropic vibration): no amplitude stabilises it"
            )),
        );
    }
    if let Some(cholesky) = k.clone().cholesky() {
        // −C x = μ K x ⇔ (L⁻¹(−C)L⁻ᵀ) y = μ y with K = L Lᵀ.
        let l_inv = cholesky
            .l()
            .try_inverse()
            .unwrap_or_else(|| DMatrix::zeros(kept.len(), kept.len()));
        let m = &l_inv * (-&c) * l_inv.transpose();
        let m = (&m + m.transpose()) * 0.5;
        let mu = m.symmetric_eigenvalues().max();
        return (Some(mu.max(0.0).sqrt()), None);
    }
    // K only semidefinite: bisect on s = a², where C + sK grows with s.
    let definite = |s: f64| positive_definite(&(&c + &k * s));
    let mut high = c.amax() / k.amax().max(1e-300);
    for _ in 0..40 {
        if definite(high) {
            break;
        }
        high *= 4.0;
    }
    if !definite(high) {
        return (
            None,
            Some(format!(
                "no amplitude stabilises it: '{name}' does not act on an unstable direction"
            )),
        );
    }
    let mut low = 0.0;
    while high - low > 1e-14 * high {
        let mid = 0.5 * (low + high);
        if definite(mid) {
            high = mid;
        } else {
            low = mid;
        }
    }
    (Some(high.sqrt()), None)
}

/// The equilibrium of the second-order averaged system near (q, 0) (by
/// Newton on its field; it moves by O(ε²) where K̄ has terms odd in p), and
/// whether K̄'s Hessian is positive definite there; None where the
/// second-order system is not derived or Newton does not converge.
fn second_order_stable(model: &dyn Systems, params: &[f64], q: &[f64]) -> Option<bool> {
    let system = model.averaged2(params)?;
    let (d, n) = (q.len(), system.dim());
    let mut y = model.at_rest(q);
    let mut hessian = DMatrix::zeros(n, n);
    for _ in 0..20 {
        let h = model.averaged2_hessian(params, &y)?;
        hessian = DMatrix::from_fn(n, n, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
        // The field is J∇K̄ (+ forces): ∇K̄ = −J f without forces.
        let f = system.rhs(0.0, &y).ok()?;
        let gradient = DVector::from_fn(n, |i, _| if i < d { -f[d + i] } else { f[i - d] });
        if gradient.amax() < 1e-13 * (1.0 + hessian.amax()) {
            return Some(positive_definite(&hessian));
        }
        let step = hessian.clone().lu().solve(&gradient)?;
        for (yi, di) in y.iter_mut().zip(step.iter()) {
            *yi -= di;
        }
    }
    (hessian.amax().is_finite()).then(|| positive_definite(&hessian))
}

/// The amplitude at which the second-order averaged system's equilibrium
/// near (q, 0) becomes stable (K̄'s Hessian positive definite), by
/// bisection in [a*/2, 2a*] to 1e-13.
fn second_order_threshold(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    q: &[f64],
    a_star: f64,
) -> Option<f64> {
    let stable = |a: f64| {
        let mut p = params.to_vec();
        p[amplitude] = a;
        second_order_stable(model, &p, q)
    };
    let (mut low, mut high) = (0.5 * a_star, 2.0 * a_star);
    if stable(low)? || !stable(high)? {
        return None;
    }
    while high - low > 1e-13 * high {
        let mid = 0.5 * (low + high);
        if stable(mid)? {
            high = mid;
        } else {
            low = mid;
        }
    }
    Some(high)
}

/// The spectral radius and the stability margin
/// ([`stability_margin`]: ≤ 0 stable) of the exact system's monodromy
/// matrix over one period of the phase from `y0`, at each parameter point
/// of `points` (a sweep): on all cores, in batches of the method's width
/// (the lanes of the batch Taylor method; each as its own scalar run, bit
/// for bit).
fn floquet_at(
    model: &dyn Systems,
    points: &[Vec<f64>],
    y0: &[f64],
    method: Method,
) -> Result<Vec<(f64, f64)>, OdeError> {
    use rayon::prelude::*;
    // Whole batches, about four tasks per thread.
    let width = method.batch_width();
    let task = points
        .len()
        .div_ceil(4 * rayon::current_num_threads())
        .next_multiple_of(width)
        .max(width);
    let values: Vec<Vec<(f64, f64)>> = points
        .par_chunks(task)
        .map(|chunk| {
            let problems: Vec<_> = chunk
                .iter()
                .map(|p| (p.clone(), model.phase_period(p).unwrap_or(f64::NAN)))
                .collect();
            model
                .monodromies(method, &problems, y0)
                .0
                .into_iter()
                .zip(&problems)
                .map(|(result, (_, period))| {
                    result.map(|(_, m)| {
                        (
                            spectral_radius(&multipliers_of(&m)),
                            stability_margin(&m, *period),
                        )
                    })
                })
                .collect()
        })
        .collect::<Result<_, _>>()?;
    Ok(values.concat())
}

/// The parameters by name of a model with a fast phase, or why it cannot be
/// analysed (no phase, a wrong number of values).
fn vibrating_model(
    model: &dyn Systems,
    params: &[f64],
) -> Result<BTreeMap<String, f64>, StabilityError> {
    let info = model.info();
    if !model.has_fast_phase() {
        return Err(StabilityError::Refused(Refusal::no_fast_phase(info.name)));
    }
    info.named_values(params)
        .ok_or_else(|| StabilityError::ParameterCount(params.len(), info.name.into()))
}

/// The exact system's stability window in the amplitude at (q, 0), from
/// the stability margin of its monodromy matrix over one period of the
/// phase ([`stability_margin`]), if (q, 0) is a solution of the exact
/// system for every amplitude; each edge with its error.
fn exact_window(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    q: &[f64],
    settings: &Settings,
    out: &mut EquilibriumStability,
) -> Result<(), OdeError> {
    let Some(a_star) = out.a_star else {
        out.exact_reason = Some("no threshold in the averaged system".into());
        return Ok(());
    };
    let y0 = model.at_rest(q);
    let with = |a: f64| {
        let mut p = params.to_vec();
        p[amplitude] = a;
        p
    };
    if moved_by_vibration(model, &with(a_star.max(params[amplitude])), &y0) {
        out.exact_reason =
            Some("(q, 0) is not a solution of the exact system: the vibration moves it".into());
        return Ok(());
    }
    let a_max = settings.a_max.unwrap_or(3.0 * a_star);
    let curve = RefCell::new(Vec::new());
    let margins = |amplitudes: &[f64]| -> Result<Vec<f64>, OdeError> {
        let points: Vec<Vec<f64>> = amplitudes.iter().map(|&a| with(a)).collect();
        let values = floquet_at(model, &points, &y0, settings.method)?;
        let mut curve = curve.borrow_mut();
        curve.extend(amplitudes.iter().zip(&values).map(|(&a, &(r, _))| [a, r]));
        Ok(values.iter().map(|&(_, margin)| margin).collect())
    };
    let window = window_in_batches(
        &margins,
        settings.method.batch_width(),
        0.0,
        a_max,
        settings.samples,
        settings.edge_tolerance,
    )?;
    // At the precision floor no tighter run exists: the edges' errors are
    // then not stated (a run against itself would state its brackets only).
    let reference = settings.method.check_run();
    let checked = |amplitudes: &[f64]| -> Result<Vec<f64>, OdeError> {
        let points: Vec<Vec<f64>> = amplitudes.iter().map(|&a| with(a)).collect();
        let values = floquet_at(model, &points, &y0, reference.unwrap_or(settings.method))?;
        Ok(values.iter().map(|&(_, margin)| margin).collect())
    };
    let error = |edge: f64, unstable_below: bool| {
        let Some(reference) = reference else {
            return Ok(None);
        };
        let width = reference.batch_width();
        edge_error(
            &checked,
            width,
            edge,
            unstable_below,
            settings.edge_tolerance,
        )
    };
    match window {
        Some((low, high)) => {
            out.exact_window = Some([Some(low), high]);
            let high_error = match high {
                Some(high) => error(high, false)?,
                None => None,
            };
            out.exact_window_error = Some([error(low, true)?, high_error]);
            out.exact_window_check = Some(super::check::runs_compared(settings.method));
        }
        None => out.exact_reason = Some(format!("not stable for any amplitude up to {a_max}")),
    }
    let mut curve = curve.into_inner();
    curve.sort_by(|x, y| x[0].total_cmp(&y[0]));
    out.spectral_radius = curve;
    Ok(())
}

/// [`exact_window`] with `settings.accuracy` met where it is asked: the
/// edges bisected to a quarter of it, and the method's tolerance tightened
/// a hundredfold while their error is larger, down to the precision floor
/// (where the result says the accuracy was not reached, and why).
fn checked_window(
    model: &dyn Systems,
    params: &[f64],
    amplitude: usize,
    q: &[f64],
    settings: &Settings,
    out: &mut EquilibriumStability,
) -> Result<(), OdeError> {
    let Some(accuracy) = settings.accuracy else {
        return exact_window(model, params, amplitude, q, settings, out);
    };
    let mut settings = settings.clone();
    settings.edge_tolerance = settings.edge_tolerance.min(0.25 * accuracy);
    // An edge at a is known to a few units of rounding of a at best.
    let floor = out.a_star.map_or(0.0, |a| 64.0 * f64::EPSILON * a);
    if accuracy < floor {
        out.exact_reason = Some(format!(
            "accuracy {accuracy:e} is below what double precision resolves at a* = {}: about {floor:.1e}",
            out.a_star.unwrap_or(0.0)
        ));
        return Ok(());
    }
    loop {
        exact_window(model, params, amplitude, q, &settings, out)?;
        let Some(errors) = out.exact_window_error else {
            return Ok(());
        };
        let error = match errors {
            [Some(low), None] if out.exact_window.is_some_and(|[_, high]| high.is_none()) => low,
            [Some(low), Some(high)] => low.max(high),
            _ => f64::INFINITY,
        };
        let tighter = settings.method.tighter();
        let check = out.exact_window_check.take().unwrap_or_default();
        if error <= accuracy {
            out.exact_window_check = Some(format!("{check}: accuracy {accuracy:e} reached"));
            return Ok(());
        }
        if tighter.check_run().is_none() {
            out.exact_window_check = Some(format!(
                "{check}: accuracy {accuracy:e} NOT reached (error {error:.1e}; a tighter tolerance would be at the precision floor, where no run checks it)"
            ));
            return Ok(());
        }
        settings.method = tighter;
    }
}

/// The error of an edge found at `edge` (unstable below it if
/// `unstable_below`), from `margins` of a more accurate run: the same edge
/// bracketed in intervals around it that widen sixteenfold (from 4 to
/// about 4·10¹¹ `tolerance`s), bisected to `tolerance`; twice their
/// distance plus both bisections' half brackets, or None where that run
/// has no edge there. Twice: the more accurate run has an error of its
/// own, which is a hundredth of the first's only where the error falls in
/// proportion to the tolerance; at the edges of 50 Kapitza cases it was up
/// to 12 % of the distance, which alone bounded the true error in only half
/// of them.
fn edge_error(
    margins: &dyn Fn(&[f64]) -> Result<Vec<f64>, OdeError>,
    width: usize,
    edge: f64,
    unstable_below: bool,
    tolerance: f64,
) -> Result<Option<f64>, OdeError> {
    let flipped = |values: &[f64]| -> Result<Vec<f64>, OdeError> {
        Ok(margins(values)?.into_iter().map(|m| -m).collect())
    };
    let oriented: &dyn Fn(&[f64]) -> Result<Vec<f64>, OdeError> = match unstable_below {
        true => margins,
        false => &flipped,
    };
    let mut half = 4.0 * tolerance;
    for _ in 0..10 {
        let found =
            first_onset_in_batches(oriented, width, edge - half, edge + half, 1, tolerance)?;
        if let Some(again) = found {
            return Ok(Some(2.0 * (again - edge).abs() + tolerance));
        }
        half *= 16.0;
    }
    Ok(None)
}

/// Whether the exact system at parameter values `params` moves the state
/// `y0`: its field, at eight phases of a period, is not zero.
fn moved_by_vibration(model: &dyn Systems, params: &[f64], y0: &[f64]) -> bool {
    let period = model.phase_period(params).unwrap_or(f64::NAN);
    let exact = model.exact(params);
    (0..8).any(|k| {
        let f = exact.rhs(period * k as f64 / 8.0, y0);
        f.map_or(true, |f| {
            f.iter().map(|x| x.abs()).fold(0.0, f64::max) > 1e-9
        })
    })
}

/// The periodic orbit of the exact system near `y0`: Newton on P(y) − y
/// with the monodromy matrix M (solving (M − I) δ = −(P(y) − y)), at most
/// 30 steps and within 1 of `y0`; the orbit's start and its M, or None.
fn periodic_orbit_near(
    model: &dyn Systems,
    params: &[f64],
    y0: &[f64],
    method: &Method,
) -> Option<(Vec<f64>, DMatrix<f64>)> {
    let period = model.phase_period(params)?;
    let n = y0.len();
    let mut y = y0.to_vec();
    for _ in 0..30 {
        let mut integrator = crate::ode::Integrator::new(*method).ok()?;
        let (image, m) = model.monodromy(params, &mut integrator, period, &y).ok()?;
        let a = DMatrix::from_fn(n, n, |i, k| m[(i, k)] - f64::from(u8::from(i == k)));
        let r = DVector::from_fn(n, |i, _| image[i] - y[i]);
        let step = a.lu().solve(&r)?;
        for i in 0..n {
            y[i] -= step[i];
        }
        // An orbit more than 1 away is not the one near the equilibrium
        // (and a runaway Newton step would integrate far out).
        let away = (0..n).map(|i| (y[i] - y0[i]).abs()).fold(0.0, f64::max);
        if !(away <= 1.0) {
            return None;
        }
        if step.norm() < 1e-12 * (1.0 + y.iter().map(|x| x.abs()).fold(0.0, f64::max)) {
            let mut integrator = crate::ode::Integrator::new(*method).ok()?;
            let (_, m) = model.monodromy(params, &mut integrator, period, &y).ok()?;
            return Some((y, m));
        }
    }
    None
}

/// What [`stability_chart`] computes.
#[derive(Clone, Debug)]
pub struct ChartSettings {
    /// The equilibrium (q) whose periodic solution (q, 0) is judged.
    pub q: Vec<f64>,
    /// The parameter along the horizontal axis and its values.
    pub x: String,
    pub x_values: Vec<f64>,
    /// The parameter along the vertical axis, sampled on (0, y_max].
    pub y: String,
    pub y_max: f64,
    pub y_samples: usize,
    /// Each boundary is bisected to this tolerance in y.
    pub edge_tolerance: f64,
    pub method: Method,
    /// Cut the chart into tiles of whole columns (x values), each written
    /// to a file when done (None: one run in memory).
    pub tiles: Option<Tiles>,
}

/// A stability chart of the exact system in two parameters (an Ince–Strutt
/// chart): for every x, the y-values where the spectral radius of the
/// monodromy matrix at (q, 0) crosses 1, located by bisection.
#[derive(Clone, Debug, Serialize)]
pub struct StabilityChart {
    pub model: String,
    pub q: Vec<f64>,
    pub x: String,
    pub y: String,
    pub x_values: Vec<f64>,
    pub y_values: Vec<f64>,
    /// [x][y sample]: stable (the stability margin of the monodromy matrix ≤ 0).
    pub stable: Vec<Vec<bool>>,
    /// \[x\]: the boundaries in y, ascending.
    pub boundaries: Vec<Vec<f64>>,
}

impl StabilityChart {
    /// (x, y) of every boundary.
    pub fn boundary_rows(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.boundaries
            .iter()
            .zip(&self.x_values)
            .flat_map(|(edges, x)| edges.iter().map(move |y| (*x, *y)))
    }
}

/// The stability chart of `model` (see [`StabilityChart`]).
pub fn stability_chart(
    model: &Model,
    params: &[f64],
    settings: &ChartSettings,
) -> Result<StabilityChart, StabilityError> {
    let model = crate::analysis::hamiltonian(model)?;
    chart(model, params, settings)
}

/// [`stability_chart`] on the model's systems.
fn chart(
    model: &'static dyn Systems,
    params: &[f64],
    settings: &ChartSettings,
) -> Result<StabilityChart, StabilityError> {
    {
        let info = model.info();
        vibrating_model(model, params)?;
        let (ix, iy) = (
            parameter_index(info, &settings.x)?,
            parameter_index(info, &settings.y)?,
        );
        if settings.q.len() != info.coordinates.len() {
            return Err(StabilityError::ParameterCount(
                settings.q.len(),
                format!("{} (coordinates of the equilibrium)", info.name),
            ));
        }
        let y0 = model.at_rest(&settings.q);
        // Probed at the chart's corner of the largest y (the amplitude).
        let mut corner = params.to_vec();
        corner[ix] = settings.x_values.last().copied().unwrap_or(corner[ix]);
        corner[iy] = settings.y_max;
        if moved_by_vibration(model, &corner, &y0) {
            return Err(StabilityError::MovedByVibration {
                model: info.name.into(),
                q: settings.q.clone(),
            });
        }
        let margins = |xy: &[(f64, f64)]| -> Result<Vec<f64>, OdeError> {
            let points: Vec<Vec<f64>> = xy
                .iter()
                .map(|&(x, y)| {
                    let mut p = params.to_vec();
                    (p[ix], p[iy]) = (x, y);
                    p
                })
                .collect();
            let values = floquet_at(model, &points, &y0, settings.method)?;
            Ok(values.iter().map(|&(_, margin)| margin).collect())
        };
        let y_values: Vec<f64> = (1..=settings.y_samples)
            .map(|k| settings.y_max * k as f64 / settings.y_samples as f64)
            .collect();
        let samples = y_values.len();
        let columns_of =
            |range: std::ops::Range<usize>| -> Result<(Vec<f64>, u64), StabilityError> {
                let xs = &settings.x_values[range];
                let columns = chart_columns(xs, &y_values, settings.edge_tolerance, &margins)?;
                Ok((
                    columns
                        .iter()
                        .flat_map(|c| encode_column(c, samples))
                        .collect(),
                    0,
                ))
            };
        let columns = match &settings.tiles {
            None => columns_of(0..settings.x_values.len())?.0,
            Some(tiles) => {
                let key = format!(
                    "chart {} {:?} {:?} {} {:?} {} {} {} {} {:?} {}",
                    info.name,
                    params,
                    settings.q,
                    settings.x,
                    settings.x_values,
                    settings.y,
                    settings.y_max,
                    settings.y_samples,
                    settings.edge_tolerance,
                    settings.method,
                    tiles.rows
                );
                let shape = (settings.x_values.len(), 2 * samples, "columns");
                match run_tiles(tiles, fingerprint(&key), shape, &columns_of)? {
                    Some((values, _)) => values,
                    None => return Err(StabilityError::Partial),
                }
            }
        };
        let (stable, boundaries) = columns
            .chunks(2 * samples)
            .map(|c| decode_column(c, samples))
            .unzip();
        Ok(StabilityChart {
            model: info.name.into(),
            q: settings.q.clone(),
            x: settings.x.clone(),
            y: settings.y.clone(),
            x_values: settings.x_values.clone(),
            y_values,
            stable,
            boundaries,
        })
    }
}

/// The verdict at every y of `ys` and the boundaries between them, of each
/// column x of `xs`: every (x, y) margin of the columns in one sweep, then
/// every boundary bisected to `tolerance`, all in lockstep, one sweep per
/// step (each boundary takes the steps it would alone).
fn chart_columns(
    xs: &[f64],
    ys: &[f64],
    tolerance: f64,
    margins: &dyn Fn(&[(f64, f64)]) -> Result<Vec<f64>, OdeError>,
) -> Result<Vec<(Vec<bool>, Vec<f64>)>, OdeError> {
    let grid: Vec<(f64, f64)> = xs
        .iter()
        .flat_map(|&x| ys.iter().map(move |&y| (x, y)))
        .collect();
    let sampled = margins(&grid)?;
    let mut brackets = Vec::new();
    for (column, m) in sampled.chunks(ys.len()).enumerate() {
        for k in 1..ys.len() {
            if (m[k - 1] > 0.0) != (m[k] > 0.0) {
                let (low, high, stable_low) = (ys[k - 1], ys[k], m[k - 1] <= 0.0);
                brackets.push(Bracket {
                    column,
                    low,
                    high,
                    stable_low,
                });
            }
        }
    }
    loop {
        let open: Vec<&mut Bracket> = brackets
            .iter_mut()
            .filter(|b| b.high - b.low > tolerance)
            .collect();
        if open.is_empty() {
            break;
        }
        let middles: Vec<(f64, f64)> = open
            .iter()
            .map(|b| (xs[b.column], 0.5 * (b.low + b.high)))
            .collect();
        for ((b, (_, mid)), m) in open.into_iter().zip(&middles).zip(margins(&middles)?) {
            if (m <= 0.0) == b.stable_low {
                b.low = *mid;
            } else {
                b.high = *mid;
            }
        }
    }
    Ok(sampled
        .chunks(ys.len())
        .enumerate()
        .map(|(column, m)| {
            let edges = brackets
                .iter()
                .filter(|b| b.column == column)
                .map(|b| 0.5 * (b.low + b.high))
                .collect();
            (m.iter().map(|m| *m <= 0.0).collect(), edges)
        })
        .collect())
}

/// A boundary of a chart column being bisected: y in [low, high].
struct Bracket {
    column: usize,
    low: f64,
    high: f64,
    /// Whether the chart is stable at `low`.
    stable_low: bool,
}

/// A chart column as 2·samples numbers (for tiles): the verdicts as 1 or
/// 0, the number of boundaries, the boundaries, NaN after them (a column
/// has fewer boundaries than samples).
fn encode_column((stable, edges): &(Vec<bool>, Vec<f64>), samples: usize) -> Vec<f64> {
    let mut out: Vec<f64> = stable.iter().map(|&s| f64::from(u8::from(s))).collect();
    out.push(edges.len() as f64);
    out.extend(edges);
    out.resize(2 * samples, f64::NAN);
    out
}

/// The verdicts and boundaries of a column from [`encode_column`]'s numbers.
fn decode_column(values: &[f64], samples: usize) -> (Vec<bool>, Vec<f64>) {
    let count = values[samples] as usize;
    (
        values[..samples].iter().map(|&v| v == 1.0).collect(),
        values[samples + 1..samples + 1 + count].to_vec(),
    )
}

impl Stability {
    /// One panel per equilibrium with an exact window: the spectral radius
    /// of the monodromy matrix against the amplitude, a* of the averaged
    /// system (black) and the window's edges (red). None without one.
    pub fn figure(&self) -> Option<crate::plot::Figure> {
        use crate::plot::{Figure, PanelSpec, BLACK, BLUE, GREY, RED};
        use crate::registry::display_name;
        let drawn: Vec<&EquilibriumStability> = self
            .equilibria
            .iter()
            .filter(|e| !e.spectral_radius.is_empty())
            .collect();
        if drawn.is_empty() {
            return None;
        }
        let amplitude = display_name(&self.amplitude);
        let titles: Vec<String> = drawn
            .iter()
            .map(|e| {
                let at: Vec<String> = self
                    .coordinates
                    .iter()
                    .zip(&e.q)
                    .map(|(c, x)| format!("{} = {x:.3}", display_name(c)))
                    .collect();
                at.join(", ")
            })
            .collect();
        // The radius is drawn up to 3 (it is ≈ 1 + growth per period).
        let top = |e: &EquilibriumStability| {
            let highest = e.spectral_radius.iter().map(|p| p[1]).fold(1.0, f64::max);
            highest.min(3.0) + 0.05
        };
        let specs: Vec<PanelSpec> = drawn
            .iter()
            .zip(&titles)
            .map(|(e, title)| {
                let a_max = e.spectral_radius.last().map_or(1.0, |p| p[0]);
                PanelSpec::new(
                    title,
                    &amplitude,
                    "spectral radius",
                    (0.0, a_max),
                    (0.9, top(e)),
                )
            })
            .collect();
        let mut figure = Figure::grid(
            specs.len().min(3),
            specs.len().div_ceil(3),
            520,
            380,
            &specs,
        );
        for (k, e) in drawn.iter().enumerate() {
            let curve: Vec<(f64, f64)> = e.spectral_radius.iter().map(|p| (p[0], p[1])).collect();
            figure.line(
                k,
                &[(0.0, 1.0), (curve.last().map_or(1.0, |p| p.0), 1.0)],
                GREY,
            );
            figure.line(k, &curve, BLUE);
            let vertical = |x: f64| [(x, 0.901), (x, top(e) - 0.001)];
            if let Some(a) = e.a_star {
                figure.line(k, &vertical(a), BLACK);
            }
            for edge in e.exact_window.iter().flatten().flatten() {
                figure.line(k, &vertical(*edge), RED);
            }
            let value = |a: Option<f64>| a.map_or("none".to_string(), |a| format!("{a:.7}"));
            let lower = e.exact_window.and_then(|[low, _]| low);
            let error = match e.exact_window_error {
                Some([Some(error), _]) => format!(" ± {error:.1e}"),
                _ => String::new(),
            };
            let mut legend = vec![
                ("exact: spectral radius".to_string(), BLUE),
                (format!("averaged: a* = {}", value(e.a_star)), BLACK),
                (
                    format!("exact window edges (lower {}{error})", value(lower)),
                    RED,
                ),
            ];
            if e.a_star_second_order.is_some() {
                let text = format!("second-order averaged: {}", value(e.a_star_second_order));
                legend.push((text, GREY));
            }
            figure.legend(k, &legend);
        }
        Some(figure)
    }
}

impl StabilityChart {
    /// The stable intervals in y at column i: from the first sample's
    /// verdict, toggled at each located boundary.
    pub fn stable_intervals(&self, i: usize) -> Vec<(f64, f64)> {
        let y_max = self.y_values.last().copied().unwrap_or(0.0);
        let mut stable = self.stable[i].first().copied().unwrap_or(false);
        let (mut from, mut out) = (0.0, Vec::new());
        for &edge in self.boundaries[i].iter().chain([&y_max]) {
            if stable && edge > from {
                out.push((from, edge));
            }
            from = edge;
            stable = !stable;
        }
        out
    }

    /// The chart: the stable intervals between the located boundaries
    /// filled in grey, the boundaries as curves (the i-th boundaries of
    /// neighbouring columns joined where both columns have as many and they
    /// lie close), and their points.
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{Figure, PanelSpec, Rgb, BLUE};
        use crate::registry::display_name;
        let (x, y) = (display_name(&self.x), display_name(&self.y));
        let first = self.x_values.first().copied().unwrap_or(0.0);
        let last = self.x_values.last().copied().unwrap_or(1.0);
        let width = (last - first) / (self.x_values.len().max(2) - 1) as f64;
        let y_max = self.y_values.last().copied().unwrap_or(1.0);
        let title = format!(
            "{}: stability of the equilibrium q = {:?} (grey: stable)",
            self.model, self.q
        );
        let spec = PanelSpec::new(
            &title,
            &x,
            &y,
            (first - width / 2.0, last + width / 2.0),
            (0.0, y_max),
        );
        let mut figure = Figure::single(720, 540, spec);
        let fill = Rgb(200, 200, 200);
        // Vertical strokes fill the stable intervals. Between neighbouring
        // columns with as many intervals their ends are interpolated (the
        // region follows the located boundaries); otherwise each column
        // fills half the way to its neighbours.
        let intervals: Vec<Vec<(f64, f64)>> = (0..self.x_values.len())
            .map(|i| self.stable_intervals(i))
            .collect();
        let strokes = 24;
        let mut stroke =
            |x: f64, (low, high): (f64, f64)| figure.line(0, &[(x, low), (x, high)], fill);
        for i in 0..self.x_values.len() {
            let xi = self.x_values[i];
            let matched = |j: usize| {
                intervals
                    .get(j)
                    .is_some_and(|o| o.len() == intervals[i].len())
            };
            for k in 0..=strokes / 2 {
                let t = k as f64 / strokes as f64;
                for (side, j) in [(1.0, i + 1), (-1.0, i.wrapping_sub(1))] {
                    let x = xi + side * t * width;
                    for (n, &(low, high)) in intervals[i].iter().enumerate() {
                        if matched(j) {
                            let (l2, h2) = intervals[j][n];
                            stroke(x, (low + t * (l2 - low), high + t * (h2 - high)));
                        } else {
                            stroke(x, (low, high));
                        }
                    }
                }
            }
        }
        let most = self.boundaries.iter().map(Vec::len).max().unwrap_or(0);
        for b in 0..most {
            for i in 1..self.x_values.len() {
                let (left, right) = (&self.boundaries[i - 1], &self.boundaries[i]);
                if let (Some(p), Some(q)) = (left.get(b), right.get(b)) {
                    if left.len() == right.len() && (p - q).abs() < 0.1 * y_max {
                        figure.line(
                            0,
                            &[(self.x_values[i - 1], *p), (self.x_values[i], *q)],
                            BLUE,
                        );
                    }
                }
            }
            let points = self
                .boundaries
                .iter()
                .zip(&self.x_values)
                .filter_map(|(e, x)| e.get(b).map(|y| (*x, *y)));
            figure.points(0, points, BLUE, 3);
        }
        figure
    }
}

impl crate::outputs::Outputs for Stability {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        self.figure()
            .map(|figure| ("spectral_radius.png".into(), figure))
            .into_iter()
            .collect()
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let header = ["equilibrium", "amplitude", "spectral_radius"];
        let rows = self.spectral_radius_rows();
        vec![crate::outputs::Table::new(
            "spectral_radius.csv",
            &header,
            rows,
        )]
    }
    fn lines(&self) -> Vec<String> {
        self.report(32)
    }
}
