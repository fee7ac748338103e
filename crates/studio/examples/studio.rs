//! Scene `studio`: the interactive studio in the browser. Pick a model of
//! `models/`, move its parameters, click on the phase plane to seed orbits
//! of the period map (computed here with the generated Taylor method and
//! streamed to the page) and watch the mechanism move beside them, overlay
//! the level sets of H̄, the equilibria and the FLI chaos map of the view,
//! read the derivations as formulas.
//!
//! `cargo run --release --example studio` then open the printed address;
//! `-- --set port=8080` for another port (0: any free one).

fn main() {
    mechlab::scene::run(|| {
        mechlab_studio::scene(
            "studio",
            mechlab::models::MODELS,
            "the interactive studio: a local web server on 127.0.0.1",
            "8737",
        )
    });
}
