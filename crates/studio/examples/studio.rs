//! Scene `studio`: the interactive studio in the browser. Pick a model of
//! `models/`, move its parameters, click on the phase plane to seed orbits
//! of the period map (computed here with the generated Taylor method and
//! streamed to the page), overlay the level sets of H̄, the equilibria and
//! the FLI chaos map of the view, read the derivations as formulas.
//!
//! `cargo run --release --example studio` then open the printed address;
//! `-- --set port=8080` for another port (0: any free one).

use mechlab::scene::{knob, run, Scene, SceneError};

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "studio",
            "the interactive studio: a local web server on 127.0.0.1",
            &[knob(
                "port",
                "8737",
                "the port to listen on (0: any free port)",
            )],
        )?;
        let port = scene
            .text("port")
            .parse::<u16>()
            .map_err(|_| SceneError::BadValue {
                name: "port".into(),
                value: scene.text("port").into(),
                reason: mechlab::scene::ValueProblem::Requirement(
                    "a port is a whole number from 0 to 65535",
                ),
            })?;
        mechlab_studio::run(mechlab::models::MODELS, port)
    });
}
