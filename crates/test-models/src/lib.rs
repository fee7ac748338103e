//! Models for tests and benchmarks only, generated from `test_models/` like
//! the users' models in `mechlab::models` (a package of their own, so that
//! neither a scene nor an edit of a user's model compiles them): e.g. the
//! double pendulum in the numeric-solve form, to be compared with its
//! symbolic-inverse form.

// The paths the generated modules name (`crate::ode`, ...); a folder
// without contact or constrained models leaves `contact` or `constrained`
// unused.
#[allow(unused_imports)]
use mechlab_runtime::{constrained, contact, linalg, ode, registry};

include!(concat!(env!("OUT_DIR"), "/generated/mod.rs"));
