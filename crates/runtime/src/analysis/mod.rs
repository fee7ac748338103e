//! Analyses built on the integrators: the period map and its orbits,
//! variational equations (monodromy, Floquet multipliers, Lyapunov exponents,
//! the fast Lyapunov indicator), the Chirikov standard map, the comparison
//! of exact and averaged systems, stabilisation by vibration, and
//! Poincaré sections of autonomous models, and the continuation of
//! periodic orbits in a parameter with their bifurcations.

pub mod attractor;
pub mod averaging;
pub mod chaos_map;
pub mod continuation;
pub mod dimension;
pub mod fit;
pub mod floquet;
pub mod lyapunov;
pub mod period_map;
pub mod section;
pub mod section_map;
pub mod separatrix;
pub mod stability;
pub mod standard_map;
pub mod tiles;
pub mod variational;
pub mod vibrational_stability;
