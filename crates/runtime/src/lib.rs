//! mechlab's runtime: everything that does not depend on any one model.
//!
//! Integrators ([`ode`]), analyses by name ([`analysis`], [`explore`]) over
//! models behind trait objects ([`registry`]), the studio's calls
//! ([`studio`]), figures ([`plot`]) and reports. The scenes (the command
//! line's knobs and the files a run writes) are the `mechlab-scenes`
//! crate above this one.
//! The generated models live in the `mechlab` package, which compiles
//! against this crate and hands its models to the analyses as a
//! [`registry::Catalog`]:
//! editing a model file never recompiles this crate.

pub mod analysis;
pub mod budget;
pub mod classify;
pub mod constrained;
pub mod contact;
pub mod domain;
pub mod explore;
pub mod mathml;
pub mod ode;
pub mod outputs;
pub mod plot;
pub mod registry;
pub mod report;
pub mod settings;
pub mod study;
pub mod tangent;

/// Fixed-size linear algebra, where the generated code reaches it.
pub use ode::linalg;
