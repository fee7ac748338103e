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

/// The positions of Andrews' squeezing mechanism (`andrews_squeezer`) at
/// t = 0.03 from its published start: the Test Set for IVP Solvers'
/// reference solution (β, Θ, γ, Φ, δ, Ω, ε).
pub const ANDREWS_AT_0_03: [f64; 7] = [
    0.1581077119629904e2,
    -0.1575637105984298e2,
    0.4082224013073101e-1,
    -0.5347301163226948,
    0.5244099658805304,
    0.5347301163226948,
    0.1048080741042263e1,
];
