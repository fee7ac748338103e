//! Every derived expression of every model, pinned as an insta snapshot
//! (text and LaTeX). The text is what `build.rs` wrote into the generated
//! modules; Symbolica is not called here. A new model file gets new
//! snapshots to review with `cargo insta review`.

#[test]
fn every_derived_expression_is_pinned() {
    for model in mechlab::models::ALL {
        assert!(
            !model.derivations.is_empty(),
            "{} has no derivations",
            model.name
        );
        for d in model.derivations {
            let name = format!(
                "{}__{}",
                model.name,
                d.key
                    .replace(['[', ']'], "_")
                    .replace("__", "_")
                    .trim_end_matches('_')
            );
            let body = format!(
                "{}\n\ntext:\n{}\n\nlatex:\n{}\n",
                d.description, d.text, d.latex
            );
            insta::assert_snapshot!(name, body);
        }
    }
}
