//! The settings of the studio's own views — an orbit clicked on the page,
//! the overlays of a view, the mechanism moving — declared as the
//! library's analyses are: checked by their declarations, served by
//! `GET /api/schema` with the analyses', and the page fills its inputs
//! from them. Each view's plane (its axes, the state it passes through)
//! and method are resolved once, into a [`Plane`].

use super::*;
use mechlab_runtime::settings::{Range, METHODS};

mechlab_runtime::declare_settings! {
    /// An orbit of the period map from a clicked state, handed to the page
    /// in chunks as it grows.
    pub struct OrbitOptions for "orbit" {
        /// The clicked state [q; p].
        seed: Vec<f64> = Vec::new(), Range::Any;
        /// Periods of the fast phase.
        periods: usize = 2000, Range::Count { min: 1, max: MAX_PERIODS };
        /// The state components along the page's axes (auto: the first
        /// coordinate and its momentum).
        axes: Option<[usize; 2]> = None, Range::Any;
        /// The state the plane passes through (auto: 0).
        through: Option<Vec<f64>> = None, Range::Any;
        /// The integration method.
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size.
        tol: f64 = 1e-10, Range::Positive;
    }
}

mechlab_runtime::declare_settings! {
    /// The overlays of a view: level sets of the averaged Hamiltonian (of H
    /// without a fast phase) and the equilibria of V + V_vibr.
    pub struct OverlayOptions for "overlay" {
        /// The view: the ranges of its two axes.
        ranges: [[f64; 2]; 2] = [[-PI, PI], [-3.0, 3.0]], Range::Any;
        /// Grid points per side for the level sets.
        grid: usize = 160, Range::Count { min: 2, max: MAX_GRID };
        /// Level sets (besides those through unstable equilibria).
        levels: usize = 14, Range::Count { min: 1, max: 100 };
        /// The order of the averaged Hamiltonian drawn: 1 (H̄) or 2 (K̄ to
        /// ε², where derived).
        order: usize = 1, Range::Count { min: 1, max: 2 };
        /// The state components along the page's axes (auto: the first
        /// coordinate and its momentum).
        axes: Option<[usize; 2]> = None, Range::Any;
        /// The state the plane passes through (auto: 0).
        through: Option<Vec<f64>> = None, Range::Any;
        /// The integration method (not used by the overlays).
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (not used by the overlays).
        tol: f64 = 1e-10, Range::Positive;
    }
}

mechlab_runtime::declare_settings! {
    /// The mechanism (the model file's points) moving from an orbit's seed.
    pub struct MechanismOptions for "mechanism" {
        /// The clicked state [q; p].
        seed: Vec<f64> = Vec::new(), Range::Any;
        /// Time units drawn.
        duration: f64 = 20.0, Range::Between { low: 1e-3, high: 1e4 };
        /// Frames over the duration.
        frames: usize = 601, Range::Count { min: 2, max: mechlab_runtime::analysis::mechanism::MAX_FRAMES };
        /// The state components along the page's axes (auto: the first
        /// coordinate and its momentum).
        axes: Option<[usize; 2]> = None, Range::Any;
        /// The state the plane passes through (auto: 0).
        through: Option<Vec<f64>> = None, Range::Any;
        /// The integration method.
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size.
        tol: f64 = 1e-10, Range::Positive;
    }
}

/// The declarations the studio serves (`GET /api/schema`): the
/// analyses', then its own views'.
pub fn schemas() -> Vec<mechlab_runtime::settings::Schema> {
    use mechlab_runtime::settings::Schema;
    let mut schemas = mechlab_runtime::settings::schemas();
    schemas.extend([
        Schema::of::<OrbitOptions>(),
        Schema::of::<OverlayOptions>(),
        Schema::of::<MechanismOptions>(),
    ]);
    schemas
}

/// A view's plane checked against its model: the model, its parameters,
/// the method, the axes and the state the plane passes through.
#[derive(Clone)]
pub struct Plane {
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

impl Plane {
    /// The plane of `handle` at `params` with these (declared) settings.
    pub fn of(
        handle: &'static Model,
        params: Vec<f64>,
        axes: Option<[usize; 2]>,
        through: &Option<Vec<f64>>,
        (method, tol): (&str, f64),
    ) -> Result<Plane, StudioError> {
        let (info, model) = (handle.info, handle.dynamic);
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
        let method = Method::parse(method, tol)?;
        method.validate()?;
        let states = model.periodic_state().len();
        let plane = Plane {
            handle,
            info,
            model,
            dof,
            fast_phase,
            params,
            method,
            axes: axes.unwrap_or([0, dof]),
            through: through.clone().unwrap_or_else(|| vec![0.0; states]),
        };
        let [a, b] = plane.axes;
        if a == b || a >= states || b >= states {
            return Err(plane.bad(RequestProblem::Axes { components: states }));
        }
        if plane.through.len() != states {
            return Err(plane.bad(RequestProblem::ThroughLength {
                got: plane.through.len(),
                expected: states,
            }));
        }
        if plane.through.iter().any(|x| !x.is_finite()) {
            let what = "the state to pass through";
            return Err(plane.bad(RequestProblem::NotFinite { what }));
        }
        Ok(plane)
    }

    pub fn bad(&self, problem: RequestProblem) -> StudioError {
        StudioError::BadRequest {
            model: self.info.name.into(),
            problem,
        }
    }

    /// A seed of the full state's length, finite.
    pub fn seed(&self, seed: &[f64]) -> Result<(), StudioError> {
        if seed.len() != 2 * self.dof {
            return Err(self.bad(RequestProblem::SeedLength {
                got: seed.len(),
                expected: 2 * self.dof,
            }));
        }
        if seed.iter().any(|x| !x.is_finite()) {
            return Err(self.bad(RequestProblem::NotFinite { what: "the seed" }));
        }
        Ok(())
    }
}
