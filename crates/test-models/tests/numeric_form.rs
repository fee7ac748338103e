//! The numeric-solve form of the generated code (models of 3 or more
//! degrees of freedom, or `inverse = "numeric"`): A(q) q' = p − b solved by
//! Cholesky at run time, Jacobians and the Hessian of V + V_vibr by forward
//! mode through the solve, and the Taylor recurrence of the solve.
//!
//! Checked against the symbolic-inverse form of the same double pendulum,
//! against finite differences of the generated Hamiltonians, against
//! DOP853, and the N-link chains' thresholds against the closed form from
//! their normal modes. Here too (one test binary for the test models):
//! every test model's tangent recurrences against differences of its
//! solution's.

use mechlab::analysis::floquet::monodromy;
use mechlab::models::{double_pendulum, triple_pendulum};
use mechlab::ode::{Integrator, Method, System};
use mechlab::registry::{DynamicModel, Kind};
use mechlab_test_models::{
    awkward_names, awkward_names_numeric, double_pendulum_numeric, quadruple_pendulum,
    spring_double_pendulum,
};
use nalgebra::DMatrix;
use std::f64::consts::PI;

#[path = "../../../tests/common/mod.rs"]
mod common;
use common::{assert_close as close, assert_tangent_recurrences_differentiate, Rng};

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
            // Second-order averaging: K̄ expanded by Symbolica, its
            // derivatives forward mode in the DAG, against the Lie series
            // in the DAG with the solves and K̄'s derivatives by hyper-dual
            // numbers at run time.
            (
                vec![double_pendulum::averaged2_hamiltonian(&y, &symbolic)],
                vec![double_pendulum_numeric::averaged2_hamiltonian(&y, &numeric)],
                "averaged2_hamiltonian",
            ),
            (
                double_pendulum::averaged2_rhs(&y, &symbolic).to_vec(),
                double_pendulum_numeric::averaged2_rhs(&y, &numeric).to_vec(),
                "averaged2_rhs",
            ),
            (
                flat(&double_pendulum::averaged2_hessian(&y, &symbolic)),
                flat(&double_pendulum_numeric::averaged2_hessian(&y, &numeric)),
                "averaged2_hessian",
            ),
            (
                double_pendulum::averaged2_shift(t, &y, &symbolic).to_vec(),
                double_pendulum_numeric::averaged2_shift(t, &y, &numeric).to_vec(),
                "averaged2_shift",
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

/// Every model, in either form: with the friction `mu` switched off, the
/// exact field is q' = ∂H/∂p, p' = −∂H/∂q of the generated H, the averaged
/// field likewise of H̄, and the Hessian of V + V_vibr is that of the
/// generated V + V_vibr (central differences). Through the dynamic
/// interface, so it covers every file in `models/` and `test_models/`.
#[test]
fn every_model_follows_hamiltons_equations_of_its_hamiltonians() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let models: Vec<&dyn DynamicModel> = mechlab::models::MODELS
        .iter()
        .map(|m| m.dynamic)
        .chain([
            &double_pendulum_numeric::DYNAMIC as &dyn DynamicModel,
            &spring_double_pendulum::DYNAMIC,
            &awkward_names::DYNAMIC,
            &awkward_names_numeric::DYNAMIC,
        ])
        .collect();
    let mut checked = 0;
    for model in models {
        let Kind::Hamiltonian { dof: n, fast_phase } = model.kind() else {
            continue;
        };
        let info = model.info();
        // Hamilton's equations hold without the file's forces and
        // dissipation: every parameter they name is set to zero.
        let mut params = model.defaults();
        for k in non_conservative(info) {
            params[k] = 0.0;
        }
        let periodic = model.periodic();
        let mut inside = 0;
        for _ in 0..20 {
            let t = rng.between(0.0, 1.0);
            let mut y: Vec<f64> = (0..2 * n).map(|_| rng.between(-1.5, 1.5)).collect();
            for i in 0..n {
                if !periodic[i] {
                    y[i] = rng.between(0.8, 1.2); // lengths of springs
                }
            }
            // A model defined only near its start (a square root of a
            // negative number past a chart's edge) is checked where the
            // energy is finite a step of 5 % all round: near the edge, where
            // the energy's derivatives grow without bound, the central
            // differences lose their accuracy.
            let defined = (0..2 * n).all(|k| {
                [-0.05, 0.0, 0.05].iter().all(|d| {
                    let mut z = y.clone();
                    z[k] += d * (1.0 + z[k].abs());
                    model.energy(&params, t, &z).is_finite()
                })
            });
            if !defined {
                continue;
            }
            inside += 1;
            let check = |field: &[f64], energy: &dyn Fn(&[f64]) -> f64, what: &str| {
                for i in 0..n {
                    let name = format!("{} {what}", info.name);
                    close(&name, field[i], partial_of(energy, &y, n + i), 1e-6);
                    close(&name, field[n + i], -partial_of(energy, &y, i), 1e-6);
                }
            };
            check(
                &model.exact_rhs(&params, t, &y),
                &|y| model.energy(&params, t, y),
                "H",
            );
            if fast_phase {
                let averaged = model.averaged_rhs(&params, &y).unwrap();
                check(
                    &averaged,
                    &|y| model.averaged_energy(&params, y).unwrap(),
                    "H̄",
                );
            }
            let q = &y[..n];
            let hessian = model.effective_potential_hessian(&params, q).unwrap();
            let v = |q: &[f64]| model.effective_potential(&params, q).unwrap();
            for i in 0..n {
                for k in 0..n {
                    // Steep potentials (a charge near the orbit) need the
                    // differences' own error in the tolerance.
                    let (by_differences, error) = second_partial(&v, q, i, k);
                    close(
                        &format!("{} Hessian of V + V_vibr", info.name),
                        hessian[i * n + k],
                        by_differences,
                        1e-5 + error / (1.0 + by_differences.abs()),
                    );
                }
            }
        }
        if inside == 0 {
            eprintln!(
                "{}: skipped (none of 20 random states lies inside its domain)",
                info.name
            );
            continue;
        }
        checked += 1;
    }
    assert!(checked >= 10, "{checked} models checked");
}

/// A model whose names are those the generated code could use for itself
/// (a coordinate y, a phase z, parameters h, factor, order, series, out,
/// time, r0, g0, time named s): both forms agree with each other, with
/// friction (the parameter `time`) on, and its Taylor series with DOP853.
#[test]
fn names_that_collide_with_generated_identifiers_are_harmless() {
    let (symbolic, numeric) = (&awkward_names::DYNAMIC, &awkward_names_numeric::DYNAMIC);
    let mut params = symbolic.defaults();
    let friction = symbolic
        .info()
        .parameter_names
        .iter()
        .position(|p| *p == "time")
        .unwrap();
    params[friction] = 0.3;
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for _ in 0..50 {
        let t = rng.between(0.0, 2.0);
        let y: Vec<f64> = (0..4).map(|_| rng.between(-1.5, 1.5)).collect();
        let pairs = [
            (
                symbolic.exact_rhs(&params, t, &y),
                numeric.exact_rhs(&params, t, &y),
            ),
            (
                symbolic.averaged_rhs(&params, &y).unwrap(),
                numeric.averaged_rhs(&params, &y).unwrap(),
            ),
            (
                vec![symbolic.energy(&params, t, &y)],
                vec![numeric.energy(&params, t, &y)],
            ),
        ];
        for (a, b) in pairs {
            for (x, z) in a.iter().zip(&b) {
                close("awkward_names", *x, *z, 1e-12);
            }
        }
    }
    let p = awkward_names_numeric::Params::from_values(&params);
    let system = awkward_names_numeric::Exact { params: p };
    let y0 = [0.2, 0.4, 0.0, -0.1];
    let run = |method| {
        Integrator::new(method)
            .unwrap()
            .advance(&system, 0.0, &y0, 1.0)
            .unwrap()
    };
    let (a, b) = (
        run(Method::Taylor { tol: 1e-15 }),
        run(Method::Dop853 {
            rtol: 1e-14,
            atol: 1e-14,
        }),
    );
    for i in 0..4 {
        close("awkward_names Taylor", a[i], b[i], 1e-11);
    }
}

/// Central difference of f along component k of x.
fn partial_of(f: &dyn Fn(&[f64]) -> f64, x: &[f64], k: usize) -> f64 {
    let h = 1e-5 * (1.0 + x[k].abs());
    let (mut up, mut down) = (x.to_vec(), x.to_vec());
    up[k] += h;
    down[k] -= h;
    (f(&up) - f(&down)) / (2.0 * h)
}

/// (f(+,+) − f(+,−) − f(−,+) + f(−,−)) / 4h² along components i and k
/// at h = 10⁻⁴ and h/2, extrapolated (its error falls as h²), with the
/// two steps' difference as its error.
fn second_partial(f: &dyn Fn(&[f64]) -> f64, x: &[f64], i: usize, k: usize) -> (f64, f64) {
    let at_step = |h: f64| {
        let at = |si: f64, sk: f64| {
            let mut z = x.to_vec();
            z[i] += si * h;
            z[k] += sk * h;
            f(&z)
        };
        (at(1.0, 1.0) - at(1.0, -1.0) - at(-1.0, 1.0) + at(-1.0, -1.0)) / (4.0 * h * h)
    };
    let (coarse, fine) = (at_step(1e-4), at_step(5e-5));
    (fine + (fine - coarse) / 3.0, (fine - coarse).abs())
}

/// The numeric form's Jacobians (forward mode through the solves) against
/// central differences of the generated fields.
#[test]
fn triple_pendulum_jacobians_match_finite_differences() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for _ in 0..50 {
        let mut params = triple_pendulum::Params::default();
        for name in triple_pendulum::Params::NAMES {
            let value = match name {
                "mu" => rng.between(0.0, 0.5),
                "nu" => rng.between(10.0, 100.0),
                "a" => rng.between(0.0, 6.0),
                _ => rng.between(0.5, 2.0),
            };
            params.set(name, value).unwrap();
        }
        let t = rng.between(0.0, 1.0);
        let y: [f64; 6] = std::array::from_fn(|_| rng.between(-2.0, 2.0));
        let jacobian = triple_pendulum::exact_jacobian(t, &y, &params);
        let averaged_jacobian = triple_pendulum::averaged_jacobian(&y, &params);
        for i in 0..6 {
            for k in 0..6 {
                let f =
                    |y: &[f64]| triple_pendulum::exact_rhs(t, y.try_into().unwrap(), &params)[i];
                close(
                    "exact Jacobian",
                    jacobian[i][k],
                    partial_of(&f, &y, k),
                    1e-7,
                );
                let f =
                    |y: &[f64]| triple_pendulum::averaged_rhs(y.try_into().unwrap(), &params)[i];
                close(
                    "averaged Jacobian",
                    averaged_jacobian[i][k],
                    partial_of(&f, &y, k),
                    1e-7,
                );
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
    let too_many = mechlab_model::MAX_DOF + 1;
    let error = mechlab_model::Model::parse("models/chain.toml", &chain(too_many, "")).unwrap_err();
    assert_eq!(error.file, "models/chain.toml");
    assert_eq!(error.key, "coordinates");
    assert!(
        error
            .reason
            .contains(&format!("{too_many} degrees of freedom"))
            && error
                .reason
                .contains(&format!("at most {}", mechlab_model::MAX_DOF)),
        "{error}"
    );
    let error =
        mechlab_model::Model::parse("models/chain.toml", &chain(4, "inverse = \"symbolic\"\n"))
            .unwrap_err();
    assert_eq!(error.key, "inverse");
    let error = mechlab_model::Model::parse("models/chain.toml", &chain(2, "inverse = \"fast\"\n"))
        .unwrap_err();
    assert!(error.reason.contains("'fast'"), "{error}");
    let ok = mechlab_model::Model::parse("models/chain.toml", &chain(8, "")).unwrap();
    assert_eq!(ok.inverse, mechlab_model::Inverse::Numeric);
    let ok = mechlab_model::Model::parse("models/chain.toml", &chain(2, "")).unwrap();
    assert_eq!(ok.inverse, mechlab_model::Inverse::Symbolic);
}

/// The parameters a model file's `[forces]` and Rayleigh function name
/// (friction, a drive given as a force), whatever they are called.
fn non_conservative(info: &mechlab::registry::ModelInfo) -> Vec<usize> {
    let file = mechlab_model::Model::parse(info.source_file, info.source)
        .unwrap_or_else(|e| panic!("{} does not parse: {e}", info.name));
    let mut names = file.rayleigh.symbols();
    for force in &file.forces {
        names.extend(force.symbols());
    }
    info.parameter_names
        .iter()
        .enumerate()
        .filter(|(_, p)| names.contains(**p))
        .map(|(k, _)| k)
        .collect()
}

/// The tangent recurrences of every model in test_models/ (forward mode or
/// Jacobian form, whichever its derivation chose) differentiate its
/// solution's recurrences: the solves of the numeric form, powers, square
/// roots, quotients and awkward names included.
#[test]
fn every_test_model_s_tangent_recurrences_differentiate_its_solution_s() {
    macro_rules! check {
        ($($model:ident),*) => {$(
            assert_tangent_recurrences_differentiate(
                &mechlab_test_models::$model::Exact { params: Default::default() },
                stringify!($model),
            );
        )*};
    }
    check!(
        awkward_names,
        awkward_names_numeric,
        bare_pendulum,
        central_spring,
        double_pendulum_numeric,
        elliptic_pendulum,
        forced_oscillator,
        power_law_oscillator,
        quadruple_pendulum,
        rotating_hoop,
        spherical_pendulum,
        spring_chain4,
        spring_double_pendulum,
        van_der_pol
    );
}
