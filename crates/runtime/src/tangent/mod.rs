//! Tangent dynamics: a system with its variational equations, and the
//! indicators read from tangent vectors (Lyapunov exponents, the fast
//! Lyapunov indicator, MEGNO) and monodromy matrices.
//!
//! These are the kernels a model runs at its own state size (the registry's
//! [`crate::registry::Systems`] calls them), below the analyses, which reach
//! them through the registry with states of any length.

pub mod lyapunov;
pub mod monodromy;
pub mod variational;
