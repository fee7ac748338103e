//! Scene `trade`: what an analysis's accuracy costs on a model. The
//! analysis runs over a ladder of methods and tolerances; each run's time
//! is drawn against the error it states on its headline numbers and its
//! distance to the most accurate run. Where `accuracy` is set, the run
//! that asks for it is drawn too, with its cost over the cheapest
//! hand-chosen run that stated as small an error.
//!
//! `cargo run --release --example trade -- --set analysis=stability --set eps=0.01`
//! `cargo run --release --example trade -- --set analysis=chaos_map --set pixels=60 --set accuracy=0.01`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::trade_scene(mechlab::models::MODELS));
}
