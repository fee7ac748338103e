//! mechlab: Lagrangians of small mechanical systems → symbolic derivations at
//! build time → fast, verified simulations and figures.
//!
//! Pipeline: `models/*.toml` → `build.rs` (Symbolica, build time only) →
//! generated modules in [`models`] → runtime: [`ode`] (integrators),
//! [`analysis`] (period map, Floquet, Lyapunov, averaging), [`studies`]
//! (closed forms and runs shared by the scenes of a study), [`plot`] →
//! `examples/` (scenes).
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

pub mod analysis;
pub mod contact;
pub mod explore;
pub mod linalg;
pub mod mathml;
pub mod model;
pub mod models;
pub mod ode;
pub mod plot;
pub mod registry;
pub mod report;
pub mod scene;
pub mod scenes;
pub mod studies;
pub mod studio;
pub mod test_models;
