//! Theorem 2 on any model by name: the deviation between the exact and the
//! averaged runs from the same state falls like 1/ν.

use super::model_of;
use mechlab::analysis::averaging::{
    convergence, AveragingError, ConvergenceSettings, SweepProblem,
};
use mechlab::analysis::Refusal;
use mechlab::ode::Method;
use mechlab::registry::ParameterError;

fn settings(parameter: Option<&str>, values: &[f64]) -> ConvergenceSettings {
    ConvergenceSettings {
        parameter: parameter.map(str::to_string),
        values: Some(values.to_vec()),
        y0: None,
        t_obs: 2.0,
        method: Method::parse("dop853", 1e-11).unwrap(),
        order: 1,
    }
}

fn defaults(name: &str) -> Vec<f64> {
    mechlab::models::by_name(name).unwrap().dynamic.defaults()
}

#[test]
fn deviation_falls_like_one_over_the_frequency() {
    let values = [200.0, 400.0, 800.0, 1600.0];
    for name in ["double_pendulum", "triple_pendulum"] {
        let result =
            convergence(model_of(name), &defaults(name), &settings(None, &values)).unwrap();
        assert_eq!(result.parameter, "nu", "the rate of `{name}` is ν");
        for (f, v) in result.frequencies.iter().zip(values) {
            assert!((f - v).abs() < 1e-9 * v, "{f} vs {v}");
        }
        assert_eq!(result.slope.len(), result.coordinates.len());
        for (coordinate, slope) in result.coordinates.iter().zip(&result.slope) {
            assert!(
                (slope + 1.0).abs() < 0.15,
                "{name} {coordinate}: slope {slope}"
            );
        }
        // ν × deviation levels off (within a factor 1.5 over the sweep).
        for deviations in &result.max_deviation {
            let levels: Vec<f64> = deviations
                .iter()
                .zip(&values)
                .map(|(d, nu)| d * nu)
                .collect();
            let (lo, hi) = levels
                .iter()
                .fold((f64::MAX, 0.0f64), |(l, h), x| (l.min(*x), h.max(*x)));
            assert!(hi < 1.5 * lo, "{name}: ν·deviation {levels:?}");
        }
    }
    // Kapitza's rate is 1/ε: the swept parameter is ε, ν = 1/ε; without
    // values, ν runs over 4…64 times the default frequency 1/ε = 10.
    let mut auto = settings(None, &[]);
    auto.values = None;
    let result = convergence(model_of("kapitza"), &defaults("kapitza"), &auto).unwrap();
    assert!(
        (result.values[0] - 0.025).abs() < 1e-15 && (result.frequencies[4] - 640.0).abs() < 1e-9
    );
    assert!((result.slope[0] + 1.0).abs() < 0.15, "{:?}", result.slope);
    let result = convergence(
        model_of("kapitza"),
        &defaults("kapitza"),
        &settings(None, &[0.02, 0.01, 0.005]),
    )
    .unwrap();
    assert_eq!(result.parameter, "eps");
    assert!((result.frequencies[0] - 50.0).abs() < 1e-9);
    assert!((result.slope[0] + 1.0).abs() < 0.15, "{:?}", result.slope);
}

#[test]
fn bad_requests_are_typed_errors() {
    let e = convergence(
        model_of("painleve_klein"),
        &defaults("painleve_klein"),
        &settings(None, &[1.0]),
    )
    .unwrap_err();
    assert!(
        matches!(e, AveragingError::Refused(Refusal::ContactModel { .. })),
        "{e}"
    );
    let e = convergence(
        model_of("kapitza"),
        &defaults("kapitza"),
        &settings(Some("nu"), &[1.0]),
    )
    .unwrap_err();
    assert!(
        matches!(
            &e,
            AveragingError::Refused(Refusal::Parameter(ParameterError::Unknown { name, .. })) if name == "nu"
        ),
        "{e}"
    );
    let e = convergence(
        model_of("kapitza"),
        &defaults("kapitza"),
        &settings(Some("A"), &[1.0, 2.0]),
    )
    .unwrap_err();
    assert!(
        matches!(
            &e,
            AveragingError::Sweep { parameter, problem: SweepProblem::FrequencyUnchanged, .. } if parameter == "A"
        ),
        "{e}"
    );
    let mut bad_state = settings(None, &[100.0]);
    bad_state.y0 = Some(vec![0.1, 0.0]);
    let e = convergence(
        model_of("double_pendulum"),
        &defaults("double_pendulum"),
        &bad_state,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            AveragingError::Refused(Refusal::StateLength {
                given: 2,
                expected: 4,
                ..
            })
        ),
        "{e}"
    );
}
