//! Scene `studio`: the interactive studio in the browser. Pick a model of
//! `models/`, move its parameters, click on the phase plane to seed orbits
//! of the period map (computed here with the generated Taylor method and
//! streamed to the page), overlay the level sets of H̄, the equilibria and
//! the FLI chaos map of the view, read the derivations as formulas.
//!
//! `cargo run --release --example studio` then open the printed address;
//! `-- --set port=8080` for another port (0: any free one).

use mechlab::scene::{knob, Scene, SceneError};

fn main() {
    mechlab::scene::run(|| {
        let scene = Scene::from_args(
            "studio",
            "the interactive studio: a local web server on 127.0.0.1",
            &[knob(
                "port",
                "8737",
                "the port to listen on (0: any free port)",
            )],
        )?;
        let port = scene.count("port")?;
        let port = u16::try_from(port).map_err(|_| SceneError::BadValue {
            name: "port".into(),
            value: port.to_string(),
            reason: "a port is at most 65535".into(),
        })?;
        mechlab::studio::server::run(mechlab::models::MODELS, port)?;
        Ok(())
    });
}
