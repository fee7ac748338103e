//! Scene `explore`: any model of `models/`, by name. It integrates the exact
//! system (and the averaged one if the model has a fast phase; the
//! stick–slip integrator for a contact model) with the chosen method and
//! tolerance, and draws the time series and phase portraits per degree of
//! freedom, the period map, exact against averaged, and the energy change;
//! the equilibria of the effective potential with their stability go to the
//! summary. Every parameter of the chosen model is a knob.
//!
//! `cargo run --release --example explore -- --set model=elastic_pendulum --set k=20`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::explore_scene(mechlab::models::MODELS));
}
