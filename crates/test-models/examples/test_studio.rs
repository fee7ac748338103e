//! Scene `test_studio`: the studio over the models of `test_models/`: Andrews' squeezing
//! mechanism, the closed chain of ten rods, the Cartesian pendulums and
//! the rest, in the same studio as `models/`.
//!
//! `cargo run --release -p mechlab-test-models --features studio --example test_studio`
//! then open the printed address; `-- --set port=8080` for another port.

fn main() {
    mechlab_scenes::scene::run(|| {
        mechlab_studio::scene(
            "test_studio",
            mechlab_test_models::MODELS,
            "the interactive studio over test_models/: a local web server on 127.0.0.1",
            "8738",
        )
    });
}
