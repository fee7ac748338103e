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

/// The car axis (`car_axis`) at t = 3 from the Test Set's start (xl, yl,
/// xr, yr at 0, L0, L, L0; velocities −L0/L, 0, −L0/L, 0): the Test Set
/// for IVP Solvers' reference solution, positions, velocities and the two
/// multipliers (λ of M q'' = F + Gᵀλ, the axle's squareness then its
/// length).
#[allow(clippy::excessive_precision)] // the Test Set's digits, as published
pub const CAR_AXIS_AT_3: [f64; 10] = [
    0.4934557842755629e-1,
    0.4969894602303324,
    0.1041742524885400e1,
    0.3739110272652214,
    -0.7705836840321485e-1,
    0.7446866596327776e-2,
    0.1755681574942899e-1,
    0.7703410437794031,
    -0.4736886750784630e-2,
    -0.1104680411345730e-2,
];
