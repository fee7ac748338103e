//! Study 2: criterion (11), Theorem 2's O(1/ν) deviation, the exact system's
//! stability window and Theorem 3 with friction, each against an
//! independent computation.

use mechlab::analysis::averaging::deviation_against_frequency;
use mechlab::analysis::vibrational_stability::{
    linearization_eigenvalues, positive_definite, Stabilization,
};
use mechlab::models::double_pendulum::{self as model, Averaged, Exact, Params};
use mechlab::ode::{AnySystem, Method, SizedSystem};
use mechlab::studies::double_pendulum::{
    analyse_equilibrium, exact_multipliers, exact_stability_window, threshold_closed_form,
    EQUILIBRIA,
};

fn random_params(state: &mut u64) -> Params {
    let mut next = || {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        0.3 + 2.7 * ((*state >> 11) as f64 / (1u64 << 53) as f64)
    };
    Params {
        m1: next(),
        m2: next(),
        l1: next(),
        l2: next(),
        g: next(),
        a: 1.0,
        nu: 100.0,
        mu: 0.0,
    }
}

/// Criterion (11) against the direct test: the Hessian of the limiting
/// potential V + V_vibr (generated from the derived V_vibr, not from the
/// criterion) is positive definite just above a* and not just below.
#[test]
fn criterion_agrees_with_the_hessian_of_the_limiting_potential() {
    let mut state = 0x2545f4914f6cdd1du64;
    for _ in 0..200 {
        let params = random_params(&mut state);
        for phi in EQUILIBRIA {
            let analysis = analyse_equilibrium(&params, phi);
            let q = [phi.0, phi.1];
            let hessian = |a: f64| model::effective_potential_hessian(&q, &Params { a, ..params });
            match analysis.stabilization {
                Stabilization::AlreadyStable => {
                    assert_eq!(phi, (std::f64::consts::PI, std::f64::consts::PI));
                    assert!(positive_definite(&hessian(0.0)) && positive_definite(&hessian(7.0)));
                }
                Stabilization::Threshold { a_star, .. } => {
                    assert!(
                        positive_definite(&hessian(1.02 * a_star)),
                        "{params:?} {phi:?}"
                    );
                    assert!(
                        !positive_definite(&hessian(0.98 * a_star)),
                        "{params:?} {phi:?}"
                    );
                    let closed = threshold_closed_form(&params, phi).unwrap();
                    assert!(
                        (closed - a_star).abs() < 1e-9 * a_star,
                        "{closed} vs {a_star}"
                    );
                }
                Stabilization::Degenerate => panic!("no degenerate equilibrium expected"),
            }
        }
    }
}

/// Theorem 2: the maximal deviation of exact from averaged coordinates over a
/// fixed time falls like 1/ν (the scene's default run: t = 5, ν from 100 to
/// 10000, a = 5, from (0.2, −0.1, 0, 0)).
#[test]
fn deviation_falls_like_one_over_nu() {
    let frequencies: Vec<f64> = (0..8)
        .map(|k| 100.0 * 100f64.powf(k as f64 / 7.0))
        .collect();
    let params = Params::default();
    let systems = |nu: f64| {
        let p = Params { nu, ..params };
        let exact: Box<dyn AnySystem> = Box::new(SizedSystem(Exact { params: p }));
        let averaged: Box<dyn AnySystem> = Box::new(SizedSystem(Averaged { params: p }));
        (exact, averaged)
    };
    let result = deviation_against_frequency(
        Method::parse("dop853", 1e-11).unwrap(),
        &systems,
        &[0.2, -0.1, 0.0, 0.0],
        5.0,
        &frequencies,
        2,
    )
    .unwrap();
    for (fit, deviations) in result.fits.iter().zip(&result.max_deviation) {
        assert!((fit.slope + 1.0).abs() < 0.15, "slope {}", fit.slope);
        // ν × deviation stays bounded: within a factor 1.5 over two decades.
        let scaled: Vec<f64> = deviations
            .iter()
            .zip(&frequencies)
            .map(|(d, nu)| d * nu)
            .collect();
        let (lo, hi) = scaled
            .iter()
            .fold((f64::MAX, 0.0f64), |(l, h), x| (l.min(*x), h.max(*x)));
        assert!(hi < 1.5 * lo, "ν·deviation {scaled:?}");
    }
}

/// Theorem 3 and the stability window: at large ν the exact system's
/// verdict agrees with the averaged one just above and below a*, and the
/// window's lower edge tends to a* as ν grows.
#[test]
fn exact_floquet_verdict_follows_the_averaged_criterion() {
    let params = Params::default();
    for phi in &EQUILIBRIA[..3] {
        let Stabilization::Threshold { a_star, .. } =
            analyse_equilibrium(&params, *phi).stabilization
        else {
            panic!("{phi:?} should need vibration");
        };
        let at = |a: f64, nu: f64| {
            exact_multipliers(&Params { a, nu, ..params }, *phi, 1e-11)
                .unwrap()
                .0
        };
        assert!(at(1.1 * a_star, 400.0) < 1.0 + 1e-6, "{phi:?} above a*");
        assert!(at(0.9 * a_star, 400.0) > 1.0 + 1e-4, "{phi:?} below a*");
        let low = |nu: f64| {
            exact_stability_window(&Params { nu, ..params }, *phi, 3.0 * a_star, 60, 1e-10)
                .unwrap()
                .expect("a window exists")
                .0
        };
        let (e50, e200) = ((low(50.0) - a_star).abs(), (low(200.0) - a_star).abs());
        assert!(
            e200 < e50 && e200 < 0.01 * a_star,
            "{phi:?}: {e50} then {e200}"
        );
    }
}

/// With friction the averaged equilibrium's eigenvalues have negative real
/// parts; without, they lie on the imaginary axis.
#[test]
fn friction_makes_the_averaged_equilibrium_asymptotically_stable() {
    let y = [0.0, 0.0, 0.0, 0.0];
    for (mu, negative) in [(0.3, true), (0.0, false)] {
        let params = Params {
            mu,
            ..Params::default()
        };
        let eigenvalues = linearization_eigenvalues(&model::averaged_jacobian(&y, &params));
        for (re, im) in eigenvalues {
            if negative {
                assert!(re < -1e-3, "μ = {mu}: {re} + {im}i");
            } else {
                assert!(re.abs() < 1e-9 && im.abs() > 1e-3, "μ = 0: {re} + {im}i");
            }
        }
    }
}
