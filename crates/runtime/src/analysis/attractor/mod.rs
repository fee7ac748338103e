//! The attractor of the period map of a forced, damped model of one degree
//! of freedom, by model name: the orbit after its transient as a density
//! image, the full Lyapunov spectrum with its convergence and an error
//! from a second initial condition, the check Σλ = ∫₀ᵀ div f dt (the
//! divergence of the flow averaged along the orbit, measured separately),
//! and the box-counting and Kaplan–Yorke dimensions.
//!
//! A constrained model is analysed on its constraints
//! ([`on_constraints`]), a model of one degree of freedom in its plane
//! ([`of_plane`]); both give an [`Attractor`].

mod of_plane;
pub mod on_constraints;
mod types;

pub use types::{Attractor, AttractorError, AttractorOptions, AttractorSettings};

use crate::registry::Model;

/// The attractor of `model`'s period map at `params`: of a model of one
/// degree of freedom in its plane (q, p), of a constrained model of one
/// degree of freedom on its constraints in the chart of its first
/// coordinate and that coordinate's velocity.
pub fn attractor(
    model: &Model,
    params: &[f64],
    settings: &AttractorSettings,
) -> Result<Attractor, AttractorError> {
    match model.constrained {
        Some(constrained) => on_constraints::attractor(model, constrained, params, settings),
        None => of_plane::attractor(model, params, settings),
    }
}
