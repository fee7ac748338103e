//! Scene `model_report`: prints the derivations of a model (deliverables 1.1,
//! 2.1) and writes them as Markdown with LaTeX (`derivations.md`), beside
//! the generated code (`generated.rs`).

use mechlab::scene::{knob, run, Scene};

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "model_report",
            "the derivations of a model: Lagrangian, momenta, Hamiltonian, averaged system, equations of motion",
            &[knob("model", "kapitza", "model name (a file models/<name>.toml)")],
        )?;
        let model = mechlab::models::by_name(scene.text("model"))?.info;
        mechlab::scenes::write_outputs(&scene, &mechlab::report::model_report(model))
    });
}
