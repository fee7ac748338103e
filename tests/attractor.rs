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
        accuracy: None,
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

/// Ueda's largest Lyapunov exponent per period, written out independently
/// of mechlab: x'' + k x' + x³ = B cos t and its tangent flow by classical
/// RK4 at 256 steps a period, the two tangent vectors Gram–Schmidt
/// orthonormalised after each period, over `periods` periods after 500
/// dropped, from (x, x') = (1, 0).
fn ueda_largest_exponent_by_hand(periods: usize) -> f64 {
    let (k, b) = (0.05, 7.5);
    let steps = 256;
    let h = std::f64::consts::TAU / steps as f64;
    // (x, v, δx₁, δv₁, δx₂, δv₂)
    let f = |t: f64, z: &[f64; 6]| {
        let stiffness = 3.0 * z[0] * z[0];
        [
            z[1],
            -k * z[1] - z[0].powi(3) + b * t.cos(),
            z[3],
            -k * z[3] - stiffness * z[2],
            z[5],
            -k * z[5] - stiffness * z[4],
        ]
    };
    let mut z = [1.0, 0.0, 1.0, 0.0, 0.0, 1.0];
    let mut sum = 0.0;
    for period in 0..500 + periods {
        for s in 0..steps {
            let t = s as f64 * h;
            let step =
                |z: &[f64; 6], d: &[f64; 6], c: f64| std::array::from_fn(|i| z[i] + c * d[i]);
            let k1 = f(t, &z);
            let k2 = f(t + h / 2.0, &step(&z, &k1, h / 2.0));
            let k3 = f(t + h / 2.0, &step(&z, &k2, h / 2.0));
            let k4 = f(t + h, &step(&z, &k3, h));
            z = std::array::from_fn(|i| {
                z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        let norm = z[2].hypot(z[3]);
        let (u1, u2) = (z[2] / norm, z[3] / norm);
        let along = z[4] * u1 + z[5] * u2;
        let (w1, w2) = (z[4] - along * u1, z[5] - along * u2);
        let w = w1.hypot(w2);
        (z[2], z[3], z[4], z[5]) = (u1, u2, w1 / w, w2 / w);
        if period >= 500 {
            sum += norm.ln();
        }
    }
    sum / periods as f64
}

/// The exponents' stated error is a statistical bound that holds: twenty
/// runs of 2,000 periods from twenty starts on Ueda's attractor, each
/// against the largest exponent of 200,000 periods written out by hand
/// (whose own statistical error is a tenth of theirs). At least 19 of the
/// 20 stated errors bound the distance, and they are not loose: their
/// median is under 20 times the median distance.
#[test]
fn the_lyapunov_exponents_stated_error_bounds_their_distance_to_a_long_independent_run() {
    let model = models::by_name("ueda").unwrap();
    let reference = ueda_largest_exponent_by_hand(200_000);
    let (mut bounded, mut stated, mut distances) = (0, Vec::new(), Vec::new());
    for j in 0..20 {
        let short = AttractorSettings {
            start: [1.0 + 0.1 * j as f64, 0.0],
            transient: 200,
            points: 100,
            lyapunov_periods: 2_000,
            pixels: 10,
            ..settings()
        };
        let a = attractor(model, &model.dynamic.defaults(), &short).unwrap();
        let distance = (a.lyapunov[0] - reference).abs();
        bounded += usize::from(distance <= a.lyapunov_error[0]);
        stated.push(a.lyapunov_error[0]);
        distances.push(distance);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (stated_median, distance_median) = (median(&mut stated), median(&mut distances));
    eprintln!("{bounded} of 20 bounded; median stated {stated_median:.2e}, median distance {distance_median:.2e}; λ₁ = {reference}");
    assert!(
        bounded >= 19,
        "{bounded} of 20 bounded: stated {stated:?}, distances {distances:?}, λ₁ = {reference}"
    );
    assert!(
        stated_median < 20.0 * distance_median,
        "stated {stated_median:.2e} against distances {distance_median:.2e}"
    );
}

/// An accuracy asked of the exponents lengthens the runs until the stated
/// error is within it, and the exponent is then as close as that to the
/// long independent run.
#[test]
fn an_attractor_asked_for_an_accuracy_lengthens_its_runs_until_the_error_is_within_it() {
    let model = models::by_name("ueda").unwrap();
    let asked = AttractorSettings {
        transient: 200,
        points: 100,
        lyapunov_periods: 1_000,
        accuracy: Some(0.01),
        pixels: 10,
        ..settings()
    };
    let a = attractor(model, &model.dynamic.defaults(), &asked).unwrap();
    let said = a.accuracy.clone().unwrap();
    assert!(said.contains("accuracy 1e-2 reached"), "{said}");
    assert!(a.lyapunov_periods > 1_000, "{}", a.lyapunov_periods);
    assert!(
        a.lyapunov_error.iter().all(|e| *e <= 0.01),
        "{:?}",
        a.lyapunov_error
    );
    let reference = ueda_largest_exponent_by_hand(200_000);
    assert!(
        (a.lyapunov[0] - reference).abs() <= 0.01,
        "{} against {reference}",
        a.lyapunov[0]
    );
}
