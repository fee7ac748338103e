//! Fractal dimensions against sets whose dimension is known.

use mechlab::analysis::dimension::{box_counting, kaplan_yorke_dimension};

fn sides() -> Vec<f64> {
    (2..=8).map(|k| 0.5f64.powi(k)).collect()
}

#[test]
fn a_curve_has_dimension_one_and_a_filled_square_two() {
    let curve: Vec<[f64; 2]> = (0..100_000)
        .map(|i| {
            let s = i as f64 / 100_000.0;
            [s, (3.0 * s).sin()]
        })
        .collect();
    let d = box_counting(&curve, &sides(), 1..6).dimension;
    assert!((d - 1.0).abs() < 0.05, "curve: {d}");
    let square: Vec<[f64; 2]> = (0..300 * 300)
        .map(|k| [(k % 300) as f64 / 300.0, (k / 300) as f64 / 300.0])
        .collect();
    let d = box_counting(&square, &sides(), 1..6).dimension;
    assert!((d - 2.0).abs() < 0.05, "square: {d}");
}

#[test]
fn the_henon_attractor_has_its_known_dimension() {
    // Hénon map (a = 1.4, b = 0.3): box-counting dimension ≈ 1.26, and its
    // exponents 0.419, −1.623 (sum ln 0.3) give a Kaplan–Yorke dimension ≈ 1.26.
    let (mut x, mut y) = (0.1, 0.1);
    let mut points = Vec::with_capacity(100_000);
    for n in 0..101_000 {
        (x, y) = (1.0 - 1.4 * x * x + y, 0.3 * x);
        if n >= 1000 {
            points.push([x, y]);
        }
    }
    let d = box_counting(&points, &sides(), 1..6).dimension;
    assert!((d - 1.26).abs() < 0.08, "Hénon box counting: {d}");
    let ky = kaplan_yorke_dimension(&[0.419, 0.3f64.ln() - 0.419]);
    assert!((ky - 1.258).abs() < 0.005, "Kaplan–Yorke: {ky}");
    // A stable fixed point (both exponents negative) has dimension 0.
    assert_eq!(kaplan_yorke_dimension(&[-0.1, -0.3]), 0.0);
}

#[test]
fn the_documented_kapitza_attractor_is_strange() {
    // The parameters of the kapitza_attractor scene: a positive exponent, the
    // sum fixed by the friction, a fractional dimension between 1 and 2.
    use mechlab::analysis::lyapunov::lyapunov_spectrum;
    use mechlab::models::kapitza;
    use mechlab::ode::{Integrator, Method};
    let params = kapitza::Params {
        A: 1.5,
        eps: 0.7,
        mu: 0.4,
    };
    let period = std::f64::consts::TAU * params.eps;
    let mut integrator = Integrator::new(Method::parse("dop853", 1e-9).unwrap()).unwrap();
    let (exponents, _) = lyapunov_spectrum::<_, 2, 6>(
        &mut integrator,
        &kapitza::Exact { params },
        period,
        &[1.0, 0.3],
        300,
        3000,
        &[true, false],
    )
    .unwrap();
    assert!(exponents[0] > 0.5, "{exponents:?}");
    let sum = exponents[0] + exponents[1];
    assert!((sum + params.mu * period).abs() < 1e-6, "sum {sum}");
    let d = kaplan_yorke_dimension(&exponents);
    assert!(d > 1.2 && d < 1.5, "Kaplan–Yorke dimension {d}");
}
