//! The attractor of a forced, damped period map by model name: Ueda's
//! oscillator x'' + k x' + x³ = B cos t (k = 0.05, B = 7.5).

use mechlab::analysis::attractor::{attractor, AttractorError, AttractorSettings};
use mechlab::analysis::Refusal;
use mechlab::models;
use mechlab::ode::Method;

fn settings() -> AttractorSettings {
    AttractorSettings {
        method: Method::Taylor { tol: 1e-10 },
        start: [1.0, 0.0],
        transient: 300,
        points: 100_000,
        lyapunov_periods: 4_000,
        pixels: 100,
    }
}

/// The exponents sum to the flow's divergence, −k per unit time, which the
/// analysis measures from the Jacobian's trace along the orbit, not from
/// the tangent flow; the largest exponent is positive (chaos, about 0.10 per
/// unit time as published for Ueda's attractor), the two starts agree, and
/// the Kaplan–Yorke and box-counting dimensions (about 1.67) agree.
#[test]
fn ueda_spectrum_sums_to_the_divergence_and_the_dimensions_agree() {
    let model = models::by_name("ueda").unwrap();
    let a = attractor(model, &model.dynamic.defaults(), &settings()).unwrap();
    let k = 0.05;
    assert!(
        (a.divergence_per_period + k * a.period).abs() < 1e-9,
        "{}",
        a.divergence_per_period
    );
    assert!(
        (a.lyapunov_sum - a.divergence_per_period).abs() < 1e-8,
        "{} {}",
        a.lyapunov_sum,
        a.divergence_per_period
    );
    let lambda = a.lyapunov_per_time[0];
    assert!((0.08..0.12).contains(&lambda), "λ₁ = {lambda}");
    assert!(
        a.lyapunov_error[0] < 0.1 * a.lyapunov[0],
        "{:?}",
        a.lyapunov_error
    );
    assert!(
        (1.55..1.8).contains(&a.kaplan_yorke_dimension),
        "{}",
        a.kaplan_yorke_dimension
    );
    assert!(
        (a.box_dimension - a.kaplan_yorke_dimension).abs() < 0.15,
        "{} {}",
        a.box_dimension,
        a.kaplan_yorke_dimension
    );
}

/// Models it cannot draw get named errors: two degrees of freedom, no
/// periodic forcing, and settings too small to measure anything.
#[test]
fn models_without_a_planar_period_map_get_named_errors() {
    let double = models::by_name("double_pendulum").unwrap();
    assert!(matches!(
        attractor(double, &double.dynamic.defaults(), &settings()),
        Err(AttractorError::Refused(Refusal::Dimension { dof: 2, .. }))
    ));
    let ueda = models::by_name("ueda").unwrap();
    let none = AttractorSettings {
        points: 0,
        ..settings()
    };
    assert!(matches!(
        attractor(ueda, &ueda.dynamic.defaults(), &none),
        Err(AttractorError::Refused(Refusal::Setting { .. }))
    ));
}
