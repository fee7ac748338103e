//! Scene `standard_map`: the Chirikov standard map
//! (q, p) ↦ (q + p + ε sin q, p + ε sin q) on the cylinder — orbits, and a
//! chaos map in which every pixel is shaded by the fast Lyapunov indicator of
//! its orbit (dark = chaotic): the stochastic web of Study 1 (docs/studies.md).
//!
//! Its settings are declared in `mechlab::analysis::standard_map`.

fn main() {
    mechlab::scene::run(
        mechlab::scenes::study_scene::<mechlab::analysis::standard_map::StandardMapOptions>,
    );
}
