//! mechlab: Lagrangians of small mechanical systems → symbolic derivations at
//! build time → fast, verified simulations and figures.
//!
//! The workspace follows the data flow: `models/*.toml` (read by
//! `mechlab-model`) → `build.rs` (runs `mechlab-derive`, with Symbolica,
//! build time only) → the generated modules in [`models`] (this crate) →
//! `mechlab-runtime`: [`ode`] (integrators), [`analysis`] (period map,
//! Floquet, Lyapunov, averaging), [`studio`], [`plot`] → `mechlab-scenes`:
//! [`scene`] (the scene framework) and [`scenes`] (shared scene bodies) →
//! `examples/` (scenes). This crate holds only what depends on the models:
//! the generated modules and the three [`studies`]; it re-exports the
//! runtime and the scenes, so `mechlab::ode` is `mechlab_runtime::ode`.
//!
//! ```
//! use mechlab::models::kapitza;
//! use mechlab::ode::{Integrator, Method};
//!
//! // The averaged Kapitza pendulum conserves its Hamiltonian H̄.
//! let params = kapitza::Params { A: 2.0, ..Default::default() };
//! let system = kapitza::Averaged { params };
//! let mut integrator = Integrator::new(Method::parse("gauss6", 0.05).unwrap()).unwrap();
//! let y0 = [0.4, 0.0];
//! let y = integrator.advance(&system, 0.0, &y0, 100.0).unwrap();
//! let drift = kapitza::averaged_hamiltonian(&y, &params) - kapitza::averaged_hamiltonian(&y0, &params);
//! assert!(drift.abs() < 1e-9);
//! assert_eq!(integrator.stats.steps, 2000);
//! ```

pub use mechlab_runtime::{
    analysis, budget, classify, constrained, contact, explore, linalg, mathml, ode, outputs, plot,
    registry, report, settings, study,
};
pub use mechlab_scenes::{scene, scenes};

pub mod models;
pub mod studies;
