//! The studies' runs (what the scenes call), against laws they must obey.

use mechlab::models::double_pendulum as dp;
use mechlab::models::kapitza::Params;
use mechlab::ode::Method;
use mechlab::registry::ParameterError;
use mechlab::studies::kapitza::{
    attractor, single_orbit, upper_position, AttractorSettings, UpperPositionSettings,
};
use mechlab::studies::{double_pendulum, StudyError};
use std::f64::consts::{PI, SQRT_2};

fn dop853(tol: f64) -> Method {
    Method::parse("dop853", tol).unwrap()
}

/// Liouville: the Lyapunov exponents per period of the dissipative map sum
/// to ln det M = −μT.
#[test]
fn attractor_exponents_sum_to_the_contraction() {
    let params = Params {
        A: 1.5,
        eps: 0.7,
        mu: 0.4,
    };
    let result = attractor(&AttractorSettings {
        params,
        points: 2000,
        transient: 200,
        lyapunov_periods: 2000,
        zoom: 8.0,
        method: dop853(1e-10),
    })
    .unwrap();
    let expected = -0.4 * 2.0 * PI * 0.7;
    assert!(
        (result.lyapunov_sum - expected).abs() < 1e-6,
        "{} vs {expected}",
        result.lyapunov_sum
    );
    assert!(result.box_sides.len() == result.boxes.len());
}

/// Without vibration and friction the period map conserves the pendulum's
/// energy p²/2 + cos q (upward q = 0).
#[test]
fn single_orbit_without_vibration_conserves_energy() {
    let params = Params {
        A: 0.0,
        eps: 0.1,
        mu: 0.0,
    };
    let result = single_orbit(params, [2.0, 0.3], 300, Method::Taylor { tol: 1e-13 }, 1).unwrap();
    let energy = |y: &[f64; 2]| 0.5 * y[1] * y[1] + y[0].cos();
    let e0 = energy(&result.points[0]);
    let worst = result
        .points
        .iter()
        .map(|y| (energy(y) - e0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-10, "energy drift {worst}");
    assert_eq!(result.points.len(), 301);
    assert_eq!(result.final_state, result.points[300]);
}

/// det M = exp(−μT) (Liouville), and A*(ε) − √2 ≈ 0.62 ε² for small ε.
#[test]
fn upper_position_obeys_liouville_and_the_averaged_threshold() {
    let params = Params {
        A: 1.6,
        eps: 0.1,
        mu: 0.05,
    };
    let result = upper_position(&UpperPositionSettings {
        params,
        periods: 20,
        chart_eps: 2,
        chart_a: 12,
        chart_a_max: 4.0,
        method: dop853(1e-12),
    })
    .unwrap();
    assert!((result.determinant - result.determinant_expected).abs() < 1e-9);
    let small = result.a_star_by_eps.iter().find(|s| s.eps == 0.05).unwrap();
    let a_star = small.a_star.unwrap();
    let coefficient = (a_star - SQRT_2) / (0.05f64 * 0.05);
    assert!(
        (coefficient - 0.62).abs() < 0.05,
        "A* − √2 = {coefficient} ε²"
    );
}

/// With friction the exact spectral radius at large ν approaches the
/// averaged eigenvalues' prediction exp(max Re λ · 2π/ν).
#[test]
fn friction_multipliers_follow_the_averaged_eigenvalues() {
    let result = double_pendulum::friction(&double_pendulum::FrictionSettings {
        params: dp::Params {
            mu: 0.3,
            a: 5.0,
            ..Default::default()
        },
        equilibrium: (0.0, 0.0),
        offset: 0.1,
        t_end: 5.0,
        nus: vec![400.0],
        method: dop853(1e-11),
    })
    .unwrap();
    assert!(result.max_real_part < 0.0);
    let r = &result.exact[0];
    assert!(
        (r.spectral_radius - r.predicted).abs() < 1e-6,
        "{} vs {}",
        r.spectral_radius,
        r.predicted
    );
}

#[test]
fn bad_parameters_are_typed_errors() {
    let params = Params {
        A: 1.0,
        eps: 0.0,
        mu: 0.0,
    };
    let error = single_orbit(params, [0.1, 0.0], 10, dop853(1e-8), 1).unwrap_err();
    assert!(
        matches!(&error, StudyError::Parameter(ParameterError::OutOfRange { name, .. }) if name == "eps"),
        "{error}"
    );
    let negative = Params {
        A: -1.0,
        eps: 0.1,
        mu: 0.0,
    };
    let error = single_orbit(negative, [0.1, 0.0], 10, dop853(1e-8), 1).unwrap_err();
    assert!(
        matches!(error, StudyError::Settings { setting: "A", .. }),
        "{error}"
    );
}

/// The upper position's verdict at a fast vibration (ε = 10⁻⁴) is right on
/// either side of the exact edge (1.4142135686, the Mathieu series), 5·10⁻⁹
/// below it unstable and above it stable. A verdict on the multipliers'
/// distance from the unit circle (1e-7) called both stable: below the edge
/// the multiplier is 1 + 5·10⁻⁸.
#[test]
fn the_upper_positions_verdict_is_right_on_both_sides_of_a_fast_vibrations_edge() {
    let verdict = |a: f64| {
        upper_position(&UpperPositionSettings {
            params: Params {
                A: a,
                eps: 1e-4,
                mu: 0.0,
            },
            periods: 2,
            chart_eps: 2,
            chart_a: 2,
            chart_a_max: 2.0,
            method: dop853(1e-12),
        })
        .unwrap()
        .verdict
    };
    assert_eq!(verdict(1.4142135636), "unstable");
    assert_eq!(verdict(1.4142135736), "stable");
}
