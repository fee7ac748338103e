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
        check: false,
        accuracy: None,
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

/// The undamped forced oscillator x'' + x = F cos(ωt) from (x0, 0):
/// exactly x0 cos t + A (cos ωt − cos t) with A = F/(1 − ω²), averaged
/// x0 cos t, so the deviation is |A (cos ωt − cos t)|, here at the
/// analysis's own samples.
fn oscillator_deviation(f: f64, omega: f64, t_obs: f64) -> f64 {
    use mechlab::analysis::averaging::time_grid;
    let amplitude = f / (1.0 - omega * omega);
    time_grid(t_obs, 2.0 * std::f64::consts::PI / omega, 32, 2000)
        .iter()
        .map(|t| (amplitude * ((omega * t).cos() - t.cos())).abs())
        .fold(0.0, f64::max)
}

/// Each deviation's stated numerical error against the closed form, at
/// three tolerances of DOP853 and two of Taylor over four frequencies: it
/// bounds the distance in every case and is within 100 times it; and an
/// `accuracy` of 1e-10 is reached, the deviations then within it of the
/// closed form.
#[test]
fn the_deviations_stated_errors_bound_their_distance_to_the_closed_form() {
    let model = &mechlab_test_models::forced_oscillator::MODEL;
    let (f, omegas) = (0.1, [8.0, 16.0, 32.0, 64.0]);
    let params = [0.0, 0.0, f, 8.0];
    let mut ratios = Vec::new();
    for (name, tol) in [
        ("dop853", 1e-5),
        ("dop853", 1e-7),
        ("dop853", 1e-9),
        ("taylor", 1e-6),
        ("taylor", 1e-9),
    ] {
        let settings = ConvergenceSettings {
            check: true,
            method: Method::parse(name, tol).unwrap(),
            ..settings(Some("omega"), &omegas)
        };
        let result = convergence(model, &params, &settings).unwrap();
        for (k, &omega) in omegas.iter().enumerate() {
            let (deviation, error) = (result.max_deviation[0][k], result.deviation_error[0][k]);
            let distance = (deviation - oscillator_deviation(f, omega, 2.0)).abs();
            println!("{name} {tol:e}, ω = {omega}: {deviation:.10e} ± {error:.1e}, off by {distance:.1e}");
            assert!(distance <= error, "{name} {tol:e}, ω = {omega}");
            ratios.push(error / distance.max(1e-16));
        }
    }
    println!("stated over distance: {ratios:.1?}");
    assert!(ratios.iter().all(|&r| r <= 100.0), "{ratios:?}");
    let asked = ConvergenceSettings {
        accuracy: Some(1e-10),
        method: Method::parse("dop853", 1e-5).unwrap(),
        ..settings(Some("omega"), &omegas)
    };
    let result = convergence(model, &params, &asked).unwrap();
    let verdict = result.accuracy.clone().unwrap();
    println!("{verdict}");
    assert!(verdict.contains(" reached"), "{verdict}");
    for (k, &omega) in omegas.iter().enumerate() {
        let exact = oscillator_deviation(f, omega, 2.0);
        assert!(
            (result.max_deviation[0][k] - exact).abs() <= 1e-10,
            "ω = {omega}"
        );
    }
}
