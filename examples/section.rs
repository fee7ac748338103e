//! Scene `section`: the Poincaré surface of section of an autonomous model
//! of two degrees of freedom at a fixed energy (Hénon–Heiles by default):
//! orbits seeded across the accessible part of the plane, the missing
//! momentum solved from H = E, crossings located on the dense output.
//!
//! `cargo run --release --example section -- --set energy=0.125`
//! `cargo run --release --example section -- --set model=<name> --set energy=<E>`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::section_scene(mechlab::models::MODELS, "section", &[]));
}
