//! mechlab: Lagrangians of small mechanical systems → symbolic derivations at
//! build time → fast, verified simulations and figures.
//!
//! Pipeline: `models/*.toml` → `build.rs` (Symbolica, build time only) →
//! generated modules in [`models`] → runtime: [`ode`] (integrators),
//! analyses, plots → `examples/` (scenes).

pub mod analysis;
pub mod model;
pub mod models;
pub mod ode;
pub mod plot;
pub mod registry;
pub mod scene;
