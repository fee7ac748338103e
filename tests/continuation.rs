//! Continuation of periodic orbits in a parameter: branches against closed
//! forms, bifurcations against independent computations (the exact Floquet
//! window by bisection, harmonic balance, hand-written equations), the
//! period-doubling cascade of Duffing's oscillator, and named errors.

use mechlab::analysis::continuation::{
    continuation, BifurcationKind, ContinuationError, ContinuationSettings, Criticality,
};
use mechlab::analysis::Refusal;
use mechlab::models;
use mechlab::ode::Method;
use mechlab::registry::ParameterError;
use mechlab_test_models::forced_oscillator::MODEL as FORCED;
use nalgebra::{DMatrix, DVector};

fn settings(parameter: &str, to: f64, start: &[f64]) -> ContinuationSettings {
    crate::common::continuation_settings(parameter, to, start, Method::Taylor { tol: 1e-13 })
}

/// Parameter values of the forced oscillator: c, b, F, ω.
fn forced(c: f64, b: f64, f: f64, omega: f64) -> Vec<f64> {
    vec![c, b, f, omega]
}

/// The linear oscillator x'' + c x' + x = F cos ωt has the periodic orbit
/// x = a cos ωt + b sin ωt, a = F(1 − ω²)/D, b = F c ω/D,
/// D = (1 − ω²)² + (cω)²: every point of the branch through resonance
/// (ω from 0.5 to 1.5, amplitude up to 10) lies on it to 1e-10, and a
/// linear map has no bifurcation.
#[test]
fn the_linear_oscillator_is_followed_through_resonance_on_its_closed_form() {
    let (c, f) = (0.01, 0.1);
    let result = continuation(
        &FORCED,
        &forced(c, 0.0, f, 0.5),
        &settings("omega", 1.5, &[0.0, 0.0]),
    )
    .unwrap();
    assert!(result.bifurcations.is_empty(), "{:?}", result.bifurcations);
    let branch = &result.branches[0];
    assert!(branch.points.len() > 50);
    let mut largest = 0.0f64;
    for point in &branch.points {
        let w = point.parameter;
        let d = (1.0 - w * w).powi(2) + (c * w).powi(2);
        let (a, b) = (f * (1.0 - w * w) / d, f * c * w / d);
        let error = (point.state[0] - a)
            .abs()
            .max((point.state[1] - b * w).abs());
        assert!(
            error < 1e-10,
            "ω = {w}: {:?} against ({a}, {})",
            point.state,
            b * w
        );
        largest = largest.max(a.hypot(b));
    }
    assert!(largest > 9.0, "resonance reached: amplitude {largest}");
}

/// Kapitza's upright (0, 0) is a solution for every amplitude: the branch
/// stays there, and its two stability changes, a branch point (multiplier
/// +1: the tilted orbits) and a period doubling (−1), are the exact
/// system's Floquet window found by bisection on the spectral radius, to
/// 1e-9. Switching at the branch point follows the two tilted orbits,
/// mirror images of each other.
#[test]
fn kapitzas_upright_changes_stability_at_the_exact_floquet_edges() {
    use mechlab::analysis::stability::{stability, Settings};
    let model = models::by_name("kapitza").unwrap();
    let params = vec![0.5, 0.1, 0.0];
    let exact = stability(
        model,
        &params,
        &Settings {
            amplitude: "A".into(),
            a_max: Some(6.0),
            samples: 120,
            edge_tolerance: 1e-12,
            method: Method::Taylor { tol: 1e-13 },
            max_windows: mechlab::analysis::stability::MAX_WINDOWS,
            accuracy: None,
            first: Default::default(),
        },
    )
    .unwrap();
    let upright = exact.equilibria.iter().find(|e| e.q[0] == 0.0).unwrap();
    let [Some(low), Some(high)] = upright.exact_window.unwrap() else {
        panic!("{upright:?}")
    };
    let mut s = settings("A", 5.0, &[0.0, 0.0]);
    s.switch_branch_points = true;
    let result = continuation(model, &params, &s).unwrap();
    assert!(!result.dissipative);
    for point in &result.branches[0].points {
        assert!(point.state.iter().all(|x| x.abs() < 1e-12), "{point:?}");
    }
    let on_upright: Vec<_> = result
        .bifurcations
        .iter()
        .filter(|b| b.branch == 0)
        .collect();
    assert_eq!(on_upright.len(), 2, "{on_upright:?}");
    assert_eq!(on_upright[0].kind, BifurcationKind::BranchPoint);
    assert!(
        (on_upright[0].parameter - low).abs() < 1e-9,
        "{} {low}",
        on_upright[0].parameter
    );
    assert_eq!(on_upright[1].kind, BifurcationKind::PeriodDoubling);
    assert!(
        (on_upright[1].parameter - high).abs() < 1e-9,
        "{} {high}",
        on_upright[1].parameter
    );
    // The tilted orbits: two branches from the branch point, q of opposite
    // signs at equal amplitudes.
    let tilted: Vec<_> = result
        .branches
        .iter()
        .filter(|b| b.born_at == Some(0))
        .collect();
    assert_eq!(tilted.len(), 2);
    let (a, b) = (&tilted[0].points[5], &tilted[1].points[5]);
    assert!((a.parameter - b.parameter).abs() < 1e-9);
    assert!(
        (a.state[0] + b.state[0]).abs() < 1e-9 && a.state[0].abs() > 1e-3,
        "{a:?} {b:?}"
    );

    // Past the period doubling, the branch of period 2 breaks its symmetry
    // at a branch point where the corrector's matrix is singular: located
    // all the same (on the chord between trials), its multipliers at +1 to
    // the square root of the monodromy's error (a double multiplier splits
    // as its square root: 1.5e-6 from errors of about 1e-12; below 1e-6
    // before the tangent recurrences took the Jacobian form, whose
    // rounding differs).
    s.to = 6.0;
    s.max_period = 2;
    let result = continuation(model, &params, &s).unwrap();
    let on_doubled: Vec<_> = result
        .bifurcations
        .iter()
        .filter(|b| b.period == 2 && b.kind == BifurcationKind::BranchPoint)
        .collect();
    assert_eq!(on_doubled.len(), 1, "{:?}", result.bifurcations);
    assert!(
        on_doubled[0].located && on_doubled[0].residual < 3e-6,
        "{:?}",
        on_doubled[0]
    );
}

/// Duffing's x'' + δx' − x + x³ = γ cos ωt (δ = 0.3, ω = 1.2), the orbit in
/// the right well: its period doublings follow one another on the branches
/// switched to, each with a multiplier −1 to 1e-9; the ratios of
/// successive intervals approach Feigenbaum's δ = 4.6692 (within 5 %). The
/// branch born at the first doubling is a fixed point of P² and not of P,
/// checked with hand-written equations and RK4.
#[test]
fn duffings_cascade_of_period_doublings_gives_feigenbaums_ratio() {
    let model = models::by_name("duffing").unwrap();
    let mut s = settings("gamma", 0.3, &[1.0, 0.0]);
    s.max_period = 16;
    s.max_branches = 6;
    s.points = 600;
    s.method = Method::Taylor { tol: 1e-12 };
    let result = continuation(model, &model.dynamic.defaults(), &s).unwrap();
    assert!(result.dissipative);
    assert!(result.cascade.len() >= 4, "{:?}", result.cascade);
    // Up to period 8: the monodromy of P^16 is a product of 16 matrices
    // contracting by 1e-11, whose multiplier −1 holds only to 1e-8.
    for b in result
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::PeriodDoubling)
    {
        assert!(b.located && (b.period > 8 || b.residual < 1e-9), "{b:?}");
    }
    // A cascade of soft onsets: each new branch takes over the stability
    // the old one loses.
    for b in result
        .bifurcations
        .iter()
        .filter(|b| b.switched_to.is_some())
    {
        assert_eq!(b.criticality, Some(Criticality::Supercritical), "{b:?}");
    }
    let feigenbaum = 4.669_201_6;
    for ratio in &result.feigenbaum_ratios[..2] {
        assert!(
            (ratio / feigenbaum - 1.0).abs() < 0.05,
            "{:?}",
            result.feigenbaum_ratios
        );
    }
    let doubled = &result.branches[1];
    assert_eq!(doubled.period, 2);
    let point = &doubled.points[doubled.points.len() / 2];
    let gamma = point.parameter;
    let y = [point.state[0], point.state[1]];
    let once = duffing_period(y, gamma);
    let twice = duffing_period(once, gamma);
    let distance = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    assert!(
        distance(twice, y) < 1e-8,
        "P²(y) − y = {}",
        distance(twice, y)
    );
    assert!(distance(once, y) > 1e-2, "P(y) − y = {}", distance(once, y));
}

/// One period of Duffing's oscillator (δ = 0.3, ω = 1.2), written out and
/// integrated by RK4 with 20 000 steps.
fn duffing_period(mut y: [f64; 2], gamma: f64) -> [f64; 2] {
    let (delta, omega) = (0.3, 1.2);
    let f = |t: f64, y: [f64; 2]| {
        [
            y[1],
            y[0] - y[0].powi(3) - delta * y[1] + gamma * (omega * t).cos(),
        ]
    };
    rk4(&f, &mut y, 2.0 * std::f64::consts::PI / omega, 20_000);
    y
}

fn rk4(f: &dyn Fn(f64, [f64; 2]) -> [f64; 2], y: &mut [f64; 2], end: f64, steps: usize) {
    let h = end / steps as f64;
    let add = |y: [f64; 2], k: [f64; 2], s: f64| [y[0] + s * k[0], y[1] + s * k[1]];
    for i in 0..steps {
        let t = i as f64 * h;
        let k1 = f(t, *y);
        let k2 = f(t + h / 2.0, add(*y, k1, h / 2.0));
        let k3 = f(t + h / 2.0, add(*y, k2, h / 2.0));
        let k4 = f(t + h, add(*y, k3, h));
        for j in 0..2 {
            y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
    }
}

/// The hardening oscillator x'' + c x' + x + b x³ = F cos ωt: its frequency
/// response bends right and folds. The fold the continuation locates on
/// the upper branch is where harmonic balance (24 harmonics, collocation,
/// exact to far below the tolerance for this analytic orbit) has ω
/// stationary along its own branch, parametrised by x(0).
#[test]
fn the_hardening_fold_is_where_harmonic_balance_turns() {
    let (c, b, f) = (0.2, 0.5, 0.3);
    let result = continuation(
        &FORCED,
        &forced(c, b, f, 0.6),
        &settings("omega", 2.0, &[0.0, 0.0]),
    )
    .unwrap();
    let folds: Vec<_> = result
        .bifurcations
        .iter()
        .filter(|x| x.kind == BifurcationKind::Fold)
        .collect();
    assert_eq!(folds.len(), 2, "{:?}", result.bifurcations);
    for fold in folds {
        assert!(fold.located && fold.residual < 1e-5, "{fold:?}");
        let x0 = fold.state[0];
        let balance = HarmonicBalance {
            c,
            b,
            f,
            harmonics: 24,
        };
        let h = 1e-4;
        let omegas: Vec<f64> = [-h, 0.0, h]
            .iter()
            .map(|d| balance.frequency_at(x0 + d, fold.state[1], fold.parameter))
            .collect();
        // The vertex of the parabola through the three points.
        let curvature = omegas[0] - 2.0 * omegas[1] + omegas[2];
        let shift = 0.5 * h * (omegas[0] - omegas[2]) / curvature;
        let vertex = omegas[1] - 0.25 * (omegas[0] - omegas[2]) * shift / h;
        assert!(
            shift.abs() < 1e-5,
            "x(0) of the balance's turning point off by {shift}"
        );
        assert!(
            (vertex - fold.parameter).abs() < 1e-8,
            "fold at ω = {}, harmonic balance turns at {vertex}",
            fold.parameter
        );
    }
}

/// Harmonic balance by collocation for x'' + c x' + x + b x³ = F cos ωt:
/// x(t) = a₀ + Σ aₙ cos nωt + bₙ sin nωt, the equation imposed at 2N + 1
/// equally spaced times of a period.
struct HarmonicBalance {
    c: f64,
    b: f64,
    f: f64,
    harmonics: usize,
}

impl HarmonicBalance {
    /// The frequency at which the periodic orbit has x(0) = x0: Newton on
    /// the collocation equations and x(0) = x0, unknowns the coefficients
    /// and ω, from ω = `omega` and the first harmonic through (x0, v0).
    fn frequency_at(&self, x0: f64, v0: f64, omega: f64) -> f64 {
        let n = 2 * self.harmonics + 1;
        let mut u = DVector::zeros(n + 1);
        u[1] = x0;
        u[2] = v0 / omega;
        u[n] = omega;
        for _ in 0..60 {
            let r = self.residual(&u, x0);
            let mut jacobian = DMatrix::zeros(n + 1, n + 1);
            for k in 0..=n {
                let mut v = u.clone();
                let h = 1e-7 * (1.0 + u[k].abs());
                v[k] += h;
                let column = (self.residual(&v, x0) - &r) / h;
                jacobian.set_column(k, &column);
            }
            let step = jacobian.lu().solve(&r).expect("regular");
            u -= &step;
            if step.norm() < 1e-14 {
                break;
            }
        }
        assert!(self.residual(&u, x0).norm() < 1e-11);
        u[n]
    }

    fn residual(&self, u: &DVector<f64>, x0: f64) -> DVector<f64> {
        let n = 2 * self.harmonics + 1;
        let omega = u[n];
        let mut r = DVector::zeros(n + 1);
        for j in 0..n {
            let phase = std::f64::consts::TAU * j as f64 / n as f64;
            let (mut x, mut v, mut a) = (u[0], 0.0, 0.0);
            for h in 1..=self.harmonics {
                let k = h as f64;
                let (cos, sin) = ((k * phase).cos(), (k * phase).sin());
                let (ca, sb) = (u[2 * h - 1], u[2 * h]);
                x += ca * cos + sb * sin;
                v += k * omega * (-ca * sin + sb * cos);
                a -= (k * omega).powi(2) * (ca * cos + sb * sin);
            }
            r[j] = a + self.c * v + x + self.b * x.powi(3) - self.f * phase.cos();
        }
        let at_zero: f64 = u[0] + (1..=self.harmonics).map(|h| u[2 * h - 1]).sum::<f64>();
        r[n] = at_zero - x0;
        r
    }
}

/// Bad requests get named errors: a parameter the model lacks, a contact
/// model, a start at a singular point of the model, a start where P = I (every state a fixed point:
/// the Jacobian P' − I is singular), and a step too long for Newton that
/// may not shrink.
#[test]
fn bad_requests_are_named() {
    let duffing = models::by_name("duffing").unwrap();
    let defaults = duffing.dynamic.defaults();
    let err = continuation(duffing, &defaults, &settings("kappa", 1.0, &[1.0])).unwrap_err();
    assert!(
        matches!(
            err,
            ContinuationError::Refused(Refusal::Parameter(ParameterError::Unknown { .. }))
        ),
        "{err}"
    );
    assert!(err.to_string().contains("gamma"), "{err}");

    let contact = models::by_name("painleve_klein").unwrap();
    let err = continuation(
        contact,
        &contact.dynamic.defaults(),
        &settings("mu", 1.0, &[]),
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            ContinuationError::Refused(mechlab::analysis::Refusal::ContactModel { .. })
        ),
        "{err}"
    );

    let err = continuation(
        &FORCED,
        &forced(0.0, 0.0, 0.0, 1.0),
        &settings("F", 1.0, &[0.3]),
    )
    .unwrap_err();
    assert!(
        matches!(err, ContinuationError::SingularJacobian { .. }),
        "{err}"
    );

    let mut s = settings("gamma", 0.3, &[1.0, 0.0]);
    (s.step, s.min_step, s.max_step) = (50.0, 50.0, 50.0);
    let err = continuation(duffing, &defaults, &s).unwrap_err();
    assert!(
        matches!(err, ContinuationError::StepCollapse { .. }),
        "{err}"
    );

    // The elastic pendulum's spring at length 0, a singular point of its
    // polar coordinates: the start's orbit cannot be followed, and the
    // error says where.
    let elastic = models::by_name("elastic_pendulum").unwrap();
    let err = continuation(
        elastic,
        &elastic.dynamic.defaults(),
        &settings("a", 3.0, &[0.0]),
    )
    .unwrap_err();
    assert!(matches!(err, ContinuationError::Start { .. }), "{err}");
    assert!(err.to_string().contains("elastic_pendulum"), "{err}");

    let mut s = settings("gamma", 0.3, &[1.0, 0.0]);
    s.min_step = 0.0;
    let err = continuation(duffing, &defaults, &s).unwrap_err();
    assert!(
        matches!(err, ContinuationError::Refused(Refusal::Setting { .. })),
        "{err}"
    );
}

/// A pendulum whose pivot runs round an ellipse (vertical semi-axis A,
/// horizontal a, both times ε): the horizontal component moves the upright,
/// so `stability` replaces it by the periodic orbit near it and finds that
/// orbit's window in A by continuation. Its lower edge tends to the
/// averaged threshold √(2 + a²) as ε² (the gap shrinks by about 4 when ε
/// halves).
#[test]
fn the_moved_uprights_window_tends_to_the_averaged_threshold_as_eps_squared() {
    use mechlab::analysis::stability::{stability, Settings};
    use mechlab_test_models::elliptic_pendulum::MODEL as ELLIPTIC;
    let a = 0.5;
    let threshold = (2.0f64 + a * a).sqrt();
    let gaps: Vec<f64> = [0.04, 0.02]
        .iter()
        .map(|&eps| {
            let found = stability(
                &ELLIPTIC,
                &[2.0, a, eps],
                &Settings {
                    amplitude: "A".into(),
                    a_max: Some(4.0),
                    samples: 40,
                    edge_tolerance: 1e-10,
                    method: Method::Taylor { tol: 1e-12 },
                    max_windows: mechlab::analysis::stability::MAX_WINDOWS,
                    accuracy: None,
                    first: Default::default(),
                },
            )
            .unwrap();
            let upright = found
                .moved_by_vibration
                .iter()
                .find(|m| m.q[0].abs() < 1e-9)
                .expect("the upright is moved");
            assert!(upright.periodic_orbit.is_some(), "{upright:?}");
            let window = upright.exact_window.expect("a window");
            window[0].unwrap() - threshold
        })
        .collect();
    assert!(gaps[0].abs() < 2e-3, "{gaps:?}");
    let ratio = gaps[0] / gaps[1];
    assert!((3.0..5.0).contains(&ratio), "{gaps:?}: ratio {ratio}");
}

/// A model without a fast phase has its equilibria continued. The bead on
/// a spinning hoop: the bottom loses its stability at ω = 1 by a pitchfork
/// (an eigenvalue of the Jacobian through 0), located to 1e-10, and the
/// two branches switched to are cos θ = 1/ω² to 1e-9.
#[test]
fn the_spinning_hoops_pitchfork_and_its_branches() {
    use mechlab_test_models::rotating_hoop::MODEL as HOOP;
    let mut s = settings("omega", 2.0, &[0.0, 0.0]);
    s.switch_branch_points = true;
    let result = continuation(&HOOP, &[0.5, 0.2], &s).unwrap();
    assert!(result.dissipative && result.diagram.is_none());
    let pitchfork: Vec<_> = result
        .bifurcations
        .iter()
        .filter(|b| b.branch == 0)
        .collect();
    assert_eq!(pitchfork.len(), 1, "{:?}", result.bifurcations);
    assert_eq!(pitchfork[0].kind, BifurcationKind::BranchPoint);
    assert!(
        (pitchfork[0].parameter - 1.0).abs() < 1e-10,
        "{:?}",
        pitchfork[0]
    );
    assert!(pitchfork[0].residual < 1e-8, "{:?}", pitchfork[0]);
    for p in &result.branches[0].points {
        if (p.parameter - 1.0).abs() > 1e-6 {
            assert_eq!(p.stable, p.parameter < 1.0, "{p:?}");
        }
    }
    let off_axis: Vec<_> = result
        .branches
        .iter()
        .filter(|b| b.born_at == Some(0))
        .collect();
    assert_eq!(off_axis.len(), 2);
    let signs: Vec<f64> = off_axis
        .iter()
        .map(|b| b.points[3].state[0].signum())
        .collect();
    assert_eq!(signs[0], -signs[1], "one on each side");
    for branch in off_axis {
        for p in &branch.points[1..] {
            let w = p.parameter;
            assert!((p.state[0].cos() - 1.0 / (w * w)).abs() < 1e-9, "{p:?}");
            assert!(p.stable, "off the axis the bead rests stably: {p:?}");
        }
    }
}

/// Van der Pol's rest state loses its stability at μ = 0 by a Hopf point:
/// located to 1e-10, the pair of eigenvalues on the imaginary axis (±i)
/// there.
#[test]
fn van_der_pols_rest_state_has_its_hopf_point_at_zero() {
    use mechlab_test_models::van_der_pol::MODEL as VDP;
    let result = continuation(&VDP, &[-0.5], &settings("mu", 0.5, &[0.0, 0.0])).unwrap();
    assert_eq!(result.bifurcations.len(), 1, "{:?}", result.bifurcations);
    let hopf = &result.bifurcations[0];
    assert_eq!(hopf.kind, BifurcationKind::Hopf);
    assert!(hopf.parameter.abs() < 1e-10, "{hopf:?}");
    assert!(hopf.residual < 1e-10, "{hopf:?}");
    for (re, im) in &hopf.multipliers {
        assert!(
            re.abs() < 1e-10 && (im.abs() - 1.0).abs() < 1e-10,
            "{hopf:?}"
        );
    }
}

/// A bifurcation's stated error holds: Duffing's right-well orbit doubles
/// its period where a hand-written RK4, Newton and Jury bisection put it;
/// located by runs at loose tolerances, the parameter is off by what its
/// stated error (twice the distance to the same doubling located at a
/// hundredth of the tolerance) bounds, and within 100 times it.
#[test]
fn a_period_doublings_stated_error_bounds_its_error() {
    use mechlab::analysis::continuation::{continuation, BifurcationKind};
    let model = crate::common::model_of("duffing");
    let values = model.dynamic.defaults();
    let names = model.info.parameter_names;
    let mut params = values.clone();
    params[names.iter().position(|n| *n == "gamma").unwrap()] = 0.2;
    let reference = crate::common::duffing_period_doubling(0.3, 1.2, (0.2, 0.28), 4000);
    for tol in [1e-6, 1e-7, 1e-8] {
        let method = Method::Dop853 {
            rtol: tol,
            atol: tol,
        };
        let settings = crate::common::continuation_settings("gamma", 0.28, &[1.0, 0.0], method);
        let result = continuation(model, &params, &settings).unwrap();
        let doubling = result
            .bifurcations
            .iter()
            .find(|b| b.kind == BifurcationKind::PeriodDoubling)
            .expect("a period doubling");
        let stated = doubling.parameter_error.expect("an error");
        let truth = (doubling.parameter - reference).abs();
        eprintln!(
            "tol {tol:e}: γ = {} off by {truth:.2e}, stated {stated:.2e}",
            doubling.parameter
        );
        assert!(
            truth <= stated,
            "tol {tol:e}: off by {truth:e}, stated {stated:e}"
        );
        assert!(
            stated <= 100.0 * truth.max(1e-9),
            "tol {tol:e}: off by {truth:e}, stated {stated:e}"
        );
    }
}

/// Asked for an accuracy, a continuation is run again a hundredfold tighter
/// until every bifurcation's stated error is within it: from DOP853 at
/// 1e-6, `accuracy` 1e-9 is reached at 1e-8, and the period doubling is
/// then within 1e-9 of the hand-written reference.
#[test]
fn a_continuation_asked_for_an_accuracy_tightens_until_its_bifurcations_errors_are_within_it() {
    use mechlab::analysis::continuation::{continuation, BifurcationKind, ContinuationSettings};
    let model = crate::common::model_of("duffing");
    let mut params = model.dynamic.defaults();
    let names = model.info.parameter_names;
    params[names.iter().position(|n| *n == "gamma").unwrap()] = 0.2;
    let method = Method::Dop853 {
        rtol: 1e-6,
        atol: 1e-6,
    };
    let settings = ContinuationSettings {
        accuracy: Some(1e-9),
        ..crate::common::continuation_settings("gamma", 0.28, &[1.0, 0.0], method)
    };
    let result = continuation(model, &params, &settings).unwrap();
    let said = result.accuracy.clone().unwrap();
    assert!(
        said.contains("1e-9 reached") && said.contains("1e-8"),
        "{said}"
    );
    let doubling = result
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::PeriodDoubling)
        .expect("a period doubling");
    assert!(doubling.parameter_error.unwrap() <= 1e-9);
    let reference = crate::common::duffing_period_doubling(0.3, 1.2, (0.2, 0.28), 4000);
    assert!(
        (doubling.parameter - reference).abs() <= 1e-9,
        "{} against {reference}",
        doubling.parameter
    );
}

/// A branch's states' stated error against the linear oscillator's closed
/// form (ω from 0.5 to 1.5 through resonance) at DOP853 1e-6, 1e-8 and
/// Taylor 1e-8: it bounds every point's distance, within 100 times the
/// largest.
#[test]
fn a_branchs_stated_state_error_bounds_its_distance_to_the_closed_form() {
    let (c, f) = (0.01, 0.1);
    for (name, tol) in [("dop853", 1e-6), ("dop853", 1e-8), ("taylor", 1e-8)] {
        let settings = crate::common::continuation_settings(
            "omega",
            1.5,
            &[0.0, 0.0],
            Method::parse(name, tol).unwrap(),
        );
        let result = continuation(&FORCED, &forced(c, 0.0, f, 0.5), &settings).unwrap();
        let branch = &result.branches[0];
        let largest = (branch.points.iter())
            .map(|point| {
                let w = point.parameter;
                let d = (1.0 - w * w).powi(2) + (c * w).powi(2);
                let (a, b) = (f * (1.0 - w * w) / d, f * c * w / d);
                (point.state[0] - a)
                    .abs()
                    .max((point.state[1] - b * w).abs())
            })
            .fold(0.0, f64::max);
        let stated = branch.state_error.unwrap();
        println!("{name} {tol:e}: stated {stated:.2e}, largest distance {largest:.2e}");
        assert!(
            largest <= stated && stated <= 100.0 * largest,
            "{name} {tol:e}"
        );
    }
}
