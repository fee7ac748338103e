//! Constrained model files (`[[constraints]]`), derived at build time and
//! run on their constraints (`mechlab::constrained`), against independent
//! forms: Kapitza's pendulum written as a point on a rod whose pivot
//! vibrates equals the angle model, and its multiplier is the rod's force
//! computed by hand in the pivot's accelerating frame.

use mechlab::constrained::{run, ConstrainedSystems};
use mechlab::models::kapitza;
use mechlab::ode::{states_at, Method};
use mechlab_test_models::cartesian_kapitza;

const TIGHT: Method = Method::Dop853 {
    rtol: 1e-13,
    atol: 1e-13,
};

/// The pivot's height, velocity and acceleration at t (Kapitza's model:
/// y_p = A ε cos(t/ε)).
fn pivot(a: f64, eps: f64, t: f64) -> (f64, f64, f64) {
    let theta = t / eps;
    (
        a * eps * theta.cos(),
        -a * theta.sin(),
        -a / eps * theta.cos(),
    )
}

#[test]
fn a_point_on_a_vibrating_rod_moves_as_kapitzas_pendulum() {
    // Near the upright held by the vibration, and swinging below the pivot
    // without it (regular orbits: a chaotic one would part two runs' round-off).
    for (a, mu, q0) in [(1.5, 0.0, 0.1), (1.5, 0.2, 0.1), (0.0, 0.0, 2.5)] {
        let (eps, qd0) = (0.1, 0.05);
        let kapitza = kapitza::Exact {
            params: kapitza::Params { A: a, eps, mu },
        };
        let times: Vec<f64> = (0..=60).map(|k| 0.5 * k as f64).collect();
        let angles = states_at(TIGHT, &kapitza, 0.0, &[q0, qd0], &times).unwrap();
        // The same start in Cartesian coordinates (the pivot is at rest at t = 0).
        let y0 = [
            q0.sin(),
            a * eps + q0.cos(),
            q0.cos() * qd0,
            -q0.sin() * qd0,
        ];
        let model = &cartesian_kapitza::SYSTEMS;
        let params = [a, eps, mu];
        let points = run(model, &params, Some(&y0), TIGHT, &times).unwrap();
        let mut worst: f64 = 0.0;
        for ((t, angle), point) in times.iter().zip(&angles).zip(&points.states) {
            let (yp, vp, ap) = pivot(a, eps, *t);
            let q = point[0].atan2(point[1] - yp);
            let dq = (q - angle[0] + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            worst = worst.max(dq.abs());
            // The rod's force on the bob, N = 2λ (x, y − y_p) for the
            // constraint x² + (y − y_p)² − 1: along the rod, Newton in the
            // pivot's frame gives N·e = (1 + ÿ_p) cos q − q'².
            let qd = angle[1] + vp * angle[0].sin();
            let lambda = model.reactions(&params, *t, point).unwrap()[0];
            let by_hand = 0.5 * ((1.0 + ap) * angle[0].cos() - qd * qd);
            assert!(
                (lambda - by_hand).abs() < 1e-8 * (1.0 + by_hand.abs()),
                "A = {a}, t = {t}: λ = {lambda}, by hand {by_hand}"
            );
        }
        assert!(worst < 1e-10, "A = {a}, μ = {mu}: angles differ by {worst:e}");
        assert!(points.largest_residual.0 < 1e-13 && points.largest_residual.1 < 1e-13);
    }
}

/// The upright pendulum on the vibrating pivot is a periodic orbit of both
/// forms; the monodromy restricted to the constraints' tangent space has
/// the angle model's multipliers (its trace and determinant), and the full
/// 4 × 4 one has two more, spurious, at 1.
#[test]
fn floquet_multipliers_on_the_constraints_are_the_angle_models() {
    for (a, mu) in [(1.5, 0.0), (1.2, 0.1), (2.0, 0.0)] {
        let eps = 0.1;
        let period = std::f64::consts::TAU * eps;
        let params = [a, eps, mu];
        let mut integrator = mechlab::ode::Integrator::new(TIGHT).unwrap();
        let angle = kapitza::MODEL.systems().unwrap();
        let (_, m) = angle
            .monodromy(&params, &mut integrator, period, &[0.0, 0.0])
            .unwrap();
        let y0 = [0.0, a * eps + 1.0, 0.0, 0.0];
        let model = &cartesian_kapitza::SYSTEMS;
        let (end, restricted) =
            mechlab::constrained::monodromy_on_constraints(model, &params, TIGHT, period, &y0)
                .unwrap();
        assert_eq!(restricted.shape(), (2, 2));
        assert!((end[1] - y0[1]).abs() < 1e-12, "the orbit closes");
        let close = |x: f64, y: f64| (x - y).abs() < 1e-10 * (1.0 + y.abs());
        assert!(
            close(restricted.trace(), m.trace()),
            "A = {a}: trace {} against {}",
            restricted.trace(),
            m.trace()
        );
        assert!(close(restricted.determinant(), m.determinant()));
        // The damping fixes the determinant: e^{−μT}.
        assert!(close(m.determinant(), (-mu * period).exp()));
        let mut integrator = mechlab::ode::Integrator::new(TIGHT).unwrap();
        let (_, full) = model
            .monodromy(&params, &mut integrator, period, &y0)
            .unwrap();
        let ones = full
            .complex_eigenvalues()
            .iter()
            .filter(|z| (z.re - 1.0).abs() < 1e-6 && z.im.abs() < 1e-6)
            .count();
        assert!(ones >= 2, "A = {a}: {:?}", full.complex_eigenvalues());
    }
}
