//! The generated model modules, one per file in `models/` (see `build.rs`).
//! Each has a typed `Params`, fixed-size state functions (`exact_rhs`,
//! `averaged_rhs`, Jacobians, `hamiltonian`, potentials, ...), and the
//! systems `Exact` / `Averaged` for the integrators.

include!(concat!(env!("OUT_DIR"), "/generated/mod.rs"));

/// The model named `name` (a file `models/<name>.toml`), or an error that
/// lists the known ones: the handle every analysis takes.
pub fn by_name(
    name: &str,
) -> Result<&'static crate::registry::Model, crate::registry::UnknownModel> {
    crate::registry::lookup(MODELS, name)
}
