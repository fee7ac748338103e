//! The generated model modules, one per file in `models/` (see `build.rs`).
//! Each has a typed `Params`, fixed-size state functions (`exact_rhs`,
//! `averaged_rhs`, Jacobians, `hamiltonian`, potentials, ...), and the
//! systems `Exact` / `Averaged` for the integrators.

include!(concat!(env!("OUT_DIR"), "/generated/mod.rs"));
