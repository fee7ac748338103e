//! Scene `steady_motion`: the linearisation of a constrained model's
//! steady motion (Chaplygin's sleigh gliding straight by default, stable
//! forwards and unstable backwards): its eigenvalues with their errors and
//! verdict, and the eigenvalues against the speed with the stability
//! boundaries. The shape, the speed and the rates to hold are found from
//! the model unless named.
//!
//! `cargo run --release --example steady_motion`
//! `cargo run --release --example steady_motion -- --set model=rolling_disk`

fn main() {
    mechlab::scene::run(|| {
        mechlab::scenes::steady_motion_scene(mechlab::models::MODELS, "steady_motion", &[])
    });
}
