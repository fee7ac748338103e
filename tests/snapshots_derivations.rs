//! Every derived expression of every model shipped with its snapshots,
//! pinned as an insta snapshot (text and LaTeX). The text is what
//! `build.rs` wrote into the generated modules; Symbolica is not called
//! here. A model file a user adds has no snapshots yet: the test names it
//! and passes (so `cargo test` stays green for any valid model file), and
//! `INSTA_UPDATE=new cargo test --release --test snapshots_derivations`
//! writes its snapshots as `.snap.new` files for `cargo insta review`
//! (`INSTA_UPDATE=always` accepts them at once).

use std::path::Path;

/// Models shipped with their snapshots: `models/`, the 4-link chain of
/// `test_models/` and its Kapitza pendulum written as a point on a moving
/// rod. Fewer pinned means a shipped model lost its snapshots.
const SHIPPED: usize = 19;

#[test]
fn every_derived_expression_is_pinned() {
    let snapshots = Path::new(env!("CARGO_MANIFEST_DIR")).join("snapshots");
    let has_snapshots = |model: &str| {
        let prefix = format!("snapshots_derivations__{model}__");
        std::fs::read_dir(&snapshots).unwrap().any(|e| {
            let name = e.unwrap().file_name();
            let name = name.to_string_lossy();
            name.starts_with(&prefix) && name.ends_with(".snap")
        })
    };
    // Two test models (test_models/), pinned here too: the quadruple chain
    // and a moving constraint's forms.
    let quadruple = &mechlab_test_models::quadruple_pendulum::INFO;
    let cartesian = &mechlab_test_models::cartesian_kapitza::INFO;
    // Asked to write snapshots: a model without any gets them written.
    let writing = matches!(
        std::env::var("INSTA_UPDATE").as_deref(),
        Ok("new" | "always")
    );
    let (mut pinned, mut new_snapshots) = (0, Vec::new());
    for model in mechlab::models::ALL.iter().chain([quadruple, cartesian]) {
        assert!(
            !model.derivations.is_empty(),
            "{} has no derivations",
            model.name
        );
        if !has_snapshots(model.name) && !writing {
            eprintln!(
                "{}: no snapshots yet (a model file of your own?); write them for review with \
                 INSTA_UPDATE=new cargo test --release --test snapshots_derivations",
                model.name
            );
            continue;
        }
        let fresh = !has_snapshots(model.name);
        pinned += usize::from(!fresh);
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
            if fresh {
                // Every snapshot of a new model is written before the test
                // reports them (insta stops a test at its first new one).
                let written =
                    std::panic::catch_unwind(|| insta::assert_snapshot!(name.clone(), body));
                if written.is_err() {
                    new_snapshots.push(name);
                }
            } else {
                insta::assert_snapshot!(name, body);
            }
        }
    }
    assert!(
        new_snapshots.is_empty(),
        "{} new snapshots written as .snap.new in tests/snapshots for review \
         (cargo insta review, or accept them by renaming to .snap): {}",
        new_snapshots.len(),
        new_snapshots.join(", ")
    );
    assert!(pinned >= SHIPPED, "only {pinned} models pinned");
}

fn derived(model: &str, key: &str) -> &'static mechlab::registry::DerivedExpression {
    let info = mechlab::models::by_name(model)
        .ok()
        .map(|m| m.info)
        .expect("model exists");
    info.derivations
        .iter()
        .find(|d| d.key == key)
        .unwrap_or_else(|| panic!("{model} has no derived `{key}`"))
}

/// Pins the size of the key expressions, so that a regression to expanded
/// products of sines and cosines fails here and not only in review.
#[test]
fn key_expressions_stay_readable() {
    let kapitza_h = derived("kapitza", "hamiltonian").text;
    assert!(kapitza_h.len() <= 80, "{kapitza_h}");
    let v_vibr = derived("double_pendulum", "vibrational_potential").text;
    assert!(v_vibr.len() <= 120, "{v_vibr}");
    assert!(v_vibr.contains("(m1+m2*sin(phi1-phi2)^2)"), "{v_vibr}");
    let h = derived("double_pendulum", "hamiltonian").text;
    assert!(h.len() <= 400, "{} characters: {h}", h.len());
    assert_eq!(
        derived("inclined_pendulum", "vibrational_potential").text,
        "A^2*sin(q-alpha)^2/4"
    );
    assert_eq!(
        derived("elastic_pendulum", "vibrational_potential").text,
        "a^2*m/4"
    );
}

/// LaTeX follows a mechanics text: Greek letters, subscripts, dotted
/// velocities, momenta p_{φ₁}; no ASCII names of Greek letters are left.
#[test]
fn latex_uses_greek_letters_and_subscripts() {
    // The bicycle's wheel angles thetaR and thetaF read θ_R and θ_F.
    let bicycle = &mechlab_test_models::whipple_bicycle::INFO;
    for model in mechlab::models::ALL.iter().chain([bicycle]) {
        for d in model.derivations {
            for word in ["phi", "alpha", "theta", "tau", "eps", "mu", "nu"] {
                let bare = d
                    .latex
                    .match_indices(word)
                    .any(|(i, _)| i == 0 || !d.latex[..i].ends_with(['\\', 'r', 'a']));
                assert!(!bare, "{} {}: '{word}' in {}", model.name, d.key, d.latex);
            }
        }
    }
    // A two-digit index (the test model's parameter h10) is one subscript;
    // reading it as a name again sent the build into endless recursion.
    let energy = bicycle.derivations.iter().find(|d| d.key == "energy");
    let energy = energy.expect("the bicycle has an energy").latex;
    assert!(energy.contains("\\dot{\\theta_R}"), "{energy}");
    let awkward = &mechlab_test_models::awkward_names::INFO;
    let potential = awkward.derivations.iter().find(|d| d.key == "potential");
    let latex = potential.expect("awkward_names has a potential").latex;
    assert!(latex.contains("h_{10}"), "{latex}");
    let p = derived("double_pendulum", "velocities[0]").latex;
    assert!(p.contains("p_{\\varphi_2}") && p.contains("\\frac{"), "{p}");
    let rates = derived("double_pendulum", "momentum_rates[0]").latex;
    assert!(
        rates.contains("\\dot{\\varphi_1}") && rates.contains("\\sin \\varphi_1"),
        "{rates}"
    );
}

/// The chains solve for A⁻¹ at run time, so their K̄₂ has no closed form to
/// pin: their second-order Hessian at the upright chain (defaults, ν = 100)
/// is pinned instead, to nine digits, in a snapshot.
#[test]
fn chains_second_order_hessians_are_pinned() {
    use mechlab::models::triple_pendulum as triple;
    use mechlab_test_models::quadruple_pendulum as quadruple;
    fn rows<const S: usize>(h: [[f64; S]; S]) -> String {
        let scale = h.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
        // Round-off below 1e-12 of the largest entry prints as zero.
        let cell = |x: f64| if x.abs() < 1e-12 * scale { 0.0 } else { x };
        h.iter()
            .map(|row| {
                let cells: Vec<String> = row.iter().map(|&x| format!("{:+.9e}", cell(x))).collect();
                cells.join(" ")
            })
            .collect::<Vec<_>>()
            .join("\n")
    }
    let triple = triple::averaged2_hessian(&[0.0; 6], &triple::Params::default());
    insta::assert_snapshot!("triple_pendulum__averaged2_hessian_upright", rows(triple));
    let quadruple = quadruple::averaged2_hessian(&[0.0; 8], &quadruple::Params::default());
    insta::assert_snapshot!(
        "quadruple_pendulum__averaged2_hessian_upright",
        rows(quadruple)
    );
}
