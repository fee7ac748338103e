//! Model files: the expression language and the validated model description.
//! Compiled both into the library and into `build.rs` (via `#[path]`).

pub mod expr;
pub mod file;

pub use expr::Expr;
pub use file::{Contact, Inverse, Model, ModelError, Range, MAX_DOF, SYMBOLIC_INVERSE_MAX_DOF};
