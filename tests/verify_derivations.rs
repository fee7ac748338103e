//! The generated code against independent closed forms and hand derivations.

use mechlab::models::{double_pendulum as dp, kapitza};
use mechlab::ode::{Integrator, Method, Options, System};

use crate::common::{close, Rng};

/// Study 1 (docs/studies.md) with our phase convention y = A ε cos θ, which gives the cross
/// term with a minus sign: H = p²/2 − A p sin q sin θ + (A²/2) sin²q sin²θ + cos q.
fn kapitza_h_closed_form(q: f64, p: f64, t: f64, a: f64, eps: f64) -> f64 {
    let th = t / eps;
    p * p / 2.0 - a * p * q.sin() * th.sin()
        + a * a / 2.0 * q.sin().powi(2) * th.sin().powi(2)
        + q.cos()
}

#[test]
fn kapitza_hamiltonian_matches_the_closed_form() {
    let mut rng = Rng(7);
    for _ in 0..200 {
        let params = kapitza::Params {
            A: 3.0 * rng.between(-1.0, 1.0),
            eps: 0.05 + rng.between(-1.0, 1.0).abs(),
            mu: rng.between(-1.0, 1.0).abs(),
        };
        let (q, p, t) = (
            4.0 * rng.between(-1.0, 1.0),
            3.0 * rng.between(-1.0, 1.0),
            10.0 * rng.between(-1.0, 1.0),
        );
        let h = kapitza::hamiltonian(t, &[q, p], &params);
        assert!(close(
            h,
            kapitza_h_closed_form(q, p, t, params.A, params.eps),
            1e-13
        ));
        let hbar = kapitza::averaged_hamiltonian(&[q, p], &params);
        let expected = p * p / 2.0 + q.cos() + params.A * params.A / 4.0 * q.sin().powi(2);
        assert!(
            close(hbar, expected, 1e-13),
            "H̄ = {hbar}, expected {expected}"
        );
        let v = kapitza::effective_potential(&[q], &params);
        assert!(close(
            v,
            q.cos() + params.A * params.A / 4.0 * q.sin().powi(2),
            1e-13
        ));
    }
}

#[test]
fn kapitza_equations_are_hamiltons_with_friction() {
    // q' = ∂H/∂p, p' = −∂H/∂q − μ ∂H/∂p, with H the closed form (central differences).
    let mut rng = Rng(11);
    let d = 1e-6;
    for _ in 0..100 {
        let params = kapitza::Params {
            A: 2.0 * rng.between(-1.0, 1.0),
            eps: 0.1 + rng.between(-1.0, 1.0).abs(),
            mu: rng.between(-1.0, 1.0).abs(),
        };
        let (q, p, t) = (
            4.0 * rng.between(-1.0, 1.0),
            2.0 * rng.between(-1.0, 1.0),
            5.0 * rng.between(-1.0, 1.0),
        );
        let h = |q: f64, p: f64| kapitza_h_closed_form(q, p, t, params.A, params.eps);
        let dh_dp = (h(q, p + d) - h(q, p - d)) / (2.0 * d);
        let dh_dq = (h(q + d, p) - h(q - d, p)) / (2.0 * d);
        let [qd, pd] = kapitza::exact_rhs(t, &[q, p], &params);
        assert!(close(qd, dh_dp, 1e-8));
        assert!(close(pd, -dh_dq - params.mu * dh_dp, 1e-8));
    }
}

fn check_jacobian<const N: usize>(
    f: &dyn Fn(&[f64; N]) -> [f64; N],
    jac: &[[f64; N]; N],
    y: &[f64; N],
) {
    let d = 1e-6;
    for k in 0..N {
        let mut plus = *y;
        let mut minus = *y;
        plus[k] += d;
        minus[k] -= d;
        let (fp, fm) = (f(&plus), f(&minus));
        for i in 0..N {
            let numeric = (fp[i] - fm[i]) / (2.0 * d);
            assert!(
                close(jac[i][k], numeric, 1e-6),
                "J[{i}][{k}] = {} vs {numeric}",
                jac[i][k]
            );
        }
    }
}

#[test]
fn jacobians_match_finite_differences() {
    let mut rng = Rng(3);
    for _ in 0..50 {
        let kp = kapitza::Params {
            A: 2.0 * rng.between(-1.0, 1.0),
            eps: 0.2,
            mu: rng.between(-1.0, 1.0).abs(),
        };
        let t = rng.between(-1.0, 1.0);
        let y = [3.0 * rng.between(-1.0, 1.0), rng.between(-1.0, 1.0)];
        check_jacobian(
            &|y| kapitza::exact_rhs(t, y, &kp),
            &kapitza::exact_jacobian(t, y.as_ref().try_into().unwrap(), &kp),
            &y,
        );
        check_jacobian(
            &|y| kapitza::averaged_rhs(y, &kp),
            &kapitza::averaged_jacobian(&y, &kp),
            &y,
        );
        let pp = dp::Params {
            a: 3.0,
            nu: 10.0,
            mu: 0.3,
            m1: 1.3,
            m2: 0.7,
            l1: 0.9,
            l2: 1.2,
            ..Default::default()
        };
        let y = [
            3.0 * rng.between(-1.0, 1.0),
            3.0 * rng.between(-1.0, 1.0),
            rng.between(-1.0, 1.0),
            rng.between(-1.0, 1.0),
        ];
        check_jacobian(
            &|y| dp::exact_rhs(t, y, &pp),
            &dp::exact_jacobian(t, &y, &pp),
            &y,
        );
        check_jacobian(
            &|y| dp::averaged_rhs(y, &pp),
            &dp::averaged_jacobian(&y, &pp),
            &y,
        );
    }
}

/// Accelerations of the double pendulum on a base with vertical acceleration
/// ẅ, derived by hand in the base frame (effective gravity g + ẅ, angles from
/// the upward vertical, friction Q1 = −μ φ1', Q2 = −μ(φ2' − φ1')).
fn double_pendulum_accelerations(phi: [f64; 2], w: [f64; 2], t: f64, p: &dp::Params) -> [f64; 2] {
    let wdd = -p.a * p.nu * (p.nu * t).cos();
    let g = p.g + wdd;
    let (s12, c12) = (phi[0] - phi[1]).sin_cos();
    let m11 = (p.m1 + p.m2) * p.l1 * p.l1;
    let m12 = p.m2 * p.l1 * p.l2 * c12;
    let m22 = p.m2 * p.l2 * p.l2;
    let q1 = -p.mu * w[0];
    let q2 = -p.mu * (w[1] - w[0]);
    let r1 = q1 - p.m2 * p.l1 * p.l2 * s12 * w[1] * w[1] + g * (p.m1 + p.m2) * p.l1 * phi[0].sin();
    let r2 = q2 + p.m2 * p.l1 * p.l2 * s12 * w[0] * w[0] + g * p.m2 * p.l2 * phi[1].sin();
    let det = m11 * m22 - m12 * m12;
    [(m22 * r1 - m12 * r2) / det, (m11 * r2 - m12 * r1) / det]
}

#[test]
fn double_pendulum_equations_match_a_hand_derivation() {
    let mut rng = Rng(5);
    for _ in 0..100 {
        let params = dp::Params {
            m1: 1.0 + rng.between(-1.0, 1.0).abs(),
            m2: 0.5 + rng.between(-1.0, 1.0).abs(),
            l1: 0.5 + rng.between(-1.0, 1.0).abs(),
            l2: 0.5 + rng.between(-1.0, 1.0).abs(),
            g: 9.81,
            a: 2.0 * rng.between(-1.0, 1.0).abs(),
            nu: 5.0 + 20.0 * rng.between(-1.0, 1.0).abs(),
            mu: rng.between(-1.0, 1.0).abs(),
        };
        let t = 3.0 * rng.between(-1.0, 1.0);
        let phi = [3.0 * rng.between(-1.0, 1.0), 3.0 * rng.between(-1.0, 1.0)];
        let w = [2.0 * rng.between(-1.0, 1.0), 2.0 * rng.between(-1.0, 1.0)];
        // State from the generated momenta, then accelerations by the chain rule:
        // q'' = ∂v/∂t + ∂v/∂q q' + ∂v/∂p p'.
        let p = dp::momenta(t, &phi, &w, &params);
        let y = [phi[0], phi[1], p[0], p[1]];
        let v = dp::velocities(t, &y, &params);
        assert!(close(v[0], w[0], 1e-12) && close(v[1], w[1], 1e-12));
        let f = dp::exact_rhs(t, &y, &params);
        let j = dp::exact_jacobian(t, &y, &params);
        let d = 1e-6;
        let (vp, vm) = (
            dp::velocities(t + d, &y, &params),
            dp::velocities(t - d, &y, &params),
        );
        let expected = double_pendulum_accelerations(phi, w, t, &params);
        for i in 0..2 {
            let dv_dt = (vp[i] - vm[i]) / (2.0 * d);
            let acceleration = dv_dt + (0..4).map(|k| j[i][k] * f[k]).sum::<f64>();
            assert!(
                close(acceleration, expected[i], 1e-6),
                "φ{}'' = {acceleration}, by hand {}",
                i + 1,
                expected[i]
            );
        }
    }
}

#[test]
fn double_pendulum_vibrational_potential_matches_the_closed_form() {
    // V_vibr = (a²/4) sᵀ A⁻¹ s, s = ((m1 + m2) l1 sin φ1, m2 l2 sin φ2).
    let mut rng = Rng(9);
    for _ in 0..100 {
        let p = dp::Params {
            m1: 1.0 + rng.between(-1.0, 1.0).abs(),
            m2: 0.5 + rng.between(-1.0, 1.0).abs(),
            l1: 0.5 + rng.between(-1.0, 1.0).abs(),
            l2: 0.5 + rng.between(-1.0, 1.0).abs(),
            a: 3.0 * rng.between(-1.0, 1.0),
            ..Default::default()
        };
        let phi = [3.0 * rng.between(-1.0, 1.0), 3.0 * rng.between(-1.0, 1.0)];
        let s = [
            (p.m1 + p.m2) * p.l1 * phi[0].sin(),
            p.m2 * p.l2 * phi[1].sin(),
        ];
        let m11 = (p.m1 + p.m2) * p.l1 * p.l1;
        let m12 = p.m2 * p.l1 * p.l2 * (phi[0] - phi[1]).cos();
        let m22 = p.m2 * p.l2 * p.l2;
        let det = m11 * m22 - m12 * m12;
        let quadratic = (m22 * s[0] * s[0] - 2.0 * m12 * s[0] * s[1] + m11 * s[1] * s[1]) / det;
        let expected = p.a * p.a / 4.0 * quadratic;
        assert!(close(dp::vibrational_potential(&phi, &p), expected, 1e-12));
        let mass = dp::mass_matrix(&phi, &p);
        assert!(
            close(mass[0][0], m11, 1e-13)
                && close(mass[0][1], m12, 1e-13)
                && close(mass[1][1], m22, 1e-13)
        );
        let v = p.g * ((p.m1 + p.m2) * p.l1 * phi[0].cos() + p.m2 * p.l2 * phi[1].cos());
        assert!(close(dp::potential(&phi, &p), v, 1e-13));
    }
}

#[test]
fn averaged_double_pendulum_conserves_its_hamiltonian() {
    let params = dp::Params {
        a: 3.0,
        mu: 0.0,
        ..Default::default()
    };
    let system = dp::Averaged { params };
    let y0 = [0.3, -0.4, 0.2, 0.1];
    let h0 = dp::averaged_hamiltonian(&y0, &params);
    let mut integrator = Integrator::new(Method::Dop853 {
        rtol: 1e-12,
        atol: 1e-12,
    })
    .unwrap();
    let mut worst = 0.0f64;
    let y = integrator
        .solve(
            &system,
            0.0,
            &y0,
            200.0,
            Options::default().observe(&mut |_, y| {
                worst = worst.max((dp::averaged_hamiltonian(y, &params) - h0).abs());
            }),
        )
        .unwrap()
        .y;
    assert!(worst < 1e-9, "H̄ drifted by {worst}");
    assert!(y != y0);
}

/// Max over t ∈ [0, t_end] of |φ_exact − φ_averaged| from the same (q, p).
fn averaging_deviation(nu: f64) -> f64 {
    let params = dp::Params {
        a: 2.0,
        nu,
        ..Default::default()
    };
    let exact = dp::Exact { params };
    let averaged = dp::Averaged { params };
    let y0 = [2.8, 3.3, 0.0, 0.0];
    let method = Method::Dop853 {
        rtol: 1e-11,
        atol: 1e-11,
    };
    let (mut a, mut b) = (
        Integrator::new(method).unwrap(),
        Integrator::new(method).unwrap(),
    );
    let (mut ya, mut yb) = (y0, y0);
    let mut deviation = 0.0f64;
    let samples = 400;
    let t_end = 3.0;
    for i in 0..samples {
        let (t0, t1) = (
            t_end * i as f64 / samples as f64,
            t_end * (i + 1) as f64 / samples as f64,
        );
        ya = a.advance(&exact, t0, &ya, t1).unwrap();
        yb = b.advance(&averaged, t0, &yb, t1).unwrap();
        deviation = deviation
            .max((ya[0] - yb[0]).abs())
            .max((ya[1] - yb[1]).abs());
    }
    deviation
}

#[test]
fn exact_solution_approaches_the_averaged_one_like_one_over_nu() {
    let nus = [100.0, 200.0, 400.0, 800.0];
    let deviations: Vec<f64> = nus.iter().map(|&nu| averaging_deviation(nu)).collect();
    for w in deviations.windows(2) {
        let ratio = w[0] / w[1];
        assert!(
            (1.6..2.5).contains(&ratio),
            "deviation ratio per doubling of ν = {ratio} ({deviations:?})"
        );
    }
    assert!(deviations[3] < 0.05, "{deviations:?}");
}

/// The generated Kapitza field against the one derived by hand from the
/// model file: x = sin q, y = Aε cos θ + cos q, θ = t/ε, L = (ẋ² + ẏ²)/2 − y
/// give p = q̇ + A sin θ sin q and ṗ = A sin θ cos q q̇ + sin q − μ q̇; the
/// averaged system (μ = 0) is H̄ = p²/2 + cos q + (A²/4) sin²q, whose
/// Jacobian is [[0, 1], [cos q − (A²/2) cos 2q, 0]]. Through the `System`
/// trait and the free functions alike, at several states and phases.
#[test]
fn the_generated_kapitza_field_is_the_hand_derived_one() {
    let (a, eps, mu) = (1.3, 0.07, 0.2);
    let params = kapitza::Params { A: a, eps, mu };
    let states: [(f64, f64, f64); 3] = [(0.7, 0.3, -0.2), (0.013, 2.9, 1.4), (1.9, -1.2, 0.05)];
    for (t, q, p) in states {
        let theta = t / eps;
        let qd = p - a * theta.sin() * q.sin();
        let expected = [qd, a * theta.sin() * q.cos() * qd + q.sin() - mu * qd];
        for got in [
            kapitza::Exact { params }.rhs(t, &[q, p]),
            kapitza::exact_rhs(t, &[q, p], &params),
        ] {
            for (g, e) in got.iter().zip(expected) {
                assert!(
                    (g - e).abs() < 1e-14,
                    "t = {t}, q = {q}: {got:?} against {expected:?}"
                );
            }
        }
        let still = kapitza::Params { mu: 0.0, ..params };
        let jacobian = [[0.0, 1.0], [q.cos() - a * a / 2.0 * (2.0 * q).cos(), 0.0]];
        let got = kapitza::Averaged { params: still }
            .jacobian(0.0, &[q, p])
            .unwrap();
        for (g, e) in got.iter().flatten().zip(jacobian.iter().flatten()) {
            assert!(
                (g - e).abs() < 1e-14,
                "q = {q}: {got:?} against {jacobian:?}"
            );
        }
    }
}

#[test]
fn parameters_by_name() {
    let mut p = kapitza::Params::default();
    p.set("A", 2.5).unwrap();
    assert_eq!(p.A, 2.5);
    assert_eq!(p.get("eps"), Some(0.1));
    let e = p.set("B", 1.0).unwrap_err().to_string();
    assert!(
        e.contains("no parameter 'B'") && e.contains("A, eps, mu"),
        "{e}"
    );
    assert!(p
        .set("mu", f64::NAN)
        .unwrap_err()
        .to_string()
        .contains("must be finite"));
}

/// The bead on a vertical circular wire written in its horizontal
/// coordinate x (`test_models/bead_on_circle.toml`: height −√(R² − x²),
/// real only for |x| ≤ R) is the pendulum in another chart, x = R sin θ:
/// from rest at x₀ = R/2 (θ₀ = π/6) it passes the bottom after a quarter
/// period K(k)√(R/g), k = sin(θ₀/2), with p_x = −m √(2gR(1 − cos θ₀)),
/// and is back at x₀ after the period. The model's build samples it
/// where it is defined; the run never leaves |x| ≤ x₀.
#[test]
fn the_bead_on_a_circle_in_its_cartesian_chart_is_the_pendulum() {
    use crate::common::agm;
    let model = &mechlab_test_models::bead_on_circle::MODEL;
    let (radius, mass, g) = (2.0, 0.5, 3.0);
    let system = model.systems().unwrap().exact(&[radius, mass, g]);
    let theta0 = std::f64::consts::FRAC_PI_6;
    let k = (theta0 / 2.0).sin();
    let quarter =
        std::f64::consts::FRAC_PI_2 / agm(1.0, (1.0 - k * k).sqrt()) * (radius / g).sqrt();
    let start = [radius * theta0.sin(), 0.0];
    for method in [
        Method::Taylor { tol: 1e-15 },
        Method::Dop853 {
            rtol: 1e-13,
            atol: 1e-13,
        },
    ] {
        let states = system
            .states_at(
                method,
                0.0,
                &start,
                &[quarter, 2.0 * quarter, 4.0 * quarter],
            )
            .unwrap();
        let bottom = -mass * (2.0 * g * radius * (1.0 - theta0.cos())).sqrt();
        let name = method.name();
        assert!(
            states[0][0].abs() < 1e-10,
            "{name}: x at a quarter period {:e}",
            states[0][0]
        );
        assert!(
            (states[0][1] - bottom).abs() < 1e-10,
            "{name}: p_x at the bottom {} against {bottom}",
            states[0][1]
        );
        assert!(
            (states[1][0] + start[0]).abs() < 1e-10,
            "{name}: x at half a period {}",
            states[1][0]
        );
        assert!(
            (states[2][0] - start[0]).abs() < 1e-10 && states[2][1].abs() < 1e-10,
            "{name}: after the period {:?}",
            states[2]
        );
    }
}
