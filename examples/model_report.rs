//! Scene `model_report`: prints the derivations of a model (deliverables 1.1,
//! 2.1) and writes them as Markdown with LaTeX.

use mechlab::scene::{knob, run, Scene};

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "model_report",
            "the derivations of a model: Lagrangian, momenta, Hamiltonian, averaged system, equations of motion",
            &[knob("model", "kapitza", "model name (a file models/<name>.toml)")],
        )?;
        let name = scene.text("model").to_string();
        let model = mechlab::models::by_name(&name)?.info;
        let mut markdown = format!(
            "# Model `{}`\n\nFrom `{}`:\n\n```toml\n{}```\n\n",
            model.name, model.source_file, model.source
        );
        markdown += &format!(
            "Coordinates {:?}, momenta {:?}; parameters {:?}.\n\n",
            model.coordinates, model.momenta, model.parameter_names
        );
        println!("model {} ({})\n", model.name, model.source_file);
        for d in model.derivations {
            println!("{}  [{}]\n    {}\n", d.key, d.description, d.text);
            markdown += &format!(
                "## `{}`\n\n{}\n\n$$\n{}\n$$\n\n",
                d.key, d.description, d.latex
            );
        }
        if model.name == "kapitza" {
            let note = "One-step averaging (docs/studies.md, Study 1): the generating function \
                W = P q + ε f(q, P, θ) with f = A P sin q cos θ + (A²/8) sin²q sin 2θ removes the phase at order zero, \
                leaving Ĥ = H̄ + O(ε) with H̄ the averaged Hamiltonian above: P²/2 + cos Q + (A²/4) sin²Q. \
                Its upper position Q = 0 is stable when V''(0) = −1 + A²/2 > 0, i.e. A > √2.";
            println!("{note}\n");
            markdown += &format!("## One-step averaging\n\n{note}\n");
        }
        markdown += "## Cost of the generated right-hand sides\n\n\
            Operations after common-subexpression elimination (transcendental calls count 20, \
            divisions 4): as derived, in the readable form above, and emitted.\n\n\
            | function | derived | readable | emitted |\n|---|---|---|---|\n";
        for (function, derived, readable, emitted) in model.operation_counts {
            println!(
                "cost of {function}: derived {derived}, readable {readable}, emitted {emitted}"
            );
            markdown += &format!("| `{function}` | {derived} | {readable} | {emitted} |\n");
        }
        scene.write_text("derivations.md", &markdown)?;
        scene.write_text("generated.rs", model.generated_code)?;
        #[derive(serde::Serialize)]
        struct Summary {
            model: &'static str,
            expressions: usize,
            generated_lines: usize,
            /// (function, derived, readable, emitted)
            operation_counts: &'static [(&'static str, usize, usize, usize)],
        }
        scene.write_summary(&Summary {
            model: model.name,
            expressions: model.derivations.len(),
            generated_lines: model.generated_code.lines().count(),
            operation_counts: model.operation_counts,
        })?;
        Ok(())
    });
}
