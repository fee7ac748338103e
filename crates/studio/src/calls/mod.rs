//! The studio's library calls: what its page asks for, reached by the
//! tests without HTTP, in the studio's crate so that the main scene's
//! build compiles none of them:
//! the models and their derivations as MathML, an orbit of the period map
//! handed over in chunks as it grows, the level sets of the averaged
//! Hamiltonian with the equilibria, and the FLI chaos map of a view at
//! growing resolutions.

pub mod contour;

use mechlab_runtime::analysis::basins::{BasinSettings, BasinsOptions};
use mechlab_runtime::analysis::chaos_map::{chaos_map, ChaosMapOptions, ChaosMapSettings};
use mechlab_runtime::analysis::period_map::{stream_orbit, wrap_angle, PeriodMapError};
use mechlab_runtime::analysis::Refusal;
use mechlab_runtime::ode::{Integrator, Method, OdeError};
use mechlab_runtime::registry::{Catalog, DynamicModel, Kind, Model, ModelInfo, ParameterError};
use mechlab_runtime::settings::Declared;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::time::{Duration, Instant};

/// The largest requests the studio computes: a click never starts an hour
/// of work.
pub const MAX_PERIODS: usize = 100_000;
pub const MAX_CHAOS_PIXELS: usize = 400;
pub const MAX_GRID: usize = 400;

/// Why the studio cannot answer a request. Each names what was wrong.
#[derive(Debug, thiserror::Error)]
pub enum StudioError {
    #[error(transparent)]
    UnknownModel(#[from] mechlab_runtime::registry::UnknownModel),
    /// The analysis does not apply to this kind of model.
    #[error(transparent)]
    Refused(#[from] mechlab_runtime::analysis::Refusal),
    #[error("model '{model}': {problem}")]
    BadRequest {
        model: String,
        problem: RequestProblem,
    },
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// A declared setting's value refused (its name, value and range).
    #[error(transparent)]
    Setting(#[from] mechlab_runtime::settings::SettingError),
    /// A section orbit asked for without a seed.
    #[error("the section's orbit needs a seed: seeds = [[q, p]] (the other coordinate and its momentum on the plane)")]
    NoSeed,
    /// A section map asked for with no pixels.
    #[error("the section's MEGNO map needs its pixels per side: map > 0")]
    NoMap,
    /// Not 1 to 8 refinements of a map.
    #[error("a map is drawn in 1 to 8 refinements (levels), got {got}")]
    Levels { got: usize },
    #[error(transparent)]
    Ode(#[from] OdeError),
    #[error(transparent)]
    PeriodMap(#[from] PeriodMapError),
    #[error(transparent)]
    Splitting(#[from] mechlab_runtime::analysis::separatrix::SplittingError),
    #[error(transparent)]
    Continuation(#[from] mechlab_runtime::analysis::continuation::ContinuationError),
    #[error(transparent)]
    Section(#[from] mechlab_runtime::analysis::section::SectionError),
    #[error(transparent)]
    Mechanism(#[from] mechlab_runtime::analysis::mechanism::MechanismError),
    #[error(transparent)]
    Basins(#[from] mechlab_runtime::analysis::basins::BasinsError),
}

/// The library's classes, and the studio's own errors as bad values.
impl mechlab_runtime::classify::Classify for StudioError {
    fn class(&self) -> mechlab_runtime::classify::ErrorClass {
        use mechlab_runtime::classify::ErrorClass;
        match self {
            StudioError::UnknownModel(e) => e.class(),
            StudioError::Refused(e) => e.class(),
            StudioError::Parameter(e) => e.class(),
            StudioError::Setting(e) => e.class(),
            StudioError::Ode(e) => e.class(),
            StudioError::PeriodMap(e) => e.class(),
            StudioError::Splitting(e) => e.class(),
            StudioError::Continuation(e) => e.class(),
            StudioError::Section(e) => e.class(),
            StudioError::Mechanism(e) => e.class(),
            StudioError::Basins(e) => e.class(),
            StudioError::BadRequest { .. }
            | StudioError::NoSeed
            | StudioError::NoMap
            | StudioError::Levels { .. } => ErrorClass::BadValue,
        }
    }
}

/// What is wrong with a request's numbers.
#[derive(Debug, thiserror::Error)]
pub enum RequestProblem {
    #[error("the seed has {got} components; the state [q; p] has {expected}")]
    SeedLength { got: usize, expected: usize },
    #[error("the state to pass through has {got} components; the state [q; p] has {expected}")]
    ThroughLength { got: usize, expected: usize },
    #[error("the averaged Hamiltonian to order {0} is not derived for this model (orders: 1, and 2 for models with a fast phase, except numeric-solve models of more than 4 degrees of freedom)")]
    Order(usize),
    #[error("the request has a field '{0}' that this route does not know")]
    UnknownField(String),
    #[error("{what} must be finite")]
    NotFinite { what: &'static str },
    #[error("{what} must be a positive number, got {got}")]
    NotPositive { what: &'static str, got: f64 },
    #[error("the axes must be two different state components among 0..{components}")]
    Axes { components: usize },
    #[error("the range of axis {axis} must be an interval of finite numbers, low < high")]
    Range { axis: usize },
    #[error("the seed cannot be put on the constraints with its axes' components held: {0}")]
    Inconsistent(mechlab_runtime::ode::holonomic::ConstraintError),
    #[error("{what} must be between 1 and {max}, got {got}")]
    Count {
        what: &'static str,
        got: usize,
        max: usize,
    },
}

/// A parameter as the page shows it: a slider around the model file's value.
#[derive(Clone, Debug, Serialize)]
pub struct ParameterSummary {
    pub name: &'static str,
    pub symbol: String,
    pub default: f64,
    pub description: &'static str,
}

/// One model of `models/` as the page lists it.
#[derive(Clone, Debug, Serialize)]
pub struct ModelSummary {
    pub name: &'static str,
    pub source_file: &'static str,
    /// `hamiltonian`, `contacts` or `constrained`.
    pub kind: &'static str,
    pub dof: usize,
    pub fast_phase: bool,
    /// The coordinates' names as the model file writes them (a section's
    /// plane is written in them).
    pub coordinates: &'static [&'static str],
    /// The state's names [q; p] in the figures' notation.
    pub state: Vec<String>,
    /// Per state component: an angle (shown mod 2π).
    pub periodic: Vec<bool>,
    pub parameters: Vec<ParameterSummary>,
    /// The parameter that scales the vibration, if the model names one.
    pub amplitude: Option<&'static str>,
    pub default_axes: [usize; 2],
    pub default_ranges: [[f64; 2]; 2],
    /// The state the plane passes through by default: zero, or a
    /// constrained model's start (its seeds are put on its constraints).
    pub through: Vec<f64>,
    /// The mechanism's points, if its model file names them (the page
    /// draws the mechanism moving from each orbit's seed).
    pub points: Vec<&'static str>,
    /// Whether the Taylor method runs it (a constrained model of more than
    /// 6 coordinates has no Taylor recurrences: the page picks DOP853).
    pub taylor: bool,
    /// Whether the page offers its Poincaré section: a Hamiltonian model
    /// of 2 degrees of freedom, or an autonomous one of 2 on holonomic
    /// constraints (`analysis::section`).
    pub section: bool,
}

/// Every model of `catalog`, in its order.
pub fn models(catalog: Catalog) -> Vec<ModelSummary> {
    catalog
        .iter()
        .map(|m| {
            let taylor = m.flows().is_none_or(|f| f.has_taylor_recurrences());
            let section = match m.constrained {
                Some(c) => {
                    let free = m.info.coordinates.len() - c.constraint_names().len();
                    free == 2 && !c.has_fast_phase() && c.holonomic().iter().all(|h| *h)
                }
                None => m.systems().is_some() && m.info.coordinates.len() == 2,
            };
            summary(m.info, m.dynamic, taylor, section)
        })
        .collect()
}

fn summary(
    info: &'static ModelInfo,
    model: &dyn DynamicModel,
    taylor: bool,
    section: bool,
) -> ModelSummary {
    let (kind, dof, fast_phase) = match model.kind() {
        Kind::Hamiltonian { dof, fast_phase } => ("hamiltonian", dof, fast_phase),
        Kind::Contacts { count } => ("contacts", count, false),
        Kind::Constrained {
            coordinates,
            fast_phase,
            ..
        } => ("constrained", coordinates, fast_phase),
    };
    let periodic = model.periodic_state();
    let state = info.state_names();
    let through = model
        .start(&model.defaults())
        .unwrap_or_else(|| vec![0.0; periodic.len()]);
    let default_axes = [0, dof.min(state.len().saturating_sub(1))];
    let default_ranges = default_axes.map(|a| {
        if periodic.get(a).copied().unwrap_or(false) {
            [-PI, PI]
        } else {
            [-3.0, 3.0]
        }
    });
    ModelSummary {
        taylor,
        section,
        through,
        name: info.name,
        source_file: info.source_file,
        kind,
        dof,
        fast_phase,
        coordinates: info.coordinates,
        // A constrained model's second half are velocities: φ₁′.
        state: state
            .iter()
            .enumerate()
            .map(|(i, n)| match kind {
                "constrained" if i >= dof => {
                    format!(
                        "{}′",
                        mechlab_runtime::registry::display_name(info.coordinates[i - dof])
                    )
                }
                _ => mechlab_runtime::registry::display_name(n),
            })
            .collect(),
        periodic,
        parameters: info
            .parameter_names
            .iter()
            .zip(model.defaults())
            .zip(info.parameter_descriptions)
            .map(|((&name, default), &description)| ParameterSummary {
                name,
                symbol: mechlab_runtime::registry::display_name(name),
                default,
                description,
            })
            .collect(),
        amplitude: info.amplitude,
        default_axes,
        default_ranges,
        points: info.drawing.map(|d| d.points.to_vec()).unwrap_or_default(),
    }
}

/// A derived expression as the page shows it.
#[derive(Clone, Debug, Serialize)]
pub struct Derivation {
    pub key: &'static str,
    pub description: &'static str,
    pub mathml: String,
}

/// The derivations a student reads first: L, H, the averaged H to each
/// order, V_vibr and the effective potential, the equations of motion.
pub fn derivations(catalog: Catalog, name: &str) -> Result<Vec<Derivation>, StudioError> {
    let info = mechlab_runtime::registry::lookup(catalog, name)?.info;
    const SHOWN: [&str; 8] = [
        "lagrangian",
        "hamiltonian",
        "averaged_hamiltonian",
        "averaged_hamiltonian_second_order",
        "vibrational_potential",
        "effective_potential",
        "free_force[",
        "normal_force[",
    ];
    let shown = |key: &str| {
        SHOWN
            .iter()
            .any(|s| key == *s || (s.ends_with('[') && key.starts_with(s)))
            || key.starts_with("velocities[")
            || key.starts_with("momentum_rates[")
    };
    Ok(info
        .derivations
        .iter()
        .filter(|d| shown(d.key))
        .map(|d| Derivation {
            key: d.key,
            description: d.description,
            mathml: mechlab_runtime::mathml::mathml(d.latex, true),
        })
        .collect())
}

fn first_order() -> usize {
    1
}

fn default_method() -> String {
    "taylor".into()
}
fn default_tol() -> f64 {
    1e-10
}

/// What every request names: the model, its parameters (the model file's
/// values where not given), the method and the plane drawn.
#[derive(Clone, Debug, Deserialize)]
pub struct Setup {
    pub model: String,
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
    #[serde(default = "default_method")]
    pub method: String,
    #[serde(default = "default_tol")]
    pub tol: f64,
    /// The state components along the page's axes (default: q₁, p₁).
    #[serde(default)]
    pub axes: Option<[usize; 2]>,
    /// The state the plane passes through (default 0).
    #[serde(default)]
    pub through: Option<Vec<f64>>,
}

/// A [`Setup`] checked against its model.
#[derive(Clone)]
pub struct Resolved {
    pub handle: &'static Model,
    pub info: &'static ModelInfo,
    pub model: &'static dyn DynamicModel,
    pub dof: usize,
    pub fast_phase: bool,
    pub params: Vec<f64>,
    pub method: Method,
    pub axes: [usize; 2],
    pub through: Vec<f64>,
}

impl Setup {
    /// The setup checked against its model; `unknown` are the request's
    /// fields that no route knows.
    pub fn resolve(
        &self,
        catalog: Catalog,
        unknown: &BTreeMap<String, serde_json::Value>,
    ) -> Result<Resolved, StudioError> {
        let handle = mechlab_runtime::registry::lookup(catalog, &self.model)?;
        let (info, model) = (handle.info, handle.dynamic);
        if let Some(field) = unknown.keys().next() {
            return Err(StudioError::BadRequest {
                model: info.name.into(),
                problem: RequestProblem::UnknownField(field.clone()),
            });
        }
        let bad = |problem| StudioError::BadRequest {
            model: info.name.into(),
            problem,
        };
        let (dof, fast_phase) = match model.kind() {
            Kind::Hamiltonian { dof, fast_phase } => (dof, fast_phase),
            Kind::Contacts { .. } => {
                return Err(StudioError::Refused(Refusal::contact_model(info.name)))
            }
            Kind::Constrained {
                coordinates,
                fast_phase,
                ..
            } => (coordinates, fast_phase),
        };
        let mut params = model.defaults();
        for (name, &value) in &self.params {
            info.check_parameter(name, value)?;
            let k = info.parameter_names.iter().position(|n| n == name);
            params[k.expect("check_parameter knows every name")] = value;
        }
        let method = Method::parse(&self.method, self.tol)?;
        method.validate()?;
        let states = model.periodic_state().len();
        let axes = self.axes.unwrap_or([0, dof]);
        if axes[0] == axes[1] || axes.iter().any(|&a| a >= states) {
            return Err(bad(RequestProblem::Axes { components: states }));
        }
        let through = self.through.clone().unwrap_or_else(|| vec![0.0; states]);
        if through.len() != states {
            return Err(bad(RequestProblem::ThroughLength {
                got: through.len(),
                expected: states,
            }));
        }
        if through.iter().any(|x| !x.is_finite()) {
            return Err(bad(RequestProblem::NotFinite {
                what: "the state to pass through",
            }));
        }
        Ok(Resolved {
            handle,
            info,
            model,
            dof,
            fast_phase,
            params,
            method,
            axes,
            through,
        })
    }
}

impl Resolved {
    fn bad(&self, problem: RequestProblem) -> StudioError {
        StudioError::BadRequest {
            model: self.info.name.into(),
            problem,
        }
    }

    fn ranges(&self, ranges: &[[f64; 2]; 2]) -> Result<[(f64, f64); 2], StudioError> {
        for (axis, r) in ranges.iter().enumerate() {
            if !(r[0].is_finite() && r[1].is_finite() && r[0] < r[1]) {
                return Err(self.bad(RequestProblem::Range { axis }));
            }
        }
        Ok(ranges.map(|r| (r[0], r[1])))
    }

    fn count(&self, what: &'static str, got: usize, max: usize) -> Result<usize, StudioError> {
        if got == 0 || got > max {
            return Err(self.bad(RequestProblem::Count { what, got, max }));
        }
        Ok(got)
    }

    fn needs_period_map(&self) -> Result<(), StudioError> {
        if self.fast_phase {
            Ok(())
        } else {
            Err(StudioError::Refused(Refusal::no_fast_phase(self.info.name)))
        }
    }
}

/// A click on the page: an orbit of the period map from `seed` (the full
/// state [q; p]), `periods` iterates.
#[derive(Clone, Debug, Deserialize)]
pub struct OrbitRequest {
    #[serde(flatten)]
    pub setup: Setup,
    pub seed: Vec<f64>,
    pub periods: usize,
    /// Fields no route knows (refused by name, not ignored).
    #[serde(flatten)]
    pub unknown: BTreeMap<String, serde_json::Value>,
}

impl OrbitRequest {
    /// The request checked: its model has a period map, the seed is a
    /// finite state of the right size, the periods are within bounds.
    pub fn check(&self, catalog: Catalog) -> Result<Resolved, StudioError> {
        let setup = self.setup.resolve(catalog, &self.unknown)?;
        setup.needs_period_map()?;
        setup.count("periods", self.periods, MAX_PERIODS)?;
        if self.seed.len() != 2 * setup.dof {
            return Err(setup.bad(RequestProblem::SeedLength {
                got: self.seed.len(),
                expected: 2 * setup.dof,
            }));
        }
        if self.seed.iter().any(|x| !x.is_finite()) {
            return Err(setup.bad(RequestProblem::NotFinite { what: "the seed" }));
        }
        Ok(setup)
    }
}

/// Points of an orbit projected on the page's axes (angles in [−π, π)), in
/// order: the first chunk starts with the seed.
#[derive(Clone, Debug, Serialize)]
pub struct OrbitChunk {
    pub points: Vec<[f64; 2]>,
}

/// How an orbit ended.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct OrbitEnd {
    /// Iterates computed (the seed not counted).
    pub periods: usize,
    /// The page went away (a superseded request): the orbit stopped early.
    pub cancelled: bool,
    pub f_evals: u64,
    pub seconds: f64,
    /// The orbit's tunes, one per degree of freedom: the fundamental
    /// frequency of its iterates (q_j + i p_j less the mean, q_j + i q_j′
    /// on constraints, e^{i q_j} for a circulating angle) in turns per
    /// period ([`mechlab_runtime::analysis::frequency_map::tunes`]); None for an
    /// orbit of fewer than 64 iterates or cancelled.
    pub tunes: Option<Vec<f64>>,
}

/// Iterates below which an orbit gets no tunes.
const MIN_TUNE_ITERATES: usize = 64;

/// How often a growing orbit is handed over.
const CHUNK_INTERVAL: Duration = Duration::from_millis(40);
const CHUNK_POINTS: usize = 4096;

/// Computes the orbit of `request`, handing its points to `sink` in chunks
/// as they come (at least every 40 ms); `sink` returns false when nobody
/// listens any more, which stops the orbit. An orbit that leaves the
/// model's domain ends with the integrator's error after the points before.
pub fn orbit(
    catalog: Catalog,
    request: &OrbitRequest,
    sink: &mut dyn FnMut(OrbitChunk) -> bool,
) -> Result<OrbitEnd, StudioError> {
    let setup = request.check(catalog)?;
    let systems = mechlab_runtime::analysis::flows(setup.handle)?;
    // A constrained model's seed, on its constraints in the chart of the axes.
    let mut seed = request.seed.clone();
    systems
        .consistent(&setup.params, &mut seed, &setup.axes)
        .map_err(|e| StudioError::BadRequest {
            model: setup.info.name.into(),
            problem: RequestProblem::Inconsistent(e),
        })?;
    let started = Instant::now();
    let period = systems
        .phase_period(&setup.params)
        .ok_or_else(|| StudioError::Refused(Refusal::no_fast_phase(setup.info.name)))?;
    let system = systems.exact(&setup.params);
    let periodic = systems.periodic_state();
    let project = |y: &[f64]| {
        setup
            .axes
            .map(|a| if periodic[a] { wrap_angle(y[a]) } else { y[a] })
    };
    let mut integrator = Integrator::new(setup.method)?;
    let mut chunk = Vec::new();
    let mut states: Vec<Vec<f64>> = Vec::with_capacity(request.periods + 1);
    let mut last_sent = Instant::now();
    // The seed, then one per period.
    let (mut points, mut cancelled) = (0usize, false);
    let run = stream_orbit(
        &mut integrator,
        &*system,
        period,
        &seed,
        request.periods,
        &periodic,
        &mut |y| {
            chunk.push(project(y));
            states.push(y.to_vec());
            points += 1;
            if points > 1 && (chunk.len() >= CHUNK_POINTS || last_sent.elapsed() >= CHUNK_INTERVAL)
            {
                let points = std::mem::take(&mut chunk);
                cancelled = !sink(OrbitChunk { points });
                last_sent = Instant::now();
            }
            !cancelled
        },
    );
    let end = |periods, cancelled, integrator: &Integrator| OrbitEnd {
        periods,
        cancelled,
        f_evals: integrator.stats.f_evals,
        seconds: started.elapsed().as_secs_f64(),
        tunes: (!cancelled && states.len() >= MIN_TUNE_ITERATES)
            .then(|| mechlab_runtime::analysis::frequency_map::tunes(&states, &periodic).0),
    };
    if let Err(error) = run {
        // The points before the failure are the page's to keep.
        sink(OrbitChunk { points: chunk });
        return Err(error.into());
    }
    if cancelled {
        return Ok(end(points - 1, true, &integrator));
    }
    let listening = chunk.is_empty() || sink(OrbitChunk { points: chunk });
    Ok(end(request.periods, !listening, &integrator))
}

/// A request of a declared analysis: the model, its parameters (the model
/// file's values where not given), and the analysis's settings by the
/// names of its declaration (the analysis's `interactive` preset where not
/// given), each checked by the declaration.
#[derive(Clone, Debug, Deserialize)]
pub struct AnalysisRequest {
    pub model: String,
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
    /// The analysis's settings (an unknown name is refused by name).
    #[serde(flatten)]
    pub settings: serde_json::Map<String, serde_json::Value>,
}

impl AnalysisRequest {
    /// The model, its parameter values and the settings, checked.
    pub fn resolve<T: Declared>(
        &self,
        catalog: Catalog,
    ) -> Result<(&'static Model, Vec<f64>, T), StudioError> {
        let handle = mechlab_runtime::registry::lookup(catalog, &self.model)?;
        let params = handle.values_with(&self.params)?;
        let settings = T::interactive().with_json(&self.settings)?;
        Ok((handle, params, settings))
    }
}

/// A map of the current view drawn coarse first (the chaos map, the
/// basins): the analysis's settings, at each number of pixels per side
/// of `levels`.
#[derive(Clone, Debug, Deserialize)]
pub struct LevelsRequest {
    /// Pixels per side of each refinement, in order (1 to 8 of them).
    pub levels: Vec<usize>,
    #[serde(flatten)]
    pub analysis: AnalysisRequest,
}

impl LevelsRequest {
    /// The request checked: the model, its parameters, and the settings of
    /// each level, checked by the declaration and resolved for the model
    /// by `resolve`.
    pub fn check<T: Declared, S, E>(
        &self,
        catalog: Catalog,
        resolve: impl Fn(&T, &Model) -> Result<S, E>,
    ) -> Result<(&'static Model, Vec<f64>, Vec<S>), StudioError>
    where
        StudioError: From<E>,
    {
        let (model, params, options) = self.analysis.resolve::<T>(catalog)?;
        if self.levels.is_empty() || self.levels.len() > 8 {
            return Err(StudioError::Levels {
                got: self.levels.len(),
            });
        }
        let levels = self
            .levels
            .iter()
            .map(|&pixels| {
                let mut level = options.clone();
                level.set_json("pixels", &pixels.into())?;
                level.validate()?;
                Ok(resolve(&level, model)?)
            })
            .collect::<Result<_, StudioError>>()?;
        Ok((model, params, levels))
    }
}

/// The chaos map's request checked, each level's settings resolved.
pub fn chaos_levels(
    catalog: Catalog,
    request: &LevelsRequest,
) -> Result<(&'static Model, Vec<f64>, Vec<ChaosMapSettings>), StudioError> {
    request.check(catalog, ChaosMapOptions::resolve)
}

/// One refinement of the chaos map.
#[derive(Clone, Debug, Serialize)]
pub struct ChaosLevel {
    pub pixels: usize,
    /// Grey levels in [0, 1] (1 = most chaotic), row-major from the lower left.
    pub shades: Vec<f64>,
    /// The FLI of each pixel (null: the orbit left the model's domain).
    pub fli: Vec<Option<f64>>,
    /// ln(periods): the FLI of a regular orbit.
    pub regular_level: f64,
    pub chaotic_fraction: f64,
    pub seconds: f64,
}

/// The FLI map of the view at each resolution of `request.levels` (rows
/// on all cores; the Taylor method in batches), each handed to `sink` when
/// done; `sink` returns false to stop before the next, and once `listening`
/// says false a level stops between blocks of rows (ending with
/// `PeriodMapError::Cancelled`).
pub fn chaos(
    catalog: Catalog,
    request: &LevelsRequest,
    sink: &mut dyn FnMut(ChaosLevel) -> bool,
    listening: &(dyn Fn() -> bool + Sync),
) -> Result<(), StudioError> {
    let (model, params, levels) = chaos_levels(catalog, request)?;
    for settings in &levels {
        let map = chaos_map(model, &params, settings, listening)?;
        let level = ChaosLevel {
            pixels: settings.pixels,
            shades: map.shades,
            fli: map
                .fli
                .iter()
                .map(|v| v.is_finite().then_some(*v))
                .collect(),
            regular_level: map.fli_regular_level,
            chaotic_fraction: map.chaotic_fraction,
            seconds: map.seconds,
        };
        if !sink(level) {
            break;
        }
    }
    Ok(())
}

/// The basins' request (`POST /api/basins`) checked, each level's
/// settings resolved.
pub fn basins_levels(
    catalog: Catalog,
    request: &LevelsRequest,
) -> Result<(&'static Model, Vec<f64>, Vec<BasinSettings>), StudioError> {
    request.check(catalog, BasinsOptions::resolve)
}

/// One refinement of the basins.
#[derive(Clone, Debug, Serialize)]
pub struct BasinsLevel {
    pub pixels: usize,
    /// Each pixel's attractor (an index of `attractors`, −1: diverged),
    /// row-major from the lower left.
    pub labels: Vec<i32>,
    pub attractors: Vec<mechlab_runtime::analysis::basins::Attractor>,
    /// Each attractor's recorded iterates on the view's axes.
    pub points: Vec<Vec<[f64; 2]>>,
    pub boundary: mechlab_runtime::analysis::basins::Boundary,
    pub seconds: f64,
}

/// Streams the basins of the view at each resolution of the request to
/// `sink`, until it returns false.
pub fn basins(
    catalog: Catalog,
    request: &LevelsRequest,
    sink: &mut dyn FnMut(BasinsLevel) -> bool,
) -> Result<(), StudioError> {
    let (model, params, levels) = basins_levels(catalog, request)?;
    for settings in &levels {
        let map = mechlab_runtime::analysis::basins::basins(model, &params, settings, &|_| ())?;
        let level = BasinsLevel {
            pixels: settings.pixels,
            labels: map.labels,
            attractors: map.attractors,
            points: map.points,
            boundary: map.boundary,
            seconds: map.seconds,
        };
        if !sink(level) {
            break;
        }
    }
    Ok(())
}

/// The overlays of a view: level sets of the averaged Hamiltonian (of H
/// without a fast phase) and the equilibria of V + V_vibr.
#[derive(Clone, Debug, Deserialize)]
pub struct OverlayRequest {
    #[serde(flatten)]
    pub setup: Setup,
    pub ranges: [[f64; 2]; 2],
    /// Grid points per side for the level sets.
    pub grid: usize,
    /// Number of level sets (besides those through unstable equilibria).
    pub levels: usize,
    /// The order of the averaged Hamiltonian drawn: 1 (H̄) or 2 (K̄ to ε²,
    /// where derived).
    #[serde(default = "first_order")]
    pub order: usize,
    /// Fields no route knows (refused by name, not ignored).
    #[serde(flatten)]
    pub unknown: BTreeMap<String, serde_json::Value>,
}

/// One level set, as segments (x₀, y₀, x₁, y₁) on the page's axes.
#[derive(Clone, Debug, Serialize)]
pub struct LevelSet {
    pub value: f64,
    /// Through an unstable equilibrium: a separatrix of the averaged system.
    pub separatrix: bool,
    pub segments: Vec<[f64; 4]>,
}

/// An equilibrium of V + V_vibr (at p = 0).
#[derive(Clone, Debug, Serialize)]
pub struct EquilibriumMark {
    pub q: Vec<f64>,
    /// Where it sits on the page's axes.
    pub point: [f64; 2],
    /// Its other state components equal the plane's: it lies on the view.
    pub on_plane: bool,
    pub stable: bool,
    pub hessian_eigenvalues: Vec<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Overlay {
    /// Which function the level sets are of.
    pub function: &'static str,
    pub levels: Vec<LevelSet>,
    pub equilibria: Vec<EquilibriumMark>,
}

/// The level sets and equilibria of a view.
pub fn overlay(catalog: Catalog, request: &OverlayRequest) -> Result<Overlay, StudioError> {
    let setup = request.setup.resolve(catalog, &request.unknown)?;
    let ranges = setup.ranges(&request.ranges)?;
    let grid = setup.count("grid points per side", request.grid, MAX_GRID)?;
    let count = setup.count("level sets", request.levels, 100)?;
    let model = setup.model;
    let params = &setup.params;
    let second_order = match request.order {
        1 => false,
        2 if model.averaged2_energy(params, &setup.through).is_some() => true,
        order => return Err(setup.bad(RequestProblem::Order(order))),
    };
    let value = |x: f64, y: f64| {
        let mut state = setup.through.clone();
        state[setup.axes[0]] = x;
        state[setup.axes[1]] = y;
        let value = if second_order {
            model.averaged2_energy(params, &state)
        } else if setup.fast_phase {
            model.averaged_energy(params, &state)
        } else {
            Some(model.energy(params, 0.0, &state))
        };
        value.unwrap_or(f64::NAN)
    };
    let field = contour::Field::sample(ranges, grid, value);
    let equilibria: Vec<EquilibriumMark> =
        mechlab_runtime::analysis::equilibria::effective_equilibria(model, params)
            .map(|(found, _)| found)
            .unwrap_or_default()
            .into_iter()
            .map(|e| {
                let mut state = e.q.clone();
                state.resize(2 * setup.dof, 0.0);
                let periodic = model.periodic();
                let same = |k: usize| {
                    let d = state[k] - setup.through[k];
                    let d = if periodic.get(k).copied().unwrap_or(false) {
                        wrap_angle(d)
                    } else {
                        d
                    };
                    d.abs() < 1e-9
                };
                let point = setup.axes.map(|a| {
                    if periodic.get(a).copied().unwrap_or(false) {
                        wrap_angle(state[a])
                    } else {
                        state[a]
                    }
                });
                EquilibriumMark {
                    on_plane: (0..state.len())
                        .filter(|k| !setup.axes.contains(k))
                        .all(same),
                    point,
                    stable: e.verdict == mechlab_runtime::analysis::equilibria::Verdict::Stable,
                    hessian_eigenvalues: e.hessian_eigenvalues,
                    q: e.q,
                }
            })
            .collect();
    let mut levels: Vec<LevelSet> = field
        .quantiles(count)
        .into_iter()
        .map(|v| LevelSet {
            value: v,
            separatrix: false,
            segments: field.segments(v),
        })
        .collect();
    for e in equilibria.iter().filter(|e| !e.stable && e.on_plane) {
        let v = value(e.point[0], e.point[1]);
        if v.is_finite() {
            levels.push(LevelSet {
                value: v,
                separatrix: true,
                segments: field.segments(v),
            });
        }
    }
    Ok(Overlay {
        function: match (setup.fast_phase, second_order) {
            (_, true) => "averaged Hamiltonian to second order K̄",
            (true, false) => "averaged Hamiltonian H̄",
            (false, false) => "Hamiltonian H",
        },
        levels,
        equilibria,
    })
}

/// A request for the invariant manifolds of the period map's hyperbolic
/// fixed point (a model of one degree of freedom with a fast phase).
#[derive(Clone, Debug, Deserialize)]
pub struct ManifoldsRequest {
    /// The separatrix splitting's settings.
    #[serde(flatten)]
    pub analysis: AnalysisRequest,
}

/// W^u and W^s on the page's cylinder (q in [−π, π)) as segments
/// (q₀, p₀, q₁, p₁), the two primary homoclinic points, and the lobe.
#[derive(Clone, Debug, Serialize)]
pub struct Manifolds {
    pub unstable: Vec<[f64; 4]>,
    pub stable: Vec<[f64; 4]>,
    pub homoclinic: Vec<[f64; 2]>,
    pub fixed_point: [f64; 2],
    pub lobe_area: f64,
    pub resolved: bool,
    pub angle: f64,
}

/// The manifolds of the hyperbolic fixed point of the model's period map
/// (`analysis::separatrix`), for the studio's overlay.
pub fn manifolds(catalog: Catalog, request: &ManifoldsRequest) -> Result<Manifolds, StudioError> {
    use mechlab_runtime::analysis::separatrix::{separatrix_splitting, SplittingOptions};
    let (model, params, options) = request.analysis.resolve::<SplittingOptions>(catalog)?;
    let s = separatrix_splitting(model, &params, &options.resolve()?)?;
    let periodic = model.dynamic.periodic().first() == Some(&true);
    let place = |y: &[f64; 2]| [if periodic { wrap_angle(y[0]) } else { y[0] }, y[1]];
    // Consecutive points as segments, except across the cut at ±π.
    let segments = |points: &[[f64; 2]]| -> Vec<[f64; 4]> {
        points
            .windows(2)
            .map(|w| (place(&w[0]), place(&w[1])))
            .filter(|(a, b)| (b[0] - a[0]).abs() < std::f64::consts::PI)
            .map(|(a, b)| [a[0], a[1], b[0], b[1]])
            .collect()
    };
    Ok(Manifolds {
        unstable: segments(&s.unstable),
        stable: segments(&s.stable),
        homoclinic: s.homoclinic.iter().map(|h| place(&h.point)).collect(),
        fixed_point: place(&s.fixed_point),
        lobe_area: s.lobe_area().unwrap_or(f64::NAN),
        resolved: s.resolved,
        angle: s.homoclinic[0].angle.unwrap_or(f64::NAN),
    })
}

/// What `POST /api/continuation` asks: the periodic orbit of the period
/// map nearest `seed` (a state), continued in `parameter` from its value
/// to `to`.
#[derive(Clone, Debug, Deserialize)]
pub struct ContinuationRequest {
    /// The page's axes: the branches are drawn on them, and a constrained
    /// model is continued in their chart unless `chart` is given (auto:
    /// the first coordinate and its momentum, or velocity).
    #[serde(default)]
    pub axes: Option<[usize; 2]>,
    /// The continuation's settings (`start` is the clicked state).
    #[serde(flatten)]
    pub analysis: AnalysisRequest,
}

/// Branches on the page's plane: each point (x, y, parameter) with its
/// stability, and the located bifurcations.
#[derive(Clone, Debug, Serialize)]
pub struct BranchesView {
    pub branches: Vec<BranchLine>,
    pub bifurcations: Vec<BifurcationMark>,
    pub seconds: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct BranchLine {
    pub period: usize,
    pub points: Vec<[f64; 3]>,
    pub stable: Vec<bool>,
}

#[derive(Clone, Debug, Serialize)]
pub struct BifurcationMark {
    pub kind: mechlab_runtime::analysis::continuation::BifurcationKind,
    pub parameter: f64,
    pub at: [f64; 2],
    pub located: bool,
}

/// The studio's "continue this orbit" (`analysis::continuation`): the
/// branch of the fixed point of P nearest the seed (the equilibrium, for a
/// model without a fast phase), and those born at its period doublings (up
/// to period 4), projected on the page's axes.
pub fn continuation(
    catalog: Catalog,
    request: &ContinuationRequest,
) -> Result<BranchesView, StudioError> {
    use mechlab_runtime::analysis::continuation::{continuation, ContinuationOptions};
    use mechlab_runtime::settings::{resolve_axes, Axis};
    let (model, params, options) = request.analysis.resolve::<ContinuationOptions>(catalog)?;
    let given = request.axes.map(|a| a.map(Axis::Index));
    let view = resolve_axes(ContinuationOptions::ANALYSIS, model.info, &given)?;
    let mut settings = options.resolve(model, &params)?;
    // A constrained model of one degree of freedom on its constraints is
    // continued in the chart of the plane's axes.
    if model.constrained.is_some() && settings.chart.is_none() {
        settings.chart = Some(view.to_vec());
    }
    let result = continuation(model, &params, &settings)?;
    let periodic = model.dynamic.periodic();
    // The state components of the axes in the branches' states.
    let axes = match &result.chart {
        Some(chart) => view.map(|a| chart.iter().position(|&c| c == a).unwrap_or(a)),
        None => view,
    };
    let place = |y: &[f64]| -> [f64; 2] {
        let at = |k: usize| {
            let axis = view[k];
            let component = axes[k];
            if periodic.get(axis).copied().unwrap_or(false) {
                wrap_angle(y[component])
            } else {
                y[component]
            }
        };
        [at(0), at(1)]
    };
    let branches = result
        .branches
        .iter()
        .map(|b| BranchLine {
            period: b.period,
            points: b
                .points
                .iter()
                .map(|p| {
                    let [x, y] = place(&p.state);
                    [x, y, p.parameter]
                })
                .collect(),
            stable: b.points.iter().map(|p| p.stable).collect(),
        })
        .collect();
    let bifurcations = result
        .bifurcations
        .iter()
        .map(|b| BifurcationMark {
            kind: b.kind,
            parameter: b.parameter,
            at: place(&b.state),
            located: b.located,
        })
        .collect();
    Ok(BranchesView {
        branches,
        bifurcations,
        seconds: result.seconds,
    })
}

/// What `POST /api/section` and `POST /api/section_map` ask: the
/// section's settings (its interactive values where not given): the orbit
/// from the one seed of `seeds`, or the MEGNO map of `map` pixels.
#[derive(Clone, Debug, Deserialize)]
pub struct SectionRequest {
    #[serde(flatten)]
    pub analysis: AnalysisRequest,
}

impl SectionRequest {
    /// The section's parts the request asks for.
    fn study(
        &self,
        catalog: Catalog,
    ) -> Result<mechlab_runtime::analysis::section::SectionStudy, StudioError> {
        use mechlab_runtime::analysis::section::{section_study, SectionOptions};
        let (model, params, options) = self.analysis.resolve::<SectionOptions>(catalog)?;
        Ok(section_study(model, &params, &options, &|_| ())?)
    }
}

/// A section orbit: its points on the plane (the seed first), its full
/// start and its largest drift from H = E.
#[derive(Clone, Debug, Serialize)]
pub struct SectionPoints {
    /// The names of the plane's two axes (Q_o and P_o of its chart).
    pub axes: [String; 2],
    pub points: Vec<[f64; 2]>,
    pub start: Vec<f64>,
    pub energy_drift: f64,
    /// Why the orbit ended (before its crossings: escaped, stopped, t_max).
    pub end: mechlab_runtime::analysis::section::OrbitEnd,
    /// The same, in words, for the page.
    pub end_text: String,
}

/// One orbit of the section map (`analysis::section`) for the studio: the
/// first of the request's seeds.
pub fn section(catalog: Catalog, request: &SectionRequest) -> Result<SectionPoints, StudioError> {
    let study = request.study(catalog)?;
    let Some(mut found) = study.section.filter(|s| !s.orbits.is_empty()) else {
        return Err(StudioError::NoSeed);
    };
    let orbit = found.orbits.remove(0);
    Ok(SectionPoints {
        axes: found.axes,
        points: orbit.points,
        start: orbit.start,
        energy_drift: orbit.energy_drift,
        end_text: orbit.end.to_string(),
        end: orbit.end,
    })
}

/// The MEGNO map of a section: ⟨Y⟩ per pixel (row 0 at the bottom, null
/// where the energy is not accessible) over `window`.
#[derive(Clone, Debug, Serialize)]
pub struct SectionMapView {
    /// The names of the plane's two axes (Q_o and P_o of its chart).
    pub axes: [String; 2],
    pub window: [[f64; 2]; 2],
    pub pixels: usize,
    pub megno: Vec<Option<f64>>,
    pub chaotic_fraction: f64,
    pub seconds: f64,
}

/// The MEGNO map of the section (`analysis::section_map`) for the studio.
pub fn section_map(
    catalog: Catalog,
    request: &SectionRequest,
) -> Result<SectionMapView, StudioError> {
    let Some(map) = request.study(catalog)?.megno_map else {
        return Err(StudioError::NoMap);
    };
    Ok(SectionMapView {
        axes: map.axes.clone(),
        window: map.window,
        pixels: map.pixels,
        megno: map
            .megno
            .iter()
            .map(|y| y.is_finite().then_some(*y))
            .collect(),
        chaotic_fraction: map.chaotic_fraction,
        seconds: map.seconds,
    })
}

/// The mechanism moving from an orbit's seed (the model file's points):
/// `duration` time units drawn in `frames` frames.
#[derive(Clone, Debug, Deserialize)]
pub struct MechanismRequest {
    #[serde(flatten)]
    pub setup: Setup,
    pub seed: Vec<f64>,
    pub duration: f64,
    pub frames: usize,
    /// Fields no route knows (refused by name, not ignored).
    #[serde(flatten)]
    pub unknown: BTreeMap<String, serde_json::Value>,
}

/// The frames of the mechanism, for the page to play.
#[derive(Clone, Debug, Serialize)]
pub struct MechanismView {
    pub points: Vec<&'static str>,
    pub bars: Vec<[usize; 2]>,
    pub times: Vec<f64>,
    /// `frames[f][p]`: the point p at `times[f]`.
    pub frames: Vec<Vec<[f64; 2]>>,
}

/// The mechanism of `request` moving, from the seed put on the constraints
/// as the orbit's is (its axes' components held).
pub fn mechanism(
    catalog: Catalog,
    request: &MechanismRequest,
) -> Result<MechanismView, StudioError> {
    let setup = request.setup.resolve(catalog, &request.unknown)?;
    if request.seed.iter().any(|x| !x.is_finite()) {
        return Err(setup.bad(RequestProblem::NotFinite { what: "the seed" }));
    }
    let frames = mechlab_runtime::analysis::mechanism::Frames {
        duration: request.duration,
        count: request.frames,
    };
    let animation = mechlab_runtime::analysis::mechanism::animate(
        setup.handle,
        &setup.params,
        setup.method,
        &request.seed,
        &setup.axes,
        frames,
    )?;
    Ok(MechanismView {
        points: animation.points.to_vec(),
        bars: animation.bars.to_vec(),
        times: animation.times,
        frames: animation.frames,
    })
}
