//! The studio's library calls: what its page asks for, reached by the
//! tests without HTTP, in the studio's crate so that the main scene's
//! build compiles none of them:
//! the models and their derivations as MathML, an orbit of the period map
//! handed over in chunks as it grows, the level sets of the averaged
//! Hamiltonian with the equilibria, and the FLI chaos map of a view at
//! growing resolutions.

mod continuation;
pub mod contour;
mod maps;
mod mechanism;
mod orbit;
mod overlay;
mod section;
mod steady;
mod views;

pub use continuation::*;
pub use maps::*;
pub use mechanism::*;
pub use orbit::*;
pub use overlay::*;
pub use section::*;
pub use steady::*;
pub use views::*;

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
    /// An orbit that left the model's domain: the integration's stop, then
    /// the model file's expression that stopped being real and where.
    #[error("{source}\n{domain}")]
    OutsideDomain {
        source: OdeError,
        domain: Box<mechlab_runtime::domain::OutsideDomain>,
    },
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
    /// A declared analysis run whole (the steady motion).
    #[error(transparent)]
    Analysis(Box<mechlab_runtime::analysis::declared::AnalysisError>),
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
            StudioError::Ode(e) | StudioError::OutsideDomain { source: e, .. } => e.class(),
            StudioError::PeriodMap(e) => e.class(),
            StudioError::Splitting(e) => e.class(),
            StudioError::Continuation(e) => e.class(),
            StudioError::Section(e) => e.class(),
            StudioError::Mechanism(e) => e.class(),
            StudioError::Basins(e) => e.class(),
            StudioError::Analysis(e) => e.class(),
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
    #[error("{what} must be finite")]
    NotFinite { what: &'static str },
    #[error("the axes must be two different state components among 0..{components}")]
    Axes { components: usize },
    #[error("the range of axis {axis} must be an interval of finite numbers, low < high")]
    Range { axis: usize },
    #[error("the seed cannot be put on the constraints with its axes' components held: {0}")]
    Inconsistent(mechlab_runtime::ode::holonomic::ConstraintError),
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
    /// The state the plane passes through by default: the model file's
    /// start at rest where it gives one (a constrained model's seeds are
    /// put on its constraints), else zero.
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
