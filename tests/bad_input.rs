//! Bad input never panics: random and mutated model files, and random
//! command lines, end in a typed error or a success.

use mechlab::scene::{knob, Scene};
use mechlab::settings::Range;
use mechlab_model::Model;
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
            match scene.get::<f64>("tol", Range::Positive) {
                Ok(tol) => prop_assert!(tol > 0.0 && tol.is_finite()),
                Err(e) => prop_assert!(e.to_string().contains("--set tol="), "{}", e),
            }
            match scene.get::<f64>("a", Range::Any) {
                Ok(a) => prop_assert!(a.is_finite()),
                Err(e) => prop_assert!(e.to_string().contains("--set a="), "{}", e),
            }
            if let Ok(values) = scene.get::<Vec<f64>>("a", Range::Any) {
                prop_assert!(!values.is_empty() && values.iter().all(|v| v.is_finite()));
            }
            if let Ok(count) = scene.get::<usize>("a", Range::Count { min: 1, max: 10 }) {
                prop_assert!((1..=10).contains(&count));
            }
        }
    }
}

/// Requests whose results could not be held in memory are named errors
/// before any work (they aborted the process on an allocation before).
#[test]
fn too_large_requests_are_refused_before_any_work() {
    use mechlab::analysis::chaos_map::{chaos_map, ChaosMapSettings};
    use mechlab::models::kapitza::Params;
    use mechlab::ode::{Method, OdeError};
    use mechlab::studies::kapitza::{portrait, single_orbit};
    use mechlab::study::StudyError;
    let params = Params {
        A: 1.0,
        eps: 0.1,
        mu: 0.0,
    };
    let method = Method::parse("dop853", 1e-10).unwrap();
    let too_large = |e: &StudyError| matches!(e, StudyError::Ode(OdeError::TooLarge(_)));
    let e = single_orbit(params, [0.1, 0.0], 2_000_000_000, method, 1).unwrap_err();
    assert!(too_large(&e), "{e}");
    assert!(
        e.to_string().contains("1 orbit(s) of 2000000000 periods"),
        "{e}"
    );
    // 24 orbits that each would fit, but not together.
    let e = portrait(params, 24, 20_000_000, method).unwrap_err();
    assert!(too_large(&e), "{e}");
    let settings = ChaosMapSettings {
        check: 0,
        accuracy: None,
        axes: [0, 1],
        ranges: [None, None],
        p_max: 3.0,
        through: None,
        pixels: 1_000_000,
        periods: 10,
        method,
        tiles: None,
    };
    let e = chaos_map(
        mechlab::models::by_name("kapitza").unwrap(),
        &params.values(),
        &settings,
        &|| true,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("a map of 1000000 × 1000000 pixels"),
        "{e}"
    );
}

/// A tolerance below what double precision holds is refused before any
/// step, naming the floor (it took ten million steps to end before).
#[test]
fn a_tolerance_below_the_rounding_is_refused_by_name() {
    use mechlab::analysis::declared::{no_progress, Analysis};
    use mechlab::explore::ExploreOptions;
    use mechlab::settings::Declared;
    let model = mechlab::models::by_name("kapitza").unwrap();
    let options = ExploreOptions::default()
        .with_texts([("method", "dop853"), ("tol", "1e-20")])
        .unwrap();
    let error = options
        .run(model, &model.dynamic.defaults(), &no_progress)
        .expect_err("refused");
    let message = error.to_string();
    assert!(
        message.contains("below what double precision can reach") && message.contains("1e-20"),
        "{message}"
    );
    assert_eq!(
        mechlab::classify::Classify::class(&error),
        mechlab::classify::ErrorClass::BadValue
    );
    // At the floor it runs.
    let floor = mechlab::ode::PRECISION_FLOOR;
    assert!(mechlab::ode::Method::parse("radau5", floor).is_ok());
    assert!(mechlab::ode::Method::parse("radau5", 0.5 * floor).is_err());
}

/// A run far longer than its step limit allows (a pendulum to t = 1e9 with
/// steps of about 0.1, by DOP853 and by the Taylor method) stops after a
/// hundredth of the limit with the steps it would take, not after the ten
/// million the limit allows; a run just within the limit is not stopped.
#[test]
fn a_run_too_long_for_its_step_limit_stops_early_with_its_forecast() {
    use mechlab::models::kapitza;
    use mechlab::ode::{Integrator, Method, OdeError};
    let system = kapitza::Exact {
        params: kapitza::Params {
            A: 1.5,
            eps: 0.1,
            mu: 0.0,
        },
    };
    for method in [
        Method::parse("dop853", 1e-10),
        Method::parse("taylor", 1e-12),
    ] {
        let mut integrator = Integrator::new(method.unwrap()).unwrap();
        let error = integrator
            .advance(&system, 0.0, &[0.1, 0.0], 1e9)
            .unwrap_err();
        let OdeError::TooLong {
            t_end,
            forecast,
            max_steps,
            ..
        } = error
        else {
            panic!("{error}");
        };
        assert_eq!(t_end, 1e9);
        assert!(forecast > 100.0 * max_steps as f64, "{forecast}");
        assert!(
            integrator.stats.steps <= max_steps / 100,
            "{}",
            integrator.stats.steps
        );
        assert!(error.to_string().contains("shorten the run"), "{error}");
    }
    let mut integrator = Integrator::new(Method::parse("dop853", 1e-10).unwrap()).unwrap();
    integrator.max_steps = 100_000;
    integrator.advance(&system, 0.0, &[0.1, 0.0], 1e3).unwrap();
    let steps = integrator.stats.steps + integrator.stats.rejected;
    // Just within the limit: the run is not stopped by its forecast.
    let mut integrator = Integrator::new(Method::parse("dop853", 1e-10).unwrap()).unwrap();
    integrator.max_steps = steps + steps / 10;
    integrator.advance(&system, 0.0, &[0.1, 0.0], 1e3).unwrap();
}

/// A run that leaves a model's domain names the model file's expression
/// that stopped being real: the bead on a circle written in x
/// (`test_models/bead_on_circle.toml`, height −√(R² − x²)) thrown hard
/// enough towards the wire's equator leaves its chart, and `explore`
/// says `definitions.y` is NaN there, at an x past R, in the model's file.
#[test]
fn a_run_out_of_the_models_domain_names_the_expression() {
    use mechlab::analysis::declared::{no_progress, Analysis, AnalysisError};
    use mechlab::explore::ExploreOptions;
    let model = &mechlab_test_models::bead_on_circle::MODEL;
    let values = model.dynamic.defaults();
    let options = ExploreOptions {
        y0: Some(vec![0.5, 3.0]),
        ..ExploreOptions::default()
    };
    let error = options
        .run(model, &values, &no_progress)
        .map_err(|e| e.located(model, &values))
        .expect_err("the bead leaves the chart |x| < R");
    let AnalysisError::OutsideDomain { domain, .. } = &error else {
        panic!("not located: {error}");
    };
    assert_eq!(domain.undefined.key, "definitions.y", "{error}");
    assert_eq!(
        domain.undefined.expression.replace(' ', ""),
        "-sqrt(R^2-x^2)",
        "{error}"
    );
    assert!(domain.undefined.value.is_nan(), "{error}");
    assert_eq!(domain.state[0].0, "x");
    assert!(domain.state[0].1 > 1.0, "{error}");
    let text = error.to_string();
    assert!(
        text.contains("bead_on_circle.toml") && text.contains("x = "),
        "{text}"
    );
    // Within the chart the same model runs.
    let inside = ExploreOptions {
        y0: Some(vec![0.5, 0.0]),
        ..ExploreOptions::default()
    };
    inside.run(model, &values, &no_progress).unwrap();
}

/// An `accuracy` below what double precision resolves on the numbers it
/// asks about is refused before any run, naming the floor: the period
/// map's points, the averaging's deviations, the linkage's edges, the
/// continuation's parameters and the section's crossings.
#[test]
fn an_accuracy_below_the_precision_floor_is_refused_before_any_run() {
    use mechlab::analysis::declared::{no_progress, Analysis, AnalysisError};
    let cases: Vec<(&str, Result<(), AnalysisError>)> = vec![
        (
            "period_map",
            run::<mechlab::analysis::period_map::PeriodMapOptions>("kapitza"),
        ),
        (
            "averaging",
            run::<mechlab::analysis::averaging::AveragingOptions>("kapitza"),
        ),
        (
            "linkage",
            run::<mechlab::analysis::on_constraints::vibration::LinkageOptions>("four_bar"),
        ),
        (
            "continuation",
            run::<mechlab::analysis::continuation::ContinuationOptions>("duffing"),
        ),
        (
            "steady_motion",
            run::<mechlab::analysis::on_constraints::steady::study::SteadyMotionOptions>(
                "chaplygin_sleigh",
            ),
        ),
        (
            "section",
            run::<mechlab::analysis::section::SectionOptions>("henon_heiles"),
        ),
    ];
    fn run<T: Analysis>(model: &str) -> Result<(), AnalysisError> {
        let model = mechlab::models::by_name(model).unwrap();
        let options = T::default().with_texts([("accuracy", "1e-20")]).unwrap();
        options
            .run(model, &model.dynamic.defaults(), &no_progress)
            .map(|_| ())
    }
    for (analysis, result) in cases {
        let error = result
            .err()
            .unwrap_or_else(|| panic!("{analysis}: not refused"));
        let text = error.to_string();
        assert!(
            matches!(
                error,
                AnalysisError::Refusal(mechlab::analysis::Refusal::BelowPrecision { .. })
            ) || text.contains("below what double precision resolves"),
            "{analysis}: {text}"
        );
        assert!(text.contains("64 units of rounding"), "{analysis}: {text}");
    }
}
