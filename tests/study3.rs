//! Study 3: the generated contact model against the hand-written equations,
//! and the stick–slip integrator on the worked example.

use mechlab::contact::{ContactError, HybridRun, Mode, Outcome, Smooth, StickSlip};
use mechlab::models::painleve_klein::{self as model, Contacts, Params};
use mechlab::ode::Method;
use mechlab::ode::System;
use mechlab::studies::painleve::{phi_slope, reduced, rigid_acceleration, rigid_rod_roots};
use mechlab::studies::painleve::{rod, worked_example_start};

fn random(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// G and N from the model file equal x1'' = X1 − R cos φ − …, x2'' = X2 +
/// R cos φ − …, N1 = R sin φ − Y1, N2 = −Y2 − R sin φ (docs/studies.md,
/// sliding equations) at random states and parameters.
#[test]
fn generated_forces_match_the_hand_written_equations() {
    let mut s = 0x1234_5678_9abc_def1u64;
    for _ in 0..500 {
        let p = Params {
            d: 0.3 + 0.5 * random(&mut s),
            l: 1.0 + 0.5 * random(&mut s),
            X1: 4.0 * random(&mut s) - 2.0,
            Y1: 4.0 * random(&mut s) - 2.0,
            X2: 4.0 * random(&mut s) - 2.0,
            Y2: 4.0 * random(&mut s) - 2.0,
            k: 0.5 + random(&mut s),
            nu: 0.5 + random(&mut s),
            eps: 0.05 + 0.2 * random(&mut s),
            ..Params::default()
        };
        let y = [
            2.0 * random(&mut s),
            2.0 * random(&mut s) - 2.0,
            4.0 * random(&mut s) - 2.0,
            4.0 * random(&mut s) - 2.0,
        ];
        let r = rod(&y, &p);
        let g = model::free_forces(&y, &p);
        let n = model::normal_forces(&y, &p);
        let expected_g = [p.X1 - r.reaction * r.cos_phi, p.X2 + r.reaction * r.cos_phi];
        let expected_n = [
            r.reaction * r.sin_phi - p.Y1,
            -p.Y2 - r.reaction * r.sin_phi,
        ];
        for i in 0..2 {
            let scale = 1.0 + r.reaction.abs() + p.X1.abs() + p.Y1.abs() + p.Y2.abs();
            assert!(
                (g[i] - expected_g[i]).abs() < 1e-10 * scale,
                "G{i}: {} vs {}",
                g[i],
                expected_g[i]
            );
            assert!(
                (n[i] - expected_n[i]).abs() < 1e-10 * scale,
                "N{i}: {} vs {}",
                n[i],
                expected_n[i]
            );
        }
        assert_eq!(model::masses(&p), [1.0, 1.0]);
    }
}

fn run(x2: f64, params: Params, tol: f64, t_end: f64, times: &[f64]) -> HybridRun<2, 4> {
    StickSlip::new(Method::parse("dop853", tol).unwrap())
        .run(
            &Contacts { params },
            0.0,
            &worked_example_start(x2),
            t_end,
            times,
        )
        .unwrap()
}

/// x2(0) = −0.78: point 2 stops and stays (3a), point 1 stops at once but
/// cannot stick and reverses (4b), then stops for good (4a): rest.
/// The forces depend on the positions only through x1 − x2: the generated
/// code must not cancel catastrophically far from the origin.
#[test]
fn generated_forces_are_translation_invariant() {
    let p = Params {
        eps: 1e-3,
        ..Params::default()
    };
    let y = [0.3, -0.3, 1.0, 2.0];
    for shift in [1e2, 1e4, 1e6] {
        let moved = [y[0] + shift, y[1] + shift, y[2], y[3]];
        for (a, b) in [
            (model::free_forces(&y, &p), model::free_forces(&moved, &p)),
            (
                model::normal_forces(&y, &p),
                model::normal_forces(&moved, &p),
            ),
        ] {
            for i in 0..2 {
                assert!(
                    (a[i] - b[i]).abs() < 1e-6 * a[i].abs().max(1.0),
                    "shift {shift}: {} vs {}",
                    a[i],
                    b[i]
                );
            }
        }
    }
}

#[test]
fn worked_example_friction_impact_stops_reverses_and_rests() {
    let r = run(-0.78, Params::default(), 1e-10, 6.0, &[]);
    let cases: Vec<(usize, &str, Mode, Mode)> = r
        .switches
        .iter()
        .map(|s| (s.contact, s.case.as_str(), s.from, s.to))
        .collect();
    assert_eq!(
        cases,
        [
            (1, "3a", Mode::Slide(1), Mode::Stick),
            (0, "4b", Mode::Slide(1), Mode::Slide(-1)),
            (0, "4a", Mode::Slide(-1), Mode::Stick),
        ]
    );
    assert_eq!(r.outcome, Outcome::Rest);
    let (t1, t2) = (r.switches[0].t, r.switches[1].t);
    assert!(
        t2 - t1 < 0.01 && t2 > t1,
        "the reversal follows the stop at once"
    );
    // Point 2 did not move after it stuck.
    assert_eq!(r.y[1], r.switches[0].y[1]);
}

/// The regular case (x2(0) = −0.65 at ε = 0.1, inside the basin of the
/// stable equilibrium; for smaller ε a start as deep inside it, δ(0) =
/// 1.2 ε² R*/k): no switch, and a constant acceleration that tends to the
/// rigid rod's at its stable root R* as ε → 0 (the rod's angle differs from
/// φ0 by O(ε²)).
#[test]
fn worked_example_regular_case_reaches_the_rigid_rod_acceleration() {
    let deviation = |eps: f64| {
        let params = Params {
            eps,
            ..Params::default()
        };
        let delta0 = 0.03 * (eps / 0.1) * (eps / 0.1);
        let x2 = -((params.l + delta0).powi(2) - params.d * params.d).sqrt();
        let r = run(x2, params, 1e-10, 6.0, &[]);
        assert!(r.switches.is_empty());
        assert_eq!(r.outcome, Outcome::Moving);
        // Two roots: R* = 2.785 where Φ rises (stable) and one where it falls.
        let q = reduced(&params);
        let roots = rigid_rod_roots(1.0, &q);
        let stable: Vec<f64> = roots
            .into_iter()
            .filter(|r| phi_slope(*r, 1.0, &q) > 0.0)
            .collect();
        assert_eq!(stable.len(), 1);
        let expected = rigid_acceleration(stable[0], 1.0, &params);
        let f = Smooth {
            model: &Contacts { params },
            modes: r.modes,
        }
        .rhs(r.t, &r.y);
        // Both points accelerate alike: the rod no longer deforms.
        assert!((f[2] - f[3]).abs() < 1e-5, "{} vs {}", f[2], f[3]);
        let rod_force = rod(&r.y, &params).reaction;
        (
            (f[2] - expected).abs() / expected,
            (rod_force - stable[0]).abs() / stable[0],
        )
    };
    let (coarse, fine) = (deviation(0.1), deviation(0.03));
    assert!(
        fine.0 < coarse.0 / 5.0 && fine.0 < 0.01,
        "{coarse:?} {fine:?}"
    );
    assert!(
        fine.1 < coarse.1 / 5.0 && fine.1 < 0.01,
        "{coarse:?} {fine:?}"
    );
}

/// Switch times converge as the tolerance tightens.
#[test]
fn event_times_converge_with_the_tolerance() {
    let reference = run(-0.78, Params::default(), 1e-13, 6.0, &[]);
    let error = |tol: f64| {
        let r = run(-0.78, Params::default(), tol, 6.0, &[]);
        assert_eq!(r.switches.len(), reference.switches.len());
        r.switches
            .iter()
            .zip(&reference.switches)
            .map(|(a, b)| (a.t - b.t).abs())
            .fold(0.0, f64::max)
    };
    let (e6, e8, e10) = (error(1e-6), error(1e-8), error(1e-10));
    assert!(e10 < e8 && e8 < e6, "{e6} {e8} {e10}");
    assert!(e10 < 1e-8, "{e10}");
}

/// A point stuck while the other slides for a long time stays exactly where it stuck.
#[test]
fn a_long_stuck_contact_does_not_drift() {
    // A very rough second guide pressed hard, and a frictionless first one:
    // point 2 sticks, point 1 oscillates on the rod (reversing at every stop).
    let params = Params {
        mu1: 0.0,
        mu2: 20.0,
        Y2: -10.0,
        ..Params::default()
    };
    let r = run(-0.78, params, 1e-10, 5.0, &[]);
    assert!(r.switches.len() > 5, "point 1 reverses again and again");
    let stick = r
        .switches
        .iter()
        .find(|s| s.contact == 1 && s.to == Mode::Stick)
        .expect("point 2 sticks");
    assert!(r.t == 5.0 && r.modes[1] == Mode::Stick && r.modes[0] != Mode::Stick);
    assert!(
        r.switches.iter().filter(|s| s.contact == 1).count() == 1,
        "point 2 sticks once"
    );
    assert_eq!(r.y[1], stick.y[1]);
    assert_eq!(r.y[3], 0.0);
}

/// The chattering guard ends a run with the promised error, never a hang.
#[test]
fn too_many_switches_in_a_short_window_is_an_error() {
    let mut settings = StickSlip::new(Method::parse("dop853", 1e-10).unwrap());
    settings.chatter_limit = 1;
    settings.chatter_window = 1.0;
    let result = settings.run(
        &Contacts {
            params: Params::default(),
        },
        0.0,
        &worked_example_start(-0.78),
        6.0,
        &[],
    );
    assert!(
        matches!(result, Err(ContactError::Chattering { .. })),
        "{result:?}"
    );
}

/// Without friction the rigid rod has one root, and the deformable rod
/// settles to it from inside and outside the worked example's basin.
#[test]
fn frictionless_guides_have_one_globally_attracting_equilibrium() {
    let params = Params {
        mu1: 0.0,
        mu2: 0.0,
        ..Params::default()
    };
    let q = reduced(&params);
    for sigma in [1.0, -1.0] {
        let roots = rigid_rod_roots(sigma, &q);
        assert_eq!(roots.len(), 1);
        assert!((roots[0] - q.x_star / 2.0).abs() < 1e-12);
    }
    // The deformable rod's equilibrium: 2 R cos φ = X1 − X2 (φ differs from φ0 by O(ε²)).
    for x2 in [-0.5, -0.65, -0.78, -0.95] {
        let r = run(x2, params, 1e-10, 8.0, &[]);
        let rod = rod(&r.y, &params);
        let balance = 2.0 * rod.reaction * rod.cos_phi - (params.X1 - params.X2);
        assert!(
            balance.abs() < 1e-6,
            "x2(0) = {x2}: 2R cos φ − (X1 − X2) = {balance}"
        );
        assert!(
            (rod.reaction - q.x_star / 2.0).abs() < 0.1 * q.x_star,
            "R = {}",
            rod.reaction
        );
    }
}

/// Deliverable 3.2: in the regular case (one root, not at a kink) Φ'(R*) > 0.
#[test]
fn phi_rises_through_a_regular_root() {
    let mut s = 0xfeed_beef_1234_5678u64;
    let mut regular = 0;
    for _ in 0..5000 {
        let p = Params {
            X1: 8.0 * random(&mut s) - 4.0,
            Y1: 8.0 * random(&mut s) - 4.0,
            X2: 8.0 * random(&mut s) - 4.0,
            Y2: 8.0 * random(&mut s) - 4.0,
            mu1: 3.0 * random(&mut s),
            mu2: 3.0 * random(&mut s),
            ..Params::default()
        };
        let q = reduced(&p);
        for sigma in [1.0, -1.0] {
            let roots = rigid_rod_roots(sigma, &q);
            let at_kink = roots
                .iter()
                .any(|r| (r - q.y1).abs() < 1e-9 || (r + q.y2).abs() < 1e-9);
            if roots.len() == 1 && !at_kink {
                regular += 1;
                assert!(phi_slope(roots[0], sigma, &q) > 0.0, "{p:?} σ = {sigma}");
            }
        }
    }
    assert!(regular > 1000, "{regular} regular cases");
}

/// Energy balance over the whole friction impact, stick phases included:
/// E(t) − E(0) = ∫ Σ F_i s_i' dt − ∫ P_D dt.
#[test]
fn energy_balance_holds_through_stops_and_sticks() {
    let params = Params::default();
    let contacts = Contacts { params };
    let n = 400_000;
    let t_end = 1.5;
    let times: Vec<f64> = (0..=n).map(|i| t_end * i as f64 / n as f64).collect();
    let r = run(-0.78, params, 1e-12, t_end, &times);
    let mu = model::friction(&params);
    let power = |t: f64, y: &[f64; 4]| {
        // The mode at time t: sliding sign from the velocity (stuck: no power).
        let nf = model::normal_forces(y, &params);
        let friction: f64 = (0..2)
            .map(|i| -mu[i] * nf[i].abs() * y[2 + i].signum() * y[2 + i])
            .sum();
        let _ = t;
        friction - model::dissipation_power(y, &params)
    };
    let mut work = 0.0;
    for w in r.samples.windows(2) {
        let ((ta, ya), (tb, yb)) = (&w[0], &w[1]);
        work += 0.5 * (tb - ta) * (power(*ta, ya) + power(*tb, yb));
    }
    let (y0, y_end) = (r.samples[0].1, r.samples.last().unwrap().1);
    let change = model::energy(&y_end, &params) - model::energy(&y0, &params);
    let _ = contacts;
    assert!(
        (change - work).abs() < 1e-6 * change.abs(),
        "ΔE = {change}, work = {work}"
    );
}

/// Deliverable 3.1: the slope signs of Φ agree with Φ itself on each piece,
/// every graph falls in one of the listed classes, all of them occur, and
/// a class whose slopes are all positive always has exactly one root.
#[test]
fn graph_classes_cover_every_phi() {
    use mechlab::studies::painleve::{phi, segment_slopes, slope_signs, Reduced, GRAPH_CLASSES};
    let mut s = 0x0dd_ba11_cafe_f00du64;
    let mut seen = std::collections::BTreeSet::new();
    for _ in 0..20000 {
        let q = Reduced {
            x_star: 20.0 * random(&mut s) - 10.0,
            mu1: 5.0 * random(&mut s),
            mu2: 5.0 * random(&mut s),
            y1: 6.0 * random(&mut s) - 3.0,
            y2: 6.0 * random(&mut s) - 3.0,
            cos_phi0: 0.6,
        };
        for sigma in [1.0, -1.0] {
            let (a, b) = (q.y1.min(-q.y2), q.y1.max(-q.y2));
            let slopes = segment_slopes(sigma, &q);
            let numeric = [
                phi(a - 1.0, sigma, &q) - phi(a - 2.0, sigma, &q),
                (phi(b, sigma, &q) - phi(a, sigma, &q)) / (b - a),
                phi(b + 2.0, sigma, &q) - phi(b + 1.0, sigma, &q),
            ];
            for i in 0..3 {
                if b - a > 1e-6 || i != 1 {
                    assert!(
                        (slopes[i] - numeric[i]).abs() < 1e-6,
                        "{q:?} σ = {sigma}: {slopes:?} vs {numeric:?}"
                    );
                }
            }
            let signs = slope_signs(sigma, &q);
            if signs.contains('0') {
                continue;
            }
            assert!(
                GRAPH_CLASSES.iter().any(|c| c.signs == signs),
                "{signs} is not listed"
            );
            if signs == "+++" {
                assert_eq!(rigid_rod_roots(sigma, &q).len(), 1);
            }
            seen.insert(signs);
        }
    }
    assert_eq!(seen.len(), GRAPH_CLASSES.len(), "{seen:?}");
}

/// Deliverable 3.3: the eigenvalues of (25) at each equilibrium are those of
/// its Jacobian by finite differences, and stability follows Φ'(R*) > 0.
#[test]
fn deformation_equilibria_and_their_eigenvalues() {
    use mechlab::studies::painleve::DeformationEquation;
    let params = Params::default();
    for sigma in [1.0, -1.0] {
        let eq = DeformationEquation {
            reduced: reduced(&params),
            sigma,
            k: params.k,
            nu: params.nu,
            eps: params.eps,
        };
        let equilibria = eq.equilibria();
        assert_eq!(equilibria.len(), 2);
        for e in equilibria {
            assert!(eq.acceleration(e.delta, 0.0).abs() < 1e-9);
            let h = 1e-7;
            let a =
                (eq.acceleration(e.delta + h, 0.0) - eq.acceleration(e.delta - h, 0.0)) / (2.0 * h);
            let b = (eq.acceleration(e.delta, h) - eq.acceleration(e.delta, -h)) / (2.0 * h);
            // λ² − b λ − a = 0 from the Jacobian [[0, 1], [a, b]].
            for (re, im) in e.eigenvalues {
                let (r2, i2) = (re * re - im * im, 2.0 * re * im);
                let residual = ((r2 - b * re - a).powi(2) + (i2 - b * im).powi(2)).sqrt();
                assert!(residual < 1e-5 * (1.0 + a.abs() + b.abs()), "{residual}");
            }
            assert_eq!(e.asymptotically_stable, e.slope > 0.0);
        }
    }
}

/// The generated sliding accelerations give δ'' of equation (23):
/// δ'' = tan²φ δ'²/(l + δ) + cos φ (X1 − X2 − 2R cos φ − (σ1μ1|Y1 − R sin φ| − σ2μ2|Y2 + R sin φ|)).
#[test]
fn sliding_accelerations_satisfy_the_deformation_equation() {
    let mut s = 0x5eed_5eed_5eed_5eedu64;
    let p = Params::default();
    let model = Contacts { params: p };
    for _ in 0..500 {
        let y = [
            random(&mut s),
            random(&mut s) - 1.5,
            4.0 * random(&mut s) - 2.0,
            4.0 * random(&mut s) - 2.0,
        ];
        let sig = [
            if random(&mut s) < 0.5 { 1i8 } else { -1 },
            if random(&mut s) < 0.5 { 1i8 } else { -1 },
        ];
        let f = Smooth {
            model: &model,
            modes: [Mode::Slide(sig[0]), Mode::Slide(sig[1])],
        }
        .rhs(0.0, &y);
        let r = rod(&y, &p);
        let length = p.l + r.delta;
        // δ'' from the accelerations: d/dt[(v1 − v2) cos φ].
        let from_model =
            (f[2] - f[3]) * r.cos_phi + (y[2] - y[3]).powi(2) * r.sin_phi.powi(2) / length;
        let (s1, s2) = (f64::from(sig[0]), f64::from(sig[1]));
        let tan = r.sin_phi / r.cos_phi;
        let eq23 = tan * tan * r.delta_rate.powi(2) / length
            + r.cos_phi
                * (p.X1
                    - p.X2
                    - 2.0 * r.reaction * r.cos_phi
                    - (s1 * p.mu1 * (p.Y1 - r.reaction * r.sin_phi).abs()
                        - s2 * p.mu2 * (p.Y2 + r.reaction * r.sin_phi).abs()));
        assert!(
            (from_model - eq23).abs() < 1e-9 * (1.0 + eq23.abs()),
            "{from_model} vs {eq23}"
        );
    }
}
