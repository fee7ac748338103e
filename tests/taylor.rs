//! The Taylor method: its recurrence kernels against direct evaluation, the
//! generated coefficients of every model against the field and an
//! independent integration, its error against the tolerance, and agreement
//! with DOP853 at 1e-14 on the two studies' problems.

use mechlab::analysis::floquet::monodromy;
use mechlab::analysis::period_map::orbit;
use mechlab::models::{double_pendulum, elastic_pendulum, horizontal_pendulum, kapitza};
use mechlab::ode::series::{self, Coefficients, COEFFICIENTS};
use mechlab::ode::{order_for_tolerance, Integrator, Method, OdeError, System, TaylorWork};
use mechlab::registry::DynamicModel;
use std::f64::consts::PI;

use crate::common::{assert_tangent_recurrences_differentiate, Rng};

const ORDER: usize = 14;

/// Σ c[k] h^k.
fn sum(c: &Coefficients, h: f64) -> f64 {
    (0..=ORDER).rev().fold(0.0, |acc, k| acc * h + c[k])
}

/// A random polynomial argument u(t) = Σ u_k t^k (k ≤ 4), with u(0) = `at_zero`.
fn argument(rng: &mut Rng, at_zero: f64) -> Coefficients {
    let mut u = [0.0; COEFFICIENTS];
    u[0] = at_zero;
    for c in u.iter_mut().take(5).skip(1) {
        *c = rng.between(-1.5, 1.5);
    }
    u
}

/// The kernel's series of f(u(t)) summed at small h against f evaluated
/// directly: they agree to O(h^{ORDER+1}), i.e. to round-off at h = 0.02
/// (the arguments' singularities lie beyond |t| ≈ 0.3).
fn check(name: &str, h: f64, series_value: f64, direct: f64) {
    assert!(
        (series_value - direct).abs() < 1e-13 * (1.0 + direct.abs()),
        "{name}: series {series_value} vs direct {direct} at h = {h}"
    );
}

#[test]
fn recurrence_kernels_match_direct_evaluation_including_zero_arguments() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for trial in 0..200 {
        // Every fourth trial starts the unary arguments at exactly zero.
        let zero = trial % 4 == 0;
        let a = argument(&mut rng, if zero { 0.0 } else { rng_value(trial) });
        let b0 = 0.5 + rng.uniform();
        let b = argument(&mut rng, b0);
        let u0 = if zero { 0.0 } else { rng.between(-3.0, 3.0) };
        let u = argument(&mut rng, u0);
        let zero: Coefficients = [0.0; COEFFICIENTS];
        let (mut product, mut square, mut quotient) = (zero, zero, zero);
        let (mut exp, mut ln, mut sqrt) = (zero, zero, zero);
        let (mut sin, mut cos, mut power) = (zero, zero, zero);
        let alpha = -1.5 + 3.0 * rng.uniform();
        product[0] = a[0] * b[0];
        square[0] = a[0] * a[0];
        quotient[0] = a[0] / b[0];
        exp[0] = u[0].exp();
        ln[0] = b[0].ln();
        sqrt[0] = b[0].sqrt();
        (sin[0], cos[0]) = u[0].sin_cos();
        power[0] = b[0].powf(alpha);
        for n in 1..=ORDER {
            product[n] = series::product(&a, &b, n);
            square[n] = series::square(&a, n);
            quotient[n] = series::quotient(&quotient, a[n], &b, n);
            exp[n] = series::exp(&exp, &u, n);
            ln[n] = series::ln(&ln, &b, n);
            sqrt[n] = series::sqrt(&sqrt, b[n], n);
            (sin[n], cos[n]) = series::sin_cos(&sin, &cos, &u, n);
            power[n] = series::power(&power, &b, alpha, n);
        }
        for h in [0.02, -0.015] {
            let (av, bv, uv) = (sum(&a, h), sum(&b, h), sum(&u, h));
            check("product", h, sum(&product, h), av * bv);
            check("square", h, sum(&square, h), av * av);
            check("quotient", h, sum(&quotient, h), av / bv);
            check("exp", h, sum(&exp, h), uv.exp());
            check("ln", h, sum(&ln, h), bv.ln());
            check("sqrt", h, sum(&sqrt, h), bv.sqrt());
            check("sin", h, sum(&sin, h), uv.sin());
            check("cos", h, sum(&cos, h), uv.cos());
            check("power", h, sum(&power, h), bv.powf(alpha));
        }
    }
}

fn rng_value(trial: usize) -> f64 {
    (trial as f64 * 0.37).sin() * 2.0
}

/// The generated coefficients of one system at (t, y): out[1] is the field,
/// the series summed over a short step matches DOP853 at 1e-14, and its
/// derivative there matches the field at the new state.
fn check_generated<S: System<N>, const N: usize>(name: &str, system: &S, t: f64, y: &[f64; N]) {
    let order = 24;
    let mut out = vec![[0.0; N]; order + 1];
    assert!(system.taylor(t, y, order, &mut TaylorWork::default(), &mut out));
    let f = system.rhs(t, y);
    for i in 0..N {
        assert!(
            (out[1][i] - f[i]).abs() < 1e-12 * (1.0 + f[i].abs()),
            "{name}: first coefficient {} vs field {}",
            out[1][i],
            f[i]
        );
    }
    // A fraction of the fastest time scale (the double pendulum's base
    // vibrates at ν = 100 by default).
    let h = 0.002;
    let summed: [f64; N] =
        std::array::from_fn(|i| (0..=order).rev().fold(0.0, |acc, k| acc * h + out[k][i]));
    let derivative: [f64; N] = std::array::from_fn(|i| {
        (1..=order)
            .rev()
            .fold(0.0, |acc, k| acc * h + k as f64 * out[k][i])
    });
    let reference = Integrator::new(Method::Dop853 {
        rtol: 1e-14,
        atol: 1e-14,
    })
    .unwrap()
    .advance(system, t, y, t + h)
    .unwrap();
    let field = system.rhs(t + h, &reference);
    for i in 0..N {
        assert!(
            (summed[i] - reference[i]).abs() < 1e-11 * (1.0 + reference[i].abs()),
            "{name}: component {i}: series {} vs DOP853 {}",
            summed[i],
            reference[i]
        );
        assert!(
            (derivative[i] - field[i]).abs() < 1e-9 * (1.0 + field[i].abs()),
            "{name}: component {i}: series derivative {} vs field {}",
            derivative[i],
            field[i]
        );
    }
}

#[test]
fn generated_coefficients_of_every_model_follow_the_field() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for _ in 0..20 {
        let t = rng.between(0.0, 2.0);
        let kapitza = kapitza::Params {
            A: rng.between(0.0, 2.0),
            eps: rng.between(0.05, 0.3),
            mu: rng.between(0.0, 0.5),
        };
        let y2 = [rng.between(-PI, PI), rng.between(-2.0, 2.0)];
        check_generated("kapitza exact", &kapitza::Exact { params: kapitza }, t, &y2);
        check_generated(
            "kapitza averaged",
            &kapitza::Averaged { params: kapitza },
            t,
            &y2,
        );
        let horizontal = horizontal_pendulum::Params::default();
        check_generated(
            "horizontal exact",
            &horizontal_pendulum::Exact { params: horizontal },
            t,
            &y2,
        );
        let dp = double_pendulum::Params {
            mu: rng.between(0.0, 0.3),
            ..Default::default()
        };
        let y4: [f64; 4] = std::array::from_fn(|_| rng.between(-1.5, 1.5));
        check_generated(
            "double pendulum exact",
            &double_pendulum::Exact { params: dp },
            t,
            &y4,
        );
        check_generated(
            "double pendulum averaged",
            &double_pendulum::Averaged { params: dp },
            t,
            &y4,
        );
        let elastic = elastic_pendulum::Params::default();
        let mut ye: [f64; 4] = std::array::from_fn(|_| rng.between(-0.5, 0.5));
        ye[0] = 1.0 + 0.2 * ye[0]; // the spring length r
        check_generated(
            "elastic exact",
            &elastic_pendulum::Exact { params: elastic },
            t,
            &ye,
        );
    }
}

/// The monodromy over `period` from the Taylor method's tangent
/// recurrences, checked against DOP853's variational equations at 1e-14
/// (state to 1e-11, matrix entries to `bound` relative to 1 + |M|).
fn taylor_monodromy_against_dop853<S: System<N>, const N: usize, const V: usize>(
    system: &S,
    period: f64,
    y0: &[f64; N],
    bound: f64,
) -> [[f64; N]; N] {
    let run = |method| {
        monodromy::<_, N, V>(&mut Integrator::new(method).unwrap(), system, period, y0).unwrap()
    };
    let (y_taylor, m_taylor) = run(Method::Taylor { tol: 1e-15 });
    let (y_dop, m_dop) = run(Method::Dop853 {
        rtol: 1e-14,
        atol: 1e-14,
    });
    for i in 0..N {
        assert!((y_taylor[i] - y_dop[i]).abs() < 1e-11, "y[{i}]");
        for k in 0..N {
            assert!(
                (m_taylor[i][k] - m_dop[i][k]).abs() < bound * (1.0 + m_dop[i][k].abs()),
                "M[{i}][{k}]: {} vs {}",
                m_taylor[i][k],
                m_dop[i][k]
            );
        }
    }
    m_taylor
}

#[test]
fn tangent_recurrences_give_the_monodromy_of_the_variational_equations() {
    let params = kapitza::Params {
        A: 1.5,
        eps: 0.1,
        mu: 0.1,
    };
    let period = 2.0 * PI * params.eps;
    let m = taylor_monodromy_against_dop853::<_, 2, 6>(
        &kapitza::Exact { params },
        period,
        &[0.4, -0.2],
        1e-10,
    );
    // Liouville: det M = exp(−μ T).
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    assert!(
        (det - (-params.mu * period).exp()).abs() < 1e-12,
        "det {det}"
    );
}

/// The double pendulum's variational recurrences are long enough to be
/// split into parts (functions of their own, `PART_LINES` in the
/// derivation): its monodromy over a period of the base against DOP853's.
#[test]
fn split_tangent_recurrences_give_the_double_pendulum_s_monodromy() {
    let params = double_pendulum::Params {
        mu: 0.05,
        ..Default::default()
    };
    let period = double_pendulum::Dynamic
        .phase_period(&params.values())
        .expect("a fast phase");
    taylor_monodromy_against_dop853::<_, 4, 20>(
        &double_pendulum::Exact { params },
        period,
        &[0.3, -0.2, 0.1, 0.4],
        1e-9,
    );
}

/// Kapitza period map over 100 periods: the error against a tighter run.
fn kapitza_error(tol: f64) -> (f64, u64) {
    let params = kapitza::Params {
        A: 1.5,
        eps: 0.1,
        mu: 0.0,
    };
    let period = 2.0 * PI * params.eps;
    let system = kapitza::Exact { params };
    let y0 = [PI - 0.5, 0.0];
    let end = |method| {
        let mut integrator = Integrator::new(method).unwrap();
        let points = orbit(&mut integrator, &system, period, &y0, 100, &[false, false]).unwrap();
        (points[100], integrator.stats.steps)
    };
    let (reference, _) = end(Method::Taylor { tol: 1e-17 });
    let (y, steps) = end(Method::Taylor { tol });
    let error = (y[0] - reference[0]).abs().max((y[1] - reference[1]).abs());
    (error, steps)
}

#[test]
fn the_error_falls_with_the_tolerance_as_designed() {
    let mut previous = (f64::INFINITY, 0);
    for tol in [1e-5, 1e-8, 1e-11] {
        let (error, steps) = kapitza_error(tol);
        // The tolerance is a per-step bound; 100 periods of about 9 steps
        // each may add up to a few thousand of them.
        assert!(error < 3e3 * tol, "tol {tol}: error {error:e}");
        assert!(
            error < previous.0 / 50.0,
            "tol {tol}: error {error:e} after {:e}",
            previous.0
        );
        // Higher orders, not smaller steps, buy the accuracy.
        assert!(steps < 2 * previous.1.max(steps / 2 + 1), "steps {steps}");
        previous = (error, steps);
    }
    assert_eq!(order_for_tolerance(1e-10), 17);
    assert_eq!(order_for_tolerance(1e-300), series::MAX_ORDER);
}

/// Both studies' problems over t ∈ [0, 10] with Taylor at 1e-15 against DOP853 at 1e-14.
#[test]
fn taylor_converges_to_dop853_on_kapitza_and_the_double_pendulum() {
    fn agree<S: System<N>, const N: usize>(name: &str, system: &S, y0: &[f64; N]) {
        let run = |method| {
            Integrator::new(method)
                .unwrap()
                .advance(system, 0.0, y0, 10.0)
                .unwrap()
        };
        let reference = run(Method::Dop853 {
            rtol: 1e-14,
            atol: 1e-14,
        });
        let mut previous = f64::INFINITY;
        for tol in [1e-8, 1e-11, 1e-15] {
            let y = run(Method::Taylor { tol });
            let error = (0..N)
                .map(|i| (y[i] - reference[i]).abs())
                .fold(0.0, f64::max);
            assert!(error < previous, "{name} tol {tol}: {error:e}");
            previous = error;
        }
        assert!(
            previous < 1e-10,
            "{name}: taylor 1e-15 vs dop853 1e-14: {previous:e}"
        );
    }
    let kapitza = kapitza::Params {
        A: 1.5,
        eps: 0.1,
        mu: 0.05,
    };
    agree("kapitza", &kapitza::Exact { params: kapitza }, &[2.5, 0.3]);
    let dp = double_pendulum::Params {
        nu: 100.0,
        ..Default::default()
    };
    agree(
        "double pendulum",
        &double_pendulum::Exact { params: dp },
        &[0.3, -0.2, 0.0, 0.1],
    );
}

struct NoRecurrences;
impl System<1> for NoRecurrences {
    fn rhs(&self, _t: f64, y: &[f64; 1]) -> [f64; 1] {
        [-y[0]]
    }
}

#[test]
fn systems_without_recurrences_and_bad_tolerances_are_errors() {
    let error = Integrator::new(Method::Taylor { tol: 1e-8 })
        .unwrap()
        .advance(&NoRecurrences, 0.0, &[1.0], 1.0)
        .unwrap_err();
    assert_eq!(error, OdeError::TaylorUnavailable);
    assert!(error.to_string().contains("taylor"));
    for tol in [0.0, -1e-8, f64::NAN] {
        assert!(matches!(
            Method::parse("taylor", tol),
            Err(OdeError::InvalidSetting { .. })
        ));
    }
    let params = kapitza::Params::default();
    let error = Integrator::new(Method::Taylor { tol: 1e-8 })
        .unwrap()
        .advance(&kapitza::Exact { params }, 0.0, &[f64::NAN, 0.0], 1.0)
        .unwrap_err();
    assert!(matches!(error, OdeError::NonFiniteInitialState { .. }));
}

/// Every model in models/ with tangent recurrences: they differentiate its
/// solution's recurrences (see the helper), whichever form its derivation
/// chose, through the same compiled code the analyses reach.
#[test]
fn every_model_s_tangent_recurrences_differentiate_its_solution_s() {
    use mechlab::registry::{Fixed, FixedSize};
    for model in mechlab::models::MODELS {
        let (name, params) = (model.info.name, model.dynamic.defaults());
        match model.sized {
            Some(FixedSize::Dof1(m)) => assert_tangent_recurrences_differentiate(&m.exact(&params), name),
            Some(FixedSize::Dof2(m)) => assert_tangent_recurrences_differentiate(&m.exact(&params), name),
            Some(FixedSize::Dof3(m)) => assert_tangent_recurrences_differentiate(&m.exact(&params), name),
            Some(FixedSize::Large(..)) => eprintln!(
                "{name}: skipped (4 to 24 degrees of freedom: this test's instances are compiled for 1 to 3)"
            ),
            None => eprintln!("{name}: skipped (a contact model has no tangent recurrences)"),
        }
    }
}
