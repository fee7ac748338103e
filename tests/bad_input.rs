//! Bad input never panics: random and mutated model files, and random
//! command lines, end in a typed error or a success.

use mechlab::model::Model;
use mechlab::scene::{knob, Scene};
use proptest::prelude::*;

const SHIPPED: [&str; 3] = [
    include_str!("../models/kapitza.toml"),
    include_str!("../models/double_pendulum.toml"),
    include_str!("../models/painleve_klein.toml"),
];

/// Pieces of model-file syntax that mutations splice in.
const FRAGMENTS: [&str; 16] = [
    "(",
    ")",
    "^",
    "/0",
    "dot(",
    "sin(",
    "=",
    "\"",
    "[[contacts]]",
    "\n",
    "1e308",
    "-",
    "*x",
    "__",
    "nan",
    "]",
];

fn mutate(text: &str, edits: &[(usize, usize, u8)]) -> String {
    let mut s: Vec<char> = text.chars().collect();
    for &(at, fragment, kind) in edits {
        if s.is_empty() {
            break;
        }
        let at = at % s.len();
        match kind % 3 {
            0 => {
                s.remove(at);
            }
            1 => {
                for (k, c) in FRAGMENTS[fragment % FRAGMENTS.len()].chars().enumerate() {
                    s.insert(at + k, c);
                }
            }
            _ => s.truncate(at),
        }
    }
    s.into_iter().collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn mutated_model_files_give_errors_not_panics(
        which in 0usize..3,
        edits in prop::collection::vec((any::<usize>(), any::<usize>(), any::<u8>()), 1..6),
    ) {
        let text = mutate(SHIPPED[which], &edits);
        match Model::parse("models/mutated.toml", &text) {
            // A mutation that still parses is a model in full: coordinates,
            // and parsing is a function of the text.
            Ok(model) => {
                prop_assert!(!model.coordinates.is_empty());
                let again = Model::parse("models/mutated.toml", &text).unwrap();
                prop_assert_eq!(format!("{model:?}"), format!("{again:?}"));
            }
            Err(e) => prop_assert!(e.to_string().starts_with("models/mutated.toml: key `")),
        }
    }

    #[test]
    fn random_text_is_not_a_model(text in ".{0,200}") {
        prop_assert!(Model::parse("models/random.toml", &text).is_err());
    }

    #[test]
    fn random_command_lines_give_errors_not_panics(
        args in prop::collection::vec("(--set|--out|--help|[a-z=.0-9 -]{0,12}|tol=[0-9eE.+-]{0,8}|a=nan)", 0..6),
    ) {
        let knobs = [knob("tol", "1e-10", "tolerance"), knob("a", "1", "amplitude")];
        if let Ok(scene) = Scene::parse("random", &knobs, &args) {
            // Values that parse keep their contracts; the others are typed
            // errors naming the knob, never panics.
            match scene.positive("tol") {
                Ok(tol) => prop_assert!(tol > 0.0 && tol.is_finite()),
                Err(e) => prop_assert!(e.to_string().contains("--set tol="), "{}", e),
            }
            match scene.number("a") {
                Ok(a) => prop_assert!(a.is_finite()),
                Err(e) => prop_assert!(e.to_string().contains("--set a="), "{}", e),
            }
            if let Ok(values) = scene.numbers("a") {
                prop_assert!(!values.is_empty() && values.iter().all(|v| v.is_finite()));
            }
            if let Ok(count) = scene.count("a") {
                prop_assert!(count > 0);
            }
        }
    }
}
