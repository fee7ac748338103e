//! mechlab's runtime: everything that does not depend on any one model.
//!
//! Integrators ([`ode`]), analyses by name ([`analysis`], [`explore`]) over
//! models behind trait objects ([`registry`]), scenes ([`scene`],
//! [`scenes`]), the studio ([`studio`]), figures ([`plot`]) and reports.
//! The generated models live in the `mechlab` package, which compiles
//! against this crate and hands it its models with [`registry::install`]:
//! editing a model file never recompiles this crate.

pub use mechlab_model as model;

pub mod analysis;
pub mod budget;
pub mod contact;
pub mod explore;
pub mod large_models;
pub mod linalg;
pub mod mathml;
pub mod ode;
pub mod plot;
pub mod registry;
pub mod report;
pub mod scene;
pub mod scenes;
pub mod studio;
pub mod study;
