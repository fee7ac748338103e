//! The numeric-solve form of the generated code (models of 3 or more
//! degrees of freedom, or `inverse = "numeric"`): A(q) q' = p − b solved by
//! Cholesky at run time, Jacobians and the Hessian of V + V_vibr by forward
//! mode through the solve, and the Taylor recurrence of the solve.
//!
//! Checked against the symbolic-inverse form of the same double pendulum,
//! against finite differences of the generated Hamiltonians, against
//! DOP853, and the N-link chains' thresholds against the closed form from
//! their normal modes.

use mechlab::analysis::floquet::monodromy;
use mechlab::models::{double_pendulum, quadruple_pendulum, triple_pendulum};
use mechlab::ode::{Integrator, Method, System};
use mechlab::test_models::double_pendulum_numeric;
use nalgebra::DMatrix;
use std::f64::consts::PI;

struct Rng(u64);
impl Rng {
    fn between(&mut self, a: f64, b: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        a + (b - a) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

fn close(what: &str, a: f64, b: f64, tol: f64) {
    assert!(
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs())),
        "{what}: {a} vs {b}"
    );
}

#[test]
fn numeric_and_symbolic_forms_agree_on_the_double_pendulum() {
    let mut rng = Rng(0x853c_49e6_748f_ea9b);
    for _ in 0..200 {
        let symbolic = double_pendulum::Params {
            m1: rng.between(0.5, 2.0),
            m2: rng.between(0.5, 2.0),
            l1: rng.between(0.5, 2.0),
            l2: rng.between(0.5, 2.0),
            g: rng.between(0.5, 2.0),
            a: rng.between(0.0, 6.0),
            nu: rng.between(10.0, 200.0),
            mu: rng.between(0.0, 0.5),
        };
        let numeric = double_pendulum_numeric::Params::from_values(&symbolic.values());
        let t = rng.between(0.0, 3.0);
        let y: [f64; 4] = std::array::from_fn(|_| rng.between(-3.0, 3.0));
        let q = [y[0], y[1]];
        let pairs = [
            (
                double_pendulum::exact_rhs(t, &y, &symbolic).to_vec(),
                double_pendulum_numeric::exact_rhs(t, &y, &numeric).to_vec(),
                "exact_rhs",
            ),
            (
                double_pendulum::averaged_rhs(&y, &symbolic).to_vec(),
                double_pendulum_numeric::averaged_rhs(&y, &numeric).to_vec(),
                "averaged_rhs",
            ),
            (
                double_pendulum::velocities(t, &y, &symbolic).to_vec(),
                double_pendulum_numeric::velocities(t, &y, &numeric).to_vec(),
                "velocities",
            ),
            (
                flat(&double_pendulum::exact_jacobian(t, &y, &symbolic)),
                flat(&double_pendulum_numeric::exact_jacobian(t, &y, &numeric)),
                "exact_jacobian",
            ),
            (
                flat(&double_pendulum::averaged_jacobian(&y, &symbolic)),
                flat(&double_pendulum_numeric::averaged_jacobian(&y, &numeric)),
                "averaged_jacobian",
            ),
            (
                flat(&double_pendulum::effective_potential_hessian(&q, &symbolic)),
                flat(&double_pendulum_numeric::effective_potential_hessian(
                    &q, &numeric,
                )),
                "effective_potential_hessian",
            ),
            (
                vec![double_pendulum::hamiltonian(t, &y, &symbolic)],
                vec![double_pendulum_numeric::hamiltonian(t, &y, &numeric)],
                "hamiltonian",
            ),
            (
                vec![double_pendulum::averaged_hamiltonian(&y, &symbolic)],
                vec![double_pendulum_numeric::averaged_hamiltonian(&y, &numeric)],
                "averaged_hamiltonian",
            ),
            (
                vec![double_pendulum::vibrational_potential(&q, &symbolic)],
                vec![double_pendulum_numeric::vibrational_potential(&q, &numeric)],
                "vibrational_potential",
            ),
        ];
        for (a, b, name) in pairs {
            for (x, z) in a.iter().zip(&b) {
                close(name, *x, *z, 1e-12);
            }
        }
    }
}

fn flat<const N: usize>(m: &[[f64; N]; N]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

/// Central difference of f along component k of x.
fn partial<const M: usize>(f: impl Fn(&[f64; M]) -> f64, x: &[f64; M], k: usize) -> f64 {
    let h = 1e-5 * (1.0 + x[k].abs());
    let (mut up, mut down) = (*x, *x);
    up[k] += h;
    down[k] -= h;
    (f(&up) - f(&down)) / (2.0 * h)
}

#[test]
fn triple_pendulum_fields_are_hamiltons_equations_of_the_generated_hamiltonians() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for _ in 0..50 {
        let mut params = triple_pendulum::Params::default();
        for name in triple_pendulum::Params::NAMES {
            let value = match name {
                "mu" => 0.0,
                "nu" => rng.between(10.0, 100.0),
                "a" => rng.between(0.0, 6.0),
                _ => rng.between(0.5, 2.0),
            };
            params.set(name, value).unwrap();
        }
        let t = rng.between(0.0, 1.0);
        let y: [f64; 6] = std::array::from_fn(|_| rng.between(-2.0, 2.0));
        let exact = triple_pendulum::exact_rhs(t, &y, &params);
        let averaged = triple_pendulum::averaged_rhs(&y, &params);
        let h = |y: &[f64; 6]| triple_pendulum::hamiltonian(t, y, &params);
        let h_bar = |y: &[f64; 6]| triple_pendulum::averaged_hamiltonian(y, &params);
        for i in 0..3 {
            // q' = ∂H/∂p, p' = −∂H/∂q.
            close("q' of H", exact[i], partial(h, &y, 3 + i), 1e-7);
            close("p' of H", exact[3 + i], -partial(h, &y, i), 1e-7);
            close("q' of H̄", averaged[i], partial(h_bar, &y, 3 + i), 1e-7);
            close("p' of H̄", averaged[3 + i], -partial(h_bar, &y, i), 1e-7);
        }
        let jacobian = triple_pendulum::exact_jacobian(t, &y, &params);
        let averaged_jacobian = triple_pendulum::averaged_jacobian(&y, &params);
        for i in 0..6 {
            for k in 0..6 {
                let f = |y: &[f64; 6]| triple_pendulum::exact_rhs(t, y, &params)[i];
                close("exact Jacobian", jacobian[i][k], partial(f, &y, k), 1e-7);
                let f = |y: &[f64; 6]| triple_pendulum::averaged_rhs(y, &params)[i];
                close(
                    "averaged Jacobian",
                    averaged_jacobian[i][k],
                    partial(f, &y, k),
                    1e-7,
                );
            }
        }
        let q = [y[0], y[1], y[2]];
        let hessian = triple_pendulum::effective_potential_hessian(&q, &params);
        let v = |q: &[f64; 3]| triple_pendulum::effective_potential(q, &params);
        for i in 0..3 {
            for k in 0..3 {
                // (f(+,+) − f(+,−) − f(−,+) + f(−,−)) / 4h², error O(h²).
                let h = 1e-4;
                let at = |si: f64, sk: f64| {
                    let mut x = q;
                    x[i] += si * h;
                    x[k] += sk * h;
                    v(&x)
                };
                let expected =
                    (at(1.0, 1.0) - at(1.0, -1.0) - at(-1.0, 1.0) + at(-1.0, -1.0)) / (4.0 * h * h);
                close("Hessian of V + V_vibr", hessian[i][k], expected, 1e-5);
            }
        }
    }
}

/// The linear-solve recurrence: the Taylor method over one base period
/// against DOP853 at 1e-14, and the tangent recurrences (one solve per
/// tangent) against DOP853's variational equations: the monodromy matrices
/// agree, and det M = 1 (Hamiltonian, μ = 0).
#[test]
fn triple_pendulum_taylor_recurrences_match_dop853_over_one_period() {
    let params = triple_pendulum::Params::default();
    let period = 2.0 * PI / params.nu;
    let y0 = [0.3, -0.2, 0.1, 0.05, -0.1, 0.2];
    let run = |method| {
        monodromy::<_, 6, 42>(
            &mut Integrator::new(method).unwrap(),
            &triple_pendulum::Exact { params },
            period,
            &y0,
        )
        .unwrap()
    };
    let (y_taylor, m_taylor) = run(Method::Taylor { tol: 1e-15 });
    let (y_dop, m_dop) = run(Method::Dop853 {
        rtol: 1e-14,
        atol: 1e-14,
    });
    for i in 0..6 {
        close("state after one period", y_taylor[i], y_dop[i], 1e-11);
        for k in 0..6 {
            close("monodromy", m_taylor[i][k], m_dop[i][k], 1e-9);
        }
    }
    let m = DMatrix::from_fn(6, 6, |i, k| m_taylor[i][k]);
    close("det M", m.determinant(), 1.0, 1e-9);
    // The averaged system's recurrences (solves for A⁻¹, its derivatives).
    let averaged = triple_pendulum::Averaged { params };
    let integrate = |method| {
        Integrator::new(method)
            .unwrap()
            .advance(&averaged, 0.0, &y0, 1.0)
            .unwrap()
    };
    let (a, b) = (
        integrate(Method::Taylor { tol: 1e-15 }),
        integrate(Method::Dop853 {
            rtol: 1e-14,
            atol: 1e-14,
        }),
    );
    for i in 0..6 {
        close("averaged state", a[i], b[i], 1e-11);
    }
    let _ = averaged.rhs(0.0, &y0);
}

/// a* of the upright N-link chain (unit masses, lengths, g) from the
/// generated Hessian of V + V_vibr, which is C + a² K: the smallest a with
/// C + a²K positive definite is a*² = λ_max(K⁻¹(−C)).
fn threshold_from_generated(hessian: impl Fn(f64) -> DMatrix<f64>) -> f64 {
    let c = hessian(0.0);
    let k = hessian(1.0) - &c;
    let l = k.clone().cholesky().expect("K is positive definite").l();
    let l_inv = l.try_inverse().unwrap();
    let m = &l_inv * (-c) * l_inv.transpose();
    let m = (&m + m.transpose()) * 0.5;
    m.symmetric_eigenvalues().max().sqrt()
}

/// The closed form from the normal modes of the hanging chain: with
/// A0_ij = N − max(i, j) (the mass matrix at the upright, unit chain) and
/// D = diag(N, N − 1, …, 1) (C = −g D), V_vibr = (a²/4) φᵀ D A0⁻¹ D φ, so
/// the upright is stable iff (a²/2) λ_min(A0⁻¹ D) > 1: a*² = 2/λ_min.
/// λ_min is the squared frequency of the chain's slowest normal mode.
fn threshold_from_normal_modes(n: usize) -> f64 {
    let a0 = DMatrix::from_fn(n, n, |i, j| (n - i.max(j)) as f64);
    let d_sqrt = DMatrix::from_fn(
        n,
        n,
        |i, j| if i == j { ((n - i) as f64).sqrt() } else { 0.0 },
    );
    let symmetric = &d_sqrt * a0.try_inverse().unwrap() * &d_sqrt;
    let lambda_min = symmetric.symmetric_eigenvalues().min();
    (2.0 / lambda_min).sqrt()
}

#[test]
fn n_link_chain_thresholds_match_the_normal_mode_closed_form() {
    // N = 2 from the symbolic form, N = 3 and 4 from the numeric one.
    let double = threshold_from_generated(|a| {
        let params = double_pendulum::Params {
            a,
            ..Default::default()
        };
        let h = double_pendulum::effective_potential_hessian(&[0.0; 2], &params);
        DMatrix::from_fn(2, 2, |i, j| h[i][j])
    });
    close("N = 2", double, threshold_from_normal_modes(2), 1e-12);
    close("N = 2, published a*", double, 1.8477590650225735, 1e-12);
    let triple = threshold_from_generated(|a| {
        let params = triple_pendulum::Params {
            a,
            ..Default::default()
        };
        let h = triple_pendulum::effective_potential_hessian(&[0.0; 3], &params);
        DMatrix::from_fn(3, 3, |i, j| h[i][j])
    });
    close("N = 3", triple, threshold_from_normal_modes(3), 1e-12);
    let quadruple = threshold_from_generated(|a| {
        let params = quadruple_pendulum::Params {
            a,
            ..Default::default()
        };
        let h = quadruple_pendulum::effective_potential_hessian(&[0.0; 4], &params);
        DMatrix::from_fn(4, 4, |i, j| h[i][j])
    });
    close("N = 4", quadruple, threshold_from_normal_modes(4), 1e-12);
    // Longer chains need faster shaking.
    assert!(
        double < triple && triple < quadruple,
        "{double} {triple} {quadruple}"
    );
}

/// The model file's limits are errors naming the file, the key and the
/// reason (checked before any computer algebra, so the build reports them).
#[test]
fn too_large_models_are_refused_with_a_reason() {
    let chain = |n: usize, extra: &str| {
        let mut text = format!(
            "name = \"chain\"\ndescription = \"a chain\"\n{extra}lagrangian = \"{}\"\n",
            (1..=n)
                .map(|i| format!("dot(q{i})^2/2 - cos(q{i})"))
                .collect::<Vec<_>>()
                .join(" + ")
        );
        for i in 1..=n {
            text.push_str(&format!(
                "[[coordinates]]\nname = \"q{i}\"\nvelocity = \"q{i}d\"\n"
            ));
        }
        text
    };
    let error = mechlab::model::Model::parse("models/chain.toml", &chain(12, "")).unwrap_err();
    assert_eq!(error.file, "models/chain.toml");
    assert_eq!(error.key, "coordinates");
    assert!(
        error.reason.contains("12 degrees of freedom") && error.reason.contains("at most 8"),
        "{error}"
    );
    let error =
        mechlab::model::Model::parse("models/chain.toml", &chain(4, "inverse = \"symbolic\"\n"))
            .unwrap_err();
    assert_eq!(error.key, "inverse");
    let error =
        mechlab::model::Model::parse("models/chain.toml", &chain(2, "inverse = \"fast\"\n"))
            .unwrap_err();
    assert!(error.reason.contains("'fast'"), "{error}");
    let ok = mechlab::model::Model::parse("models/chain.toml", &chain(8, "")).unwrap();
    assert_eq!(ok.inverse, mechlab::model::Inverse::Numeric);
    let ok = mechlab::model::Model::parse("models/chain.toml", &chain(2, "")).unwrap();
    assert_eq!(ok.inverse, mechlab::model::Inverse::Symbolic);
}
