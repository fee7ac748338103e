//! Analyses built on the integrators: the period map and its orbits,
//! variational equations (monodromy, Floquet multipliers, Lyapunov exponents,
//! the fast Lyapunov indicator) and the Chirikov standard map.

pub mod dimension;
pub mod floquet;
pub mod lyapunov;
pub mod period_map;
pub mod standard_map;
pub mod variational;
