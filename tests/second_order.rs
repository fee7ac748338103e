//! Averaging to second order in ε = 1/rate: the derived K̄ against a
//! closed form derived by hand, the thresholds against the Mathieu series
//! and the exact (Floquet) edges, and their order in ε.

use crate::common::model_of;
use mechlab::analysis::stability::{stability, EquilibriumStability, Settings};
use mechlab::models::{double_pendulum as dp, kapitza};
use mechlab::ode::{Integrator, Method};
use std::f64::consts::SQRT_2;

/// What `stability` says of the upright equilibrium (q = 0) of a model.
fn upright(model: &str, params: &[f64], settings: &Settings) -> EquilibriumStability {
    let result = stability(model_of(model), params, settings).unwrap();
    let upright = result
        .equilibria
        .into_iter()
        .find(|e| e.q.iter().all(|x| x.abs() < 1e-9));
    upright.expect("an upright equilibrium")
}

/// The exact lower edge, a*, and the second-order threshold at the
/// upright equilibrium of a model.
fn thresholds(model: &str, params: &[f64], amplitude: &str, a_max: f64) -> (f64, f64, f64) {
    let settings = Settings {
        amplitude: amplitude.into(),
        a_max: Some(a_max),
        samples: 200,
        edge_tolerance: 1e-12,
        method: Method::parse("dop853", 1e-13).unwrap(),
        max_windows: mechlab::analysis::stability::MAX_WINDOWS,
        accuracy: None,
        first: Default::default(),
    };
    let upright = upright(model, params, &settings);
    let exact = upright.exact_window.unwrap()[0].unwrap();
    let out = (
        exact,
        upright.a_star.unwrap(),
        upright.a_star_second_order.unwrap(),
    );
    eprintln!(
        "{model}: exact {:.12} first {:.12} second {:.12}",
        out.0, out.1, out.2
    );
    out
}

/// K̄ of the Kapitza pendulum by hand (the Lie series of `crates/derive/src/deprit.rs`
/// worked on H = (p − A sin θ sin q)²/2 + cos q): at (0, 0) its Hessian is
/// diag(A²/2 − 1 + A²ε²(9A² − 32)/32, 1 + A²ε²).
#[test]
fn kapitza_hessian_matches_the_hand_derivation() {
    for (a, eps) in [(1.5, 0.1), (2.0, 0.05), (0.7, 0.3)] {
        let params = kapitza::Params { A: a, eps, mu: 0.0 };
        let h = kapitza::averaged2_hessian(&[0.0, 0.0], &params);
        let expected = [
            [
                a * a / 2.0 - 1.0 + a * a * eps * eps * (9.0 * a * a - 32.0) / 32.0,
                0.0,
            ],
            [0.0, 1.0 + a * a * eps * eps],
        ];
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (h[i][j] - expected[i][j]).abs() < 1e-12,
                    "{h:?} vs {expected:?}"
                );
            }
        }
    }
}

/// The boundary a0(h) of the Mathieu equation w'' + (a − 2h cos 2z) w = 0
/// (DLMF 28.6.1): the linearised Kapitza pendulum at q = 0 is one with
/// z = θ/2, a = −4ε², h = 2εA, so A*(ε) solves −4ε² = a0(2εA).
pub(crate) fn mathieu_threshold(eps: f64) -> f64 {
    let a0 = |h: f64| {
        let h2 = h * h;
        -h2 / 2.0 + 7.0 * h2 * h2 / 128.0 - 29.0 * h2.powi(3) / 2304.0
            + 68687.0 * h2.powi(4) / 18874368.0
    };
    let (mut low, mut high) = (1.0, 2.0);
    for _ in 0..200 {
        let mid = 0.5 * (low + high);
        // Below the threshold −4ε² < a0 (unstable).
        if -4.0 * eps * eps < a0(2.0 * eps * mid) {
            low = mid;
        } else {
            high = mid;
        }
    }
    0.5 * (low + high)
}

/// The ε² coefficient: A* = √2 + c ε² with c = 7√2/16 from the Mathieu
/// series; the second-order threshold has it, the first-order one does not.
#[test]
fn kapitza_second_order_threshold_has_the_mathieu_coefficient() {
    let eps = 0.01;
    let params = kapitza::Params {
        A: 1.5,
        eps,
        mu: 0.0,
    };
    let (_, first, second) = thresholds("kapitza", &params.values(), "A", 4.0);
    assert!((first - SQRT_2).abs() < 1e-12);
    let c = (second - SQRT_2) / (eps * eps);
    assert!((c - 7.0 * SQRT_2 / 16.0).abs() < 1e-3, "c = {c}");
}

/// At ε = 0.1 the second-order threshold is ≥ 50× closer to the exact
/// (Floquet) edge than √2, and agrees with the Mathieu series; the gaps
/// fall like ε⁴ (second order) and ε² (first order).
#[test]
fn kapitza_thresholds_converge_with_the_predicted_orders() {
    let mut gaps = Vec::new();
    for eps in [0.05, 0.1, 0.2] {
        let params = kapitza::Params {
            A: 1.5,
            eps,
            mu: 0.0,
        };
        let (exact, first, second) = thresholds("kapitza", &params.values(), "A", 4.0);
        assert!((exact - mathieu_threshold(eps)).abs() < 2e-6 * (eps / 0.1).powi(8) + 1e-9);
        if eps == 0.1 {
            assert!(
                (exact - second).abs() * 50.0 < (exact - first).abs(),
                "{exact} {first} {second}"
            );
        }
        gaps.push((eps, (exact - first).abs(), (exact - second).abs()));
    }
    let slope = |k: usize| {
        let (e0, e1) = (gaps[0].0.ln(), gaps[2].0.ln());
        let (g0, g1) = if k == 1 {
            (gaps[0].1, gaps[2].1)
        } else {
            (gaps[0].2, gaps[2].2)
        };
        (g1.ln() - g0.ln()) / (e1 - e0)
    };
    assert!(
        (slope(1) - 2.0).abs() < 0.1,
        "first order: slope {}",
        slope(1)
    );
    assert!(
        (slope(2) - 4.0).abs() < 0.3,
        "second order: slope {}",
        slope(2)
    );
}

/// The double pendulum (all parameters 1) at ν = 100: the exact lower edge
/// of (0, 0) lies 4.7e-5 above a*; the second-order threshold within 1e-7.
#[test]
fn double_pendulum_second_order_threshold_meets_the_exact_edge() {
    let params = dp::Params {
        a: 2.0,
        nu: 100.0,
        ..Default::default()
    };
    let (exact, first, second) = thresholds("double_pendulum", &params.values(), "a", 6.0);
    assert!((exact - first - 4.7e-5).abs() < 0.3e-5, "{exact} − {first}");
    assert!(
        (exact - second).abs() < 1e-7,
        "exact {exact}, second order {second}"
    );
}

/// The triple and quadruple chains (numeric solves: K̄ from the Lie series
/// in the DAG) at ν = 100: the second-order threshold of the upright chain
/// is far closer to the exact (Floquet) edge than a* is.
#[test]
fn chains_second_order_thresholds_meet_the_exact_edges() {
    use mechlab::models::triple_pendulum as triple;
    use mechlab_test_models::quadruple_pendulum as quadruple;
    let triple = triple::Params {
        nu: 100.0,
        ..Default::default()
    };
    let quadruple = quadruple::Params {
        nu: 100.0,
        ..Default::default()
    };
    for (model, params, a_max) in [
        ("triple_pendulum", triple.values(), 12.0),
        ("quadruple_pendulum", quadruple.values(), 20.0),
    ] {
        let (exact, first, second) = thresholds(model, &params, "a", a_max);
        eprintln!(
            "{model}: exact − first {:e}, exact − second {:e}",
            exact - first,
            exact - second
        );
        assert!(
            (exact - second).abs() * 50.0 < (exact - first).abs(),
            "{model}: exact {exact}, first {first}, second {second}"
        );
    }
}

/// Theorem 2 one order higher: the exact run against the second-order
/// averaged run from the transformed state (mapped back) deviates like
/// 1/ν², where the first-order comparison deviates like 1/ν.
#[test]
fn second_order_trajectories_deviate_like_one_over_nu_squared() {
    use mechlab::analysis::averaging::{convergence, ConvergenceSettings};
    let params = dp::Params::default();
    for (order, expected) in [(1, -1.0), (2, -2.0)] {
        let settings = ConvergenceSettings {
            check: false,
            accuracy: None,
            parameter: Some("nu".into()),
            values: Some(vec![400.0, 800.0, 1600.0, 3200.0]),
            y0: None,
            t_obs: 2.0,
            method: Method::parse("dop853", 1e-12).unwrap(),
            order,
        };
        let result = convergence(model_of("double_pendulum"), &params.values(), &settings).unwrap();
        for slope in &result.slope {
            assert!(
                (slope - expected).abs() < 0.1,
                "order {order}: slope {slope}"
            );
        }
    }
    let kapitza = kapitza::Params {
        A: 1.5,
        eps: 0.1,
        mu: 0.0,
    };
    let settings = ConvergenceSettings {
        check: false,
        accuracy: None,
        parameter: Some("eps".into()),
        values: Some(vec![0.02, 0.01, 0.005, 0.0025]),
        y0: Some(vec![2.5, 0.3]),
        t_obs: 3.0,
        method: Method::parse("dop853", 1e-12).unwrap(),
        order: 2,
    };
    let result = convergence(model_of("kapitza"), &kapitza.values(), &settings).unwrap();
    assert!(
        (result.slope[0] + 2.0).abs() < 0.1,
        "Kapitza: slope {}",
        result.slope[0]
    );
}

/// Averaging is derived to second order: asking for the third is a typed
/// error naming the model and the order, not a panic.
#[test]
fn an_order_not_derived_is_an_error() {
    use mechlab::analysis::averaging::{convergence, AveragingError, ConvergenceSettings};
    let params = mechlab::models::triple_pendulum::Params::default();
    let settings = ConvergenceSettings {
        check: false,
        accuracy: None,
        parameter: None,
        values: None,
        y0: None,
        t_obs: 1.0,
        method: Method::parse("dop853", 1e-10).unwrap(),
        order: 3,
    };
    let error = convergence(model_of("triple_pendulum"), &params.values(), &settings).unwrap_err();
    assert!(matches!(error, AveragingError::Order(_, 3)), "{error}");
}

/// The averaging analysis to second order at its automatic sweep.
fn second_order_sweep() -> mechlab::analysis::averaging::ConvergenceSettings {
    mechlab::analysis::averaging::ConvergenceSettings {
        check: false,
        accuracy: None,
        parameter: None,
        values: None,
        y0: None,
        t_obs: 2.0,
        method: Method::parse("dop853", 1e-12).unwrap(),
        order: 2,
    }
}

/// Every model file with a fast phase has a second-order system, and its
/// trajectories deviate like 1/ν² from the exact ones (a wrong K̄₁, such as the circular
/// pivot's A²p/2, or a wrong map would leave −1).
#[test]
fn every_second_order_model_converges_like_one_over_nu_squared() {
    use mechlab::analysis::averaging::AveragingError;
    let mut checked = Vec::new();
    // The quadruple chain is a test model (test_models/), checked here too.
    let quadruple = &mechlab_test_models::quadruple_pendulum::INFO;
    for info in mechlab::models::ALL.iter().chain([quadruple]) {
        let settings = second_order_sweep();
        let defaults: Vec<f64> = info
            .parameter_defaults
            .iter()
            .map(|d| d.parse().unwrap())
            .collect();
        match crate::common::asymptotic_slopes(model_of(info.name), &defaults, &settings) {
            Ok(slopes) => {
                // −2, or −3 for a coordinate whose 1/ν² term vanishes.
                if crate::common::assert_whole_power_slopes(info.name, &slopes, -2.0) {
                    checked.push(info.name);
                }
            }
            // Friction at the defaults: the second order is not derived
            // for it, and the analysis says so.
            Err(e @ AveragingError::Dissipative { .. }) => eprintln!("{}: skipped: {e}", info.name),
            Err(
                AveragingError::Order(..)
                | AveragingError::Refused(mechlab::analysis::Refusal::NoFastPhase { .. })
                | AveragingError::Refused(mechlab::analysis::Refusal::ContactModel { .. })
                | AveragingError::Refused(mechlab::analysis::Refusal::Constrained { .. }),
            ) => {}
            Err(e) => panic!("{}: {e}", info.name),
        }
    }
    // The shipped studies' models and the chains (numeric solves) settle
    // at their own frequencies: none of their exponents is skipped.
    for name in [
        "kapitza",
        "double_pendulum",
        "triple_pendulum",
        "quadruple_pendulum",
    ] {
        assert!(checked.contains(&name), "{name} not checked: {checked:?}");
    }
    assert!(checked.len() >= 8, "{checked:?}");
}

/// Second-order averaging is derived for Hamiltonian systems: Kapitza's
/// pendulum with friction (μ = 0.1, its averaged flow losing volume at the
/// rate μ) is refused by name, not fitted to a wrong slope.
#[test]
fn second_order_averaging_refuses_friction() {
    use mechlab::analysis::averaging::{convergence, AveragingError};
    let settings = second_order_sweep();
    let damped = [1.5, 0.1, 0.1];
    match convergence(model_of("kapitza"), &damped, &settings) {
        Err(AveragingError::Dissipative { divergence, .. }) => {
            assert!((divergence + 0.1).abs() < 1e-6, "{divergence}")
        }
        other => panic!("{other:?}"),
    }
}

/// The upright's exact lower edge asked to `accuracy`, with its stated
/// error, a* and the second-order threshold.
fn edge_to_accuracy(model: &str, params: &[f64], a_max: f64, accuracy: f64) -> [f64; 4] {
    let settings = Settings {
        amplitude: model_of(model).info.amplitude.unwrap().into(),
        a_max: Some(a_max),
        samples: 20,
        edge_tolerance: 1e-9,
        method: Method::parse("dop853", 1e-10).unwrap(),
        max_windows: 1,
        accuracy: Some(accuracy),
        first: mechlab::analysis::stability::FirstWindows::Highest,
    };
    let upright = upright(model, params, &settings);
    let check = upright
        .exact_window_check
        .as_deref()
        .unwrap_or_else(|| panic!("{upright:#?}"));
    assert!(check.ends_with("reached"), "{check}");
    assert!(!check.contains("NOT"), "{check}");
    let edge = upright.exact_window.unwrap()[0].unwrap();
    let error = upright.exact_window_error.unwrap()[0].unwrap();
    eprintln!("{model} {params:?}: edge {edge:.13} ± {error:.1e} ({check})");
    let (first, second) = (
        upright.a_star.unwrap(),
        upright.a_star_second_order.unwrap(),
    );
    [edge, error, first, second]
}

/// A fast vibration (ε from 1e-2 down to 1e-5 of the pendulum's time): the
/// exact lower edge asked to 1e-10 lies within its stated error of the
/// Mathieu series' threshold (DLMF 28.6.1), above √2 wherever the series
/// puts it further above than that error, and its error is what was asked.
#[test]
fn kapitza_exact_edge_at_a_fast_vibration_meets_the_mathieu_series() {
    for eps in [1e-2, 1e-3, 1e-4, 1e-5] {
        let params = kapitza::Params {
            A: 1.5,
            eps,
            mu: 0.0,
        };
        let [edge, error, _, second] = edge_to_accuracy("kapitza", &params.values(), 2.0, 1e-10);
        let mathieu = mathieu_threshold(eps);
        assert!(error <= 1e-10, "ε = {eps}: error {error:e}");
        assert!(
            (edge - mathieu).abs() <= error + 1e-12,
            "ε = {eps}: exact {edge} vs Mathieu {mathieu} (stated error {error:e})"
        );
        if mathieu - SQRT_2 > 2.0 * error {
            assert!(edge > SQRT_2, "ε = {eps}: {edge} below √2");
        }
        // Second-order averaging is O(ε⁴) from the exact edge.
        assert!((edge - second).abs() <= error + 1e-12 + 0.1 * eps.powi(4));
    }
}

/// The double pendulum at ν = 10⁴ (a vibration 10⁴ times faster than its
/// pendulum's time): the exact lower edge of the upright asked to 1e-9
/// meets the second-order threshold within its stated error, and lies
/// above a* by the second order's shift.
#[test]
fn double_pendulum_exact_edge_at_a_fast_vibration_meets_second_order() {
    let params = dp::Params {
        a: 2.0,
        nu: 1e4,
        ..Default::default()
    };
    let [edge, error, first, second] =
        edge_to_accuracy("double_pendulum", &params.values(), 2.0, 1e-9);
    assert!(error <= 1e-9, "error {error:e}");
    assert!(
        (edge - second).abs() <= error + 1e-12,
        "exact {edge} vs second order {second} (stated error {error:e})"
    );
    assert!(edge > first, "exact {edge} below a* = {first}");
}

/// The frequencies of a linearised Hamiltonian with Hessian `h` (state
/// [q; p]): the moduli of the eigenvalues of J h, ascending, each once.
fn frequencies(h: &nalgebra::DMatrix<f64>) -> Vec<f64> {
    let n = h.nrows() / 2;
    let j = nalgebra::DMatrix::from_fn(2 * n, 2 * n, |i, k| match (i < n, k < n) {
        (true, false) if k == i + n => 1.0,
        (false, true) if i == k + n => -1.0,
        _ => 0.0,
    });
    let mut values: Vec<f64> = (j * h)
        .complex_eigenvalues()
        .iter()
        .filter(|z| z.im > 0.0)
        .map(|z| z.im)
        .collect();
    values.sort_by(f64::total_cmp);
    values
}

/// The chains' second-order Hessians (from a Lie series solved at run
/// time, with no closed form) against the exact system: the linearised
/// K̄₂'s frequencies at the upright chain are the Floquet frequencies
/// arg λ / T of the exact monodromy matrix up to O(ε³) (frequencies do not
/// change under the near-identity transformation), where K̄'s (first
/// order) are off by O(ε²), as the errors' fall from ν = 200 to 400 shows.
#[test]
fn chains_second_order_hessians_give_the_exact_floquet_frequencies() {
    use mechlab::models::triple_pendulum as triple;
    use mechlab_test_models::quadruple_pendulum as quadruple;
    let cases = [
        (
            "triple_pendulum",
            triple::Params {
                nu: 100.0,
                ..Default::default()
            }
            .values(),
            "a",
        ),
        (
            "quadruple_pendulum",
            quadruple::Params {
                nu: 100.0,
                ..Default::default()
            }
            .values(),
            "a",
        ),
    ];
    for (name, params, amplitude) in cases {
        let model = model_of(name).systems().unwrap();
        let info = model_of(name).info;
        let nu = info
            .parameter_names
            .iter()
            .position(|p| *p == "nu")
            .unwrap();
        let a = info
            .parameter_names
            .iter()
            .position(|p| *p == amplitude)
            .unwrap();
        let mut errors = Vec::new();
        for rate in [200.0, 400.0] {
            let mut p = params.clone();
            p[nu] = rate;
            // Inside the window: 1.3 times the first-order threshold.
            let n = info.coordinates.len();
            let y0 = vec![0.0; 2 * n];
            let first = |p: &[f64]| {
                let k = model.effective_potential_hessian(p, &vec![0.0; n]);
                let inverse = model.mass_matrix(p, &vec![0.0; n]).try_inverse().unwrap();
                nalgebra::DMatrix::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
                    (true, true) => k[(i, j)],
                    (false, false) => inverse[(i - n, j - n)],
                    _ => 0.0,
                })
            };
            let no_windows = Settings {
                amplitude: amplitude.into(),
                a_max: None,
                samples: 2,
                edge_tolerance: 1e-9,
                method: Method::parse("dop853", 1e-10).unwrap(),
                max_windows: 0,
                accuracy: None,
                first: Default::default(),
            };
            let a_star = upright(name, &p, &no_windows).a_star.unwrap();
            p[a] = 1.3 * a_star;
            let exact = {
                let period = model.phase_period(&p).unwrap();
                let mut integrator =
                    Integrator::new(Method::parse("dop853", 1e-13).unwrap()).unwrap();
                let (_, m) = model.monodromy(&p, &mut integrator, period, &y0).unwrap();
                let mut angles: Vec<f64> = m
                    .complex_eigenvalues()
                    .iter()
                    .filter(|z| z.im > 0.0)
                    .map(|z| z.im.atan2(z.re) / period)
                    .collect();
                angles.sort_by(f64::total_cmp);
                angles
            };
            let second = frequencies(&model.averaged2_hessian(&p, &y0).unwrap());
            let first = frequencies(&first(&p));
            assert_eq!(
                exact.len(),
                n,
                "{name} at ν = {rate}: not stable ({exact:?})"
            );
            let gap = |w: &[f64]| {
                (0..n)
                    .map(|k| ((w[k] - exact[k]) / exact[k]).abs())
                    .fold(0.0, f64::max)
            };
            eprintln!(
                "{name} ν = {rate}: exact {exact:?}, first off {:e}, second off {:e}",
                gap(&first),
                gap(&second)
            );
            errors.push((gap(&first), gap(&second)));
        }
        // Doubling ν: first order's error falls as ν⁻², second order's at
        // least as ν⁻³, and at ν = 400 it is at least 20 times smaller.
        let (first_fall, second_fall) = (errors[0].0 / errors[1].0, errors[0].1 / errors[1].1);
        assert!((3.0..5.0).contains(&first_fall), "{name}: {errors:?}");
        assert!(second_fall > 8.0, "{name}: {errors:?}");
        assert!(errors[1].1 * 20.0 < errors[1].0, "{name}: {errors:?}");
    }
}

/// The stated errors of the exact edges hold: Kapitza's upright at 25
/// vibration periods (ε from 1e-2 down to 1e-5) and two tolerances, 50
/// cases, each lower edge against the Mathieu series' threshold (DLMF
/// 28.6.1, whose truncation is below 1e-12 there). The stated error bounds
/// the true one in at least 95 % of the cases, and is within 100 times it
/// (or of the rounding at the edge, 64 units, below which no error can be
/// resolved).
#[test]
fn stated_edge_errors_bound_the_true_errors() {
    let (mut cases, mut bounded, mut sharp) = (0, 0, 0);
    for k in 0..25 {
        let eps = 1e-2 * 10f64.powf(-3.0 * k as f64 / 24.0);
        for tol in [1e-8, 1e-10] {
            let params = kapitza::Params {
                A: 1.5,
                eps,
                mu: 0.0,
            };
            let settings = Settings {
                amplitude: "A".into(),
                a_max: Some(2.0),
                samples: 20,
                edge_tolerance: 1e-13,
                method: Method::parse("dop853", tol).unwrap(),
                max_windows: 1,
                accuracy: None,
                first: mechlab::analysis::stability::FirstWindows::Highest,
            };
            let upright = upright("kapitza", &params.values(), &settings);
            let edge = upright.exact_window.unwrap()[0].unwrap();
            let stated = upright.exact_window_error.unwrap()[0].unwrap();
            let truth = (edge - mathieu_threshold(eps)).abs();
            let floor = 64.0 * f64::EPSILON * edge;
            cases += 1;
            bounded += usize::from(truth <= stated);
            sharp += usize::from(stated <= 100.0 * truth.max(floor));
            eprintln!("ε = {eps:.3e}, tol {tol:e}: error {truth:.2e}, stated {stated:.2e}");
        }
    }
    assert_eq!(cases, 50);
    assert!(
        bounded >= 48,
        "the stated error bounds the true one in {bounded} of {cases}"
    );
    assert!(
        sharp >= 48,
        "the stated error is within 100 times the true one in {sharp} of {cases}"
    );
}

/// Whether the upright N-link chain is unstable at amplitude `a`, written
/// out without mechlab: unit masses and lengths on a base shaken as
/// w = (a/ν) cos νt, linearised about the upright chain,
/// M φ'' = (g + w'') K φ with M_jk = Σ_{i ≥ max(j,k)} 1 and K_kk = Σ_{i ≥ k} 1;
/// the monodromy matrix of that linear system by classical RK4 at n and 2n
/// steps a period, Richardson-extrapolated (16 M_2n − M_n)/15; unstable
/// where its largest multiplier's modulus exceeds 1 by 10⁻¹⁰.
fn chain_unstable_by_hand(links: usize, g: f64, nu: f64, a: f64) -> bool {
    use nalgebra::DMatrix;
    let n = links;
    let mass = DMatrix::from_fn(n, n, |j, k| (n - j.max(k)) as f64);
    let stiffness = DMatrix::from_fn(n, n, |j, k| if j == k { (n - k) as f64 } else { 0.0 });
    let a_k = mass.try_inverse().unwrap() * stiffness; // φ'' = (g + w'') A_K φ
    let period = std::f64::consts::TAU / nu;
    let monodromy = |steps: usize| {
        let h = period / steps as f64;
        let rate = |t: f64, z: &DMatrix<f64>| {
            let (phi, phid) = (z.rows(0, n), z.rows(n, n));
            let mut dz = DMatrix::zeros(2 * n, 2 * n);
            dz.rows_mut(0, n).copy_from(&phid);
            let gravity = g - a * nu * (nu * t).cos();
            dz.rows_mut(n, n).copy_from(&(&a_k * phi * gravity));
            dz
        };
        let mut z = DMatrix::<f64>::identity(2 * n, 2 * n);
        for s in 0..steps {
            let t = s as f64 * h;
            let k1 = rate(t, &z);
            let k2 = rate(t + h / 2.0, &(&z + &k1 * (h / 2.0)));
            let k3 = rate(t + h / 2.0, &(&z + &k2 * (h / 2.0)));
            let k4 = rate(t + h, &(&z + &k3 * h));
            z += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        }
        z
    };
    let m = (monodromy(4000) * 16.0 - monodromy(2000)) / 15.0;
    let radius = m
        .complex_eigenvalues()
        .iter()
        .map(|l| l.norm())
        .fold(0.0, f64::max);
    radius > 1.0 + 1e-10
}

/// The lower edge of the upright chain's window by hand
/// ([`chain_unstable_by_hand`]), bisected in `bracket` (unstable at its
/// low end, stable at its high end) to 10⁻¹³ relative.
fn chain_edge_by_hand(links: usize, g: f64, nu: f64, bracket: (f64, f64)) -> f64 {
    let unstable = |a: f64| chain_unstable_by_hand(links, g, nu, a);
    let (mut lo, mut hi) = bracket;
    assert!(
        unstable(lo) && !unstable(hi),
        "{bracket:?} does not bracket the edge"
    );
    while hi - lo > 1e-13 * hi {
        let mid = 0.5 * (lo + hi);
        if unstable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The 4-link chain's exact lower edge, asked of `stability` to 10⁻¹⁰,
/// against the hand-written Floquet computation at ν = 10², 10³ and 10⁴
/// (1/ν from 10⁻² to 10⁻⁴ of the chain's time; at 10⁻¹ it has no window,
/// tested below): within 10⁻⁹ relative, and within the stated error.
#[test]
fn the_four_link_chains_exact_edge_meets_a_hand_written_floquet_computation() {
    use mechlab_test_models::quadruple_pendulum as quadruple;
    for nu in [100.0, 1000.0, 10_000.0] {
        let params = quadruple::Params {
            nu,
            ..Default::default()
        };
        let [edge, error, _, _] =
            edge_to_accuracy("quadruple_pendulum", &params.values(), 8.0, 1e-10);
        let hand = chain_edge_by_hand(4, 1.0, nu, (edge * (1.0 - 1e-6), edge * (1.0 + 1e-6)));
        eprintln!("ν = {nu}: edge {edge:.13} ± {error:.1e}, by hand {hand:.13}");
        assert!(
            (edge - hand).abs() <= 1e-9 * hand,
            "ν = {nu}: {edge} against {hand}"
        );
        assert!(
            (edge - hand).abs() <= error + 1e-12 * hand,
            "ν = {nu}: {edge} ± {error:e} against {hand}"
        );
    }
}

/// At ν = 10 (1/ν = 10⁻¹ of the chain's time) the 4-link chain has no
/// window up to a = 8, as `stability` says: the hand-written Floquet
/// computation finds the upright unstable at every amplitude of a grid of
/// 400 on (0, 8].
#[test]
fn the_four_link_chain_has_no_window_at_a_slow_vibration_by_hand_too() {
    use mechlab_test_models::quadruple_pendulum as quadruple;
    let params = quadruple::Params {
        nu: 10.0,
        ..Default::default()
    };
    let settings = Settings {
        amplitude: "a".into(),
        a_max: Some(8.0),
        samples: 20,
        edge_tolerance: 1e-9,
        method: Method::parse("dop853", 1e-10).unwrap(),
        max_windows: 1,
        accuracy: None,
        first: mechlab::analysis::stability::FirstWindows::Highest,
    };
    let upright = upright("quadruple_pendulum", &params.values(), &settings);
    assert!(upright.exact_window.is_none(), "{upright:?}");
    let stable: Vec<f64> = (1..=400)
        .map(|k| 8.0 * k as f64 / 400.0)
        .filter(|&a| !chain_unstable_by_hand(4, 1.0, 10.0, a))
        .collect();
    assert!(stable.is_empty(), "stable by hand at {stable:?}");
}

/// Study 2's averaging on a rigid body: a uniform rod of length L on
/// Kapitza's vibrating pivot, written as one `[[bodies]]` table, stands
/// upright for A² > 4 g L / 3 (2 g J/(m d), J = m L²/3 about the hinge,
/// d = L/2; a point mass's is 2 g l): the first-order threshold is that to
/// 1e-12, and at ε = 0.01 the exact (Floquet) edge is within 1e-3 of it.
#[test]
fn a_rod_on_a_vibrating_pivot_stands_above_the_rigid_bodys_threshold() {
    let params = [1.5, 0.01, 1.0, 1.0, 1.0]; // A, ε, m, L, g
    let (exact, first, _) = thresholds("physical_pendulum_body", &params, "A", 4.0);
    let closed_form = (4.0_f64 / 3.0).sqrt();
    assert!(
        (first - closed_form).abs() < 1e-12,
        "{first} not {closed_form}"
    );
    assert!((exact - closed_form).abs() < 1e-3, "exact edge {exact}");
}
