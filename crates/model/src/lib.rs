//! Model files: the expression language and the validated model description.
//! Shared by the derivation (`mechlab-derive`, at build time) and the runtime.

pub mod bodies;
pub mod domain;
pub mod expr;
pub mod file;

pub use domain::Undefined;
pub use expr::Expr;
pub use file::{
    Constraint, ConstraintKind, Contact, Inverse, Model, ModelError, Point, Range, RangeError,
    MAX_DOF, MAX_POINTS, SYMBOLIC_INVERSE_MAX_DOF,
};
