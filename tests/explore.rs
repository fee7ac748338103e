//! The explorer runs on every model of `models/`, including those added as
//! files only, and finds the equilibria the closed forms predict.

use mechlab::analysis::on_constraints::ConstrainedError;
use mechlab::explore::{explore, ExploreError, Settings};
use mechlab::models;
use mechlab::ode::{Method, OdeError};
use mechlab::registry::Kind;

fn settings() -> Settings {
    Settings {
        method: Method::parse("dop853", 1e-8).unwrap(),
        t_end: 1.0,
        samples: 50,
        periods: 5,
    }
}

#[test]
fn every_model_can_be_explored() {
    for info in models::ALL {
        let handle = mechlab::models::by_name(info.name).expect("every model is listed");
        let model = handle.dynamic;
        let (n, phase) = match model.kind() {
            Kind::Hamiltonian { dof, fast_phase } => (dof, fast_phase),
            Kind::Contacts { count } => (count, false),
            Kind::Constrained {
                coordinates,
                fast_phase,
                ..
            } => (coordinates, fast_phase),
        };
        let y0: Vec<f64> = match handle.constrained {
            // A constrained model starts on its constraints: its file's start.
            Some(_) => mechlab::explore::default_start(model),
            None => (0..n)
                .map(|i| 0.3 - 0.5 * i as f64)
                .chain((0..n).map(|_| 0.5))
                .collect(),
        };
        let result = explore(handle, &model.defaults(), &y0, &settings())
            .unwrap_or_else(|e| panic!("{}: {e}", info.name));
        if let Some(constrained) = handle.constrained {
            // The run is on the constraints from its (projected) start on.
            for (t, y) in result.times.iter().zip(&result.exact) {
                let (g, c) = constrained.residuals(&model.defaults(), *t, y).unwrap();
                assert!(
                    g < 1e-12 && c < 1e-12,
                    "{}: residuals {g:e}, {c:e} at t = {t}",
                    info.name
                );
            }
            assert!(result.equilibria.is_empty() && result.equilibria_not_searched.is_some());
            continue;
        }
        assert!(
            result.exact.iter().flatten().all(|x| x.is_finite()),
            "{}",
            info.name
        );
        assert_eq!(result.averaged.is_some(), phase, "{}", info.name);
        assert_eq!(result.period_map.is_some(), phase, "{}", info.name);
        assert_eq!(result.energy_change.len(), result.times.len());
        // Every run starts where it was asked to, the period map at y0.
        assert_eq!(result.exact[0], y0, "{}", info.name);
        if let Some(map) = &result.period_map {
            assert_eq!(map[0], y0, "{}", info.name);
        }
        assert_eq!(result.energy_change[0], 0.0, "{}", info.name);
        // Dry friction only takes energy away.
        if let Kind::Contacts { .. } = model.kind() {
            for (w, t) in result.energy_change.windows(2).zip(&result.times) {
                assert!(w[1] <= w[0] + 1e-9, "{}: E rose at t = {t}", info.name);
            }
        }
    }
}

/// Every equilibrium the explorer reports is a critical point of the
/// effective potential, checked by differences of its own at the reported
/// point, for every model with one.
#[test]
fn every_reported_equilibrium_is_a_critical_point() {
    for info in models::ALL {
        let model = mechlab::models::by_name(info.name).expect("every model is listed");
        let params = model.dynamic.defaults();
        let Ok((equilibria, _)) =
            mechlab::analysis::equilibria::effective_equilibria(model.dynamic, &params)
        else {
            continue;
        };
        let v = |q: &[f64]| model.dynamic.effective_potential(&params, q).unwrap();
        for e in &equilibria {
            let gradient: f64 = (0..e.q.len())
                .map(|i| {
                    let (mut a, mut b) = (e.q.clone(), e.q.clone());
                    a[i] += 1e-5;
                    b[i] -= 1e-5;
                    ((v(&a) - v(&b)) / 2e-5).powi(2)
                })
                .sum::<f64>()
                .sqrt();
            let scale = 1.0
                + e.hessian_eigenvalues
                    .iter()
                    .fold(0.0_f64, |m, h| m.max(h.abs()));
            assert!(
                gradient < 1e-6 * scale,
                "{}: |∇V| = {gradient:e} at the reported equilibrium {:?}",
                info.name,
                e.q
            );
        }
    }
}

#[test]
fn a_state_of_the_wrong_length_is_an_error() {
    let handle = mechlab::models::by_name("kapitza").unwrap();
    let defaults = handle.dynamic.defaults();
    assert!(explore(handle, &defaults, &[0.1, 0.0, 0.0], &settings()).is_err());
}

/// Kapitza at A = 1.5: V + V_vibr = cos q + (A²/4) sin²q has minima at 0
/// (V'' = A²/2 − 1) and π (V'' = 1 + A²/2) and maxima at cos q = 2/A².
#[test]
fn kapitza_equilibria_match_the_closed_form() {
    let model = mechlab::models::by_name("kapitza").unwrap().dynamic;
    let a: f64 = 1.5;
    let mut params = model.defaults();
    params[0] = a;
    let (found, _) = mechlab::analysis::equilibria::effective_equilibria(model, &params).unwrap();
    assert_eq!(found.len(), 4, "{found:?}");
    let at = |q: f64| {
        found
            .iter()
            .find(|e| mechlab::analysis::period_map::wrap_angle(e.q[0] - q).abs() < 1e-6)
            .unwrap_or_else(|| panic!("no equilibrium at {q}: {found:?}"))
    };
    use mechlab::explore::Verdict::{Stable, Unstable};
    assert!(
        at(0.0).verdict == Stable
            && (at(0.0).hessian_eigenvalues[0] - (a * a / 2.0 - 1.0)).abs() < 1e-9
    );
    assert_eq!(at(std::f64::consts::PI).verdict, Stable);
    let saddle = (2.0 / (a * a)).acos();
    assert!(at(saddle).verdict == Unstable && at(-saddle).verdict == Unstable);
}

/// Through the generated systems `explore` offers every method, `taylor`
/// included: its runs agree with DOP853's (Kapitza, symbolic form; the
/// triple pendulum, numeric-solve form).
#[test]
fn explore_runs_with_taylor() {
    for name in ["kapitza", "triple_pendulum"] {
        let handle = mechlab::models::by_name(name).unwrap();
        let model = handle.dynamic;
        let n = match model.kind() {
            Kind::Hamiltonian { dof, .. } => dof,
            Kind::Contacts { .. } | Kind::Constrained { .. } => unreachable!(),
        };
        let y0: Vec<f64> = (0..2 * n).map(|i| if i < n { 0.3 } else { 0.0 }).collect();
        let run = |method: &str, tol: f64| {
            let settings = Settings {
                method: Method::parse(method, tol).unwrap(),
                ..settings()
            };
            explore(handle, &model.defaults(), &y0, &settings).unwrap()
        };
        let (taylor, dop) = (run("taylor", 1e-13), run("dop853", 1e-13));
        let last = |runs: &Vec<Vec<f64>>| runs.last().unwrap().clone();
        for (a, b) in last(&taylor.exact).iter().zip(&last(&dop.exact)) {
            assert!((a - b).abs() < 1e-9, "{name}: {a} vs {b}");
        }
        let (ta, da) = (taylor.averaged.unwrap(), dop.averaged.unwrap());
        for (a, b) in last(&ta).iter().zip(&last(&da)) {
            assert!((a - b).abs() < 1e-9, "{name} averaged: {a} vs {b}");
        }
    }
}

/// The second-order verdict: a degenerate Hessian decides nothing, and an
/// empty list of equilibria says why.
#[test]
fn equilibria_are_judged_at_second_order_or_said_inconclusive() {
    use mechlab::analysis::equilibria::{effective_equilibria, NotSearched, Verdict};
    assert_eq!(Verdict::of(&[0.5, 2.0]), Verdict::Stable);
    assert_eq!(Verdict::of(&[-0.5, 2.0]), Verdict::Unstable);
    // x⁴ at 0: a Hessian of round-off, not an instability.
    assert_eq!(Verdict::of(&[8e-12]), Verdict::InconclusiveAtSecondOrder);
    assert_eq!(
        Verdict::of(&[-1e-12, 3.0]),
        Verdict::InconclusiveAtSecondOrder
    );
    // Hénon–Heiles: the minimum at 0 and three saddles at V = 1/6.
    let hh = models::by_name("henon_heiles").unwrap();
    let (found, _) = effective_equilibria(hh.dynamic, &[1.0]).unwrap();
    let stable: Vec<_> = found
        .iter()
        .filter(|e| e.verdict == Verdict::Stable)
        .collect();
    assert_eq!(stable.len(), 1);
    assert!(stable[0].q.iter().all(|x| x.abs() < 1e-9));
    assert_eq!(
        found
            .iter()
            .filter(|e| e.verdict == Verdict::Unstable)
            .count(),
        3
    );
    // A contact model has no potential to search.
    let contact = models::by_name("painleve_klein").unwrap();
    assert_eq!(
        effective_equilibria(contact.dynamic, &contact.dynamic.defaults()).unwrap_err(),
        NotSearched::NoPotential
    );
}

/// A spring whose length r is a polar coordinate (the test model
/// `spring_double_pendulum`): with a soft spring (k = 0.25) the potential
/// is stationary at r = 0, where ψ no longer means anything and the mass
/// matrix is singular. There the verdict is "singular chart", never
/// "unstable" from the Hessian of a chart that does not see the point;
/// the hanging rest state keeps its verdict.
#[test]
fn a_singular_point_of_the_chart_is_named_not_judged() {
    use mechlab::analysis::equilibria::{effective_equilibria, Verdict};
    use mechlab_test_models::spring_double_pendulum::{Params, DYNAMIC};
    let mut params = Params::default();
    params.set("k", 0.25).unwrap();
    let (found, _) = effective_equilibria(&DYNAMIC, &params.values()).unwrap();
    let at_pole: Vec<_> = found.iter().filter(|e| e.q[2].abs() < 1e-6).collect();
    assert!(!at_pole.is_empty(), "{found:#?}");
    assert!(
        at_pole.iter().all(|e| e.verdict == Verdict::SingularChart),
        "{at_pole:#?}"
    );
    // Both links hanging (tilted a little by the inclined vibration), the
    // spring stretched by about m₂g/k.
    // (The first link upright over the stretched spring is an
    // equilibrium too, with the same r: the first angle tells them apart.)
    let hanging = found
        .iter()
        .filter(|e| e.q[0].abs() < 0.5)
        .max_by(|a, b| a.q[2].total_cmp(&b.q[2]))
        .expect("the hanging rest state");
    let upright = found
        .iter()
        .find(|e| (e.q[0].abs() - std::f64::consts::PI).abs() < 0.5 && e.q[2] > 2.0);
    assert_eq!(
        upright.map(|e| e.verdict),
        Some(Verdict::Unstable),
        "{found:#?}"
    );
    assert_eq!(hanging.verdict, Verdict::Stable, "{hanging:?}");
    assert!(
        (hanging.q[2] - (1.0 + 0.5 / 0.25)).abs() < 0.1,
        "{hanging:?}"
    );
}

/// A cyclic angle (the test model `central_spring`, a planar spring
/// anchored at the origin): the rest states r = l0 are a circle of
/// equilibria. They are reported once, as a family along φ, and judged on
/// the system reduced by φ (Routh, conserved momentum 0): stable with the
/// reduced Hessian [k], where the full Hessian's zero eigenvalue decided
/// nothing.
#[test]
fn a_family_along_a_cyclic_angle_is_reported_once_and_judged_reduced() {
    use mechlab::analysis::equilibria::{effective_equilibria, Verdict};
    use mechlab_test_models::central_spring::{Params, DYNAMIC};
    let params = Params::default().values();
    let (found, _) = effective_equilibria(&DYNAMIC, &params).unwrap();
    let at_rest: Vec<_> = found
        .iter()
        .filter(|e| (e.q[0] - 1.0).abs() < 1e-6)
        .collect();
    assert_eq!(at_rest.len(), 1, "{found:#?}");
    let rest = at_rest[0];
    assert_eq!(rest.family_along, vec![1]);
    assert_eq!(rest.verdict, Verdict::Stable);
    assert_eq!(rest.hessian_eigenvalues.len(), 1);
    assert!((rest.hessian_eigenvalues[0] - 4.0).abs() < 1e-9, "{rest:?}");
}

/// A spherical pendulum on a vibrating pivot (test model
/// `spherical_pendulum`): the upright is a pole of the chart, where the
/// mass matrix diag(1, sin²θ) is singular along the cyclic azimuth only.
/// It is reported once, as a family along φ at a pole, and judged on the
/// reduced system: stable for A above √2 (the reduced Hessian
/// −1 + A²/2 > 0), unstable below — never "unstable" from the zero
/// eigenvalue of φ, never a singular chart that decides nothing.
#[test]
fn a_spherical_pendulums_upright_is_judged_at_the_pole_on_the_reduced_system() {
    use mechlab::analysis::equilibria::{effective_equilibria, Verdict};
    use mechlab_test_models::spherical_pendulum::DYNAMIC;
    for (a, verdict) in [(1.6, Verdict::Stable), (1.2, Verdict::Unstable)] {
        let (found, _) = effective_equilibria(&DYNAMIC, &[a, 0.1]).unwrap();
        let upright: Vec<_> = found.iter().filter(|e| e.q[0].abs() < 1e-6).collect();
        assert_eq!(upright.len(), 1, "A = {a}: {found:#?}");
        let upright = upright[0];
        assert!(upright.pole, "{upright:?}");
        assert_eq!(upright.family_along, vec![1]);
        assert_eq!(upright.verdict, verdict, "A = {a}: {upright:?}");
        let expected = -1.0 + a * a / 2.0;
        assert_eq!(upright.hessian_eigenvalues.len(), 1);
        assert!(
            (upright.hessian_eigenvalues[0] - expected).abs() < 1e-6,
            "{upright:?}"
        );
    }
}

/// `stability` on the same pendulum decides at the poles what `explore`
/// decides: each pole once (not once per azimuth of its grid), judged on
/// the system reduced by the azimuth. The upright's reduced C is −1 and
/// its V_vibr adds A²/2, so a* = √2 (closed form), on either side of which
/// `explore` calls it unstable (A = 1.2) and stable (A = 1.6); the hanging
/// pole (C = +1) is stable without vibration. Neither gets an exact
/// window: the exact system is singular at a pole in these coordinates.
#[test]
fn stability_judges_the_spherical_pendulums_poles_as_explore_does() {
    use mechlab::analysis::equilibria::{effective_equilibria, Verdict};
    use mechlab::analysis::stability::{stability, Settings};
    use mechlab::ode::Method;
    use mechlab_test_models::spherical_pendulum::{DYNAMIC, MODEL};
    let settings = Settings {
        amplitude: "A".into(),
        a_max: None,
        samples: 40,
        edge_tolerance: 1e-9,
        method: Method::Taylor { tol: 1e-12 },
        max_windows: mechlab::analysis::stability::MAX_WINDOWS,
        accuracy: None,
        first: Default::default(),
    };
    let found = stability(&MODEL, &[1.6, 0.1], &settings).unwrap();
    let pole = |theta: f64| {
        let at: Vec<_> = found
            .equilibria
            .iter()
            .filter(|e| (e.q[0].abs() - theta).abs() < 1e-9)
            .collect();
        assert_eq!(at.len(), 1, "θ = {theta}: {:#?}", found.equilibria);
        at[0].clone()
    };
    let upright = pole(0.0);
    assert_eq!(upright.reduced_by, vec![1], "{upright:?}");
    assert_eq!(upright.lambdas.len(), 1);
    assert!((upright.lambdas[0] + 1.0).abs() < 1e-9, "{upright:?}");
    let a_star = upright.a_star.expect("the upright pole has a threshold");
    assert!((a_star - 2f64.sqrt()).abs() < 1e-9, "a* = {a_star}");
    assert!(upright.exact_window.is_none());
    assert!(upright.exact_reason.as_deref().unwrap().contains("pole"));
    let hanging = pole(std::f64::consts::PI);
    assert_eq!(hanging.reduced_by, vec![1]);
    assert!(hanging.stable_without_vibration, "{hanging:?}");
    assert!((hanging.lambdas[0] - 1.0).abs() < 1e-9, "{hanging:?}");
    for a in [1.2, 1.6] {
        let (equilibria, _) = effective_equilibria(&DYNAMIC, &[a, 0.1]).unwrap();
        let explored = equilibria.iter().find(|e| e.q[0].abs() < 1e-6).unwrap();
        let expected = if a > a_star {
            Verdict::Stable
        } else {
            Verdict::Unstable
        };
        assert_eq!(explored.verdict, expected, "A = {a}");
    }
}

/// A 4-link chain (the test model `quadruple_pendulum`, shaken with a = 5):
/// `explore` searches its equilibria as `stability` does (the shared
/// finder; before, it searched none beyond 3 degrees of freedom), and its
/// verdict on V + V_vibr at the upright chain is `stability`'s averaged one
/// at the same amplitude: stable exactly when a exceeds a*.
#[test]
fn a_four_link_chain_gets_its_equilibria_judged_as_stability_judges_them() {
    use mechlab::analysis::equilibria::{effective_equilibria, Verdict};
    use mechlab::analysis::stability::averaged_stability;
    use mechlab_test_models::quadruple_pendulum::{Params, DYNAMIC, MODEL};
    let params = Params::default().values();
    let (found, _) = effective_equilibria(&DYNAMIC, &params).unwrap();
    let at = |target: f64| {
        found.iter().find(|e| {
            e.q.iter()
                .all(|x| mechlab::analysis::period_map::wrap_angle(x - target).abs() < 1e-6)
        })
    };
    let hanging = at(std::f64::consts::PI).expect("the hanging chain");
    assert_eq!(hanging.verdict, Verdict::Stable);
    let upright = at(0.0).expect("the upright chain");
    let averaged = averaged_stability(&MODEL, &params, "a", &[0.0; 4]).unwrap();
    let a = 5.0;
    let stable = averaged.stable_without_vibration || averaged.a_star.is_some_and(|s| a > s);
    assert_eq!(
        upright.verdict == Verdict::Stable,
        stable,
        "explore: {upright:?}; stability: {averaged:?}"
    );
    // Each link up or down is an equilibrium of the shaken chain too.
    assert!(found.len() >= 16, "{} equilibria", found.len());
}

/// Every Hamiltonian model's Taylor recurrences, exact and averaged, give
/// the runs DOP853 gives: the recurrences are generated code of their own
/// (in parts for long models, their slots passed one by one past a size),
/// and a wrong coefficient would part the two runs at once. Models added
/// to `models/` are checked too (CI adds a 12-link chain, whose
/// recurrences take both large-model forms).
#[test]
fn every_model_s_taylor_runs_agree_with_dop853() {
    let settings = |name: &str| Settings {
        method: Method::parse(name, 1e-13).unwrap(),
        t_end: 0.5,
        samples: 6,
        periods: 0,
    };
    for info in models::ALL {
        let handle = mechlab::models::by_name(info.name).expect("every model is listed");
        if let Kind::Contacts { .. } = handle.dynamic.kind() {
            eprintln!(
                "{}: skipped (a contact model has no Taylor recurrences)",
                info.name
            );
            continue;
        }
        let y0 = mechlab::explore::default_start(handle.dynamic);
        let params = handle.dynamic.defaults();
        let runs = (
            explore(handle, &params, &y0, &settings("taylor")),
            explore(handle, &params, &y0, &settings("dop853")),
        );
        // A constrained model past Taylor's size, or a field not analytic
        // at the start (as |v| at v = 0): said so, and skipped.
        if let Err(
            e @ (ExploreError::Ode(OdeError::TaylorUnavailable | OdeError::NotAnalytic { .. })
            | ExploreError::Constrained(ConstrainedError::Ode(OdeError::TaylorUnavailable))),
        ) = &runs.0
        {
            eprintln!("{}: skipped ({e})", info.name);
            continue;
        }
        // Both runs stop, or neither: a model that Taylor's method runs and
        // DOP853 cannot (or the reverse) is a disagreement, not a skip.
        let (taylor, dop853) = match runs {
            (Ok(t), Ok(d)) => (t, d),
            (Err(t), Err(d)) => {
                eprintln!(
                    "{}: skipped (both runs from the default start stop: {t}; {d})",
                    info.name
                );
                continue;
            }
            (t, d) => panic!(
                "{}: one method runs from the default start and the other stops: taylor {:?}, dop853 {:?}",
                info.name,
                t.err(),
                d.err()
            ),
        };
        let pairs = [
            ("exact", Some(&taylor.exact), Some(&dop853.exact)),
            (
                "averaged",
                taylor.averaged.as_ref(),
                dop853.averaged.as_ref(),
            ),
        ];
        for (kind, a, b) in pairs {
            let (Some(a), Some(b)) = (a, b) else { continue };
            for (t, (x, y)) in taylor.times.iter().zip(a.iter().zip(b)) {
                for (i, (u, v)) in x.iter().zip(y).enumerate() {
                    assert!(
                        (u - v).abs() <= 1e-8 * (1.0 + v.abs()),
                        "{} {kind}, t = {t}, component {i}: taylor {u}, dop853 {v}",
                        info.name
                    );
                }
            }
        }
    }
}

/// A vibrated four-bar whose vibration is set to amplitude 0 conserves its
/// energy: its run says so (E(t) − E(0) at round-off), and its label does
/// not say that the vibration does work, as it does at the file's
/// amplitude, where E changes.
#[test]
fn a_vibration_at_amplitude_zero_is_not_said_to_do_work() {
    let handle = mechlab::models::by_name("four_bar").unwrap();
    let model = handle.dynamic;
    let y0 = mechlab::explore::default_start(model);
    let mut still = models::four_bar::Params::default();
    still.set("a", 0.0).unwrap();
    let at_rest = explore(handle, &still.values(), &y0, &settings()).unwrap();
    let largest = at_rest
        .energy_change
        .iter()
        .fold(0.0_f64, |m, e| m.max(e.abs()));
    assert!(largest < 1e-6, "E changed by {largest:e} without vibration");
    assert_eq!(at_rest.energy_label, "E(t) − E(0) on the constraints");
    let vibrated = explore(handle, &model.defaults(), &y0, &settings()).unwrap();
    let largest = vibrated
        .energy_change
        .iter()
        .fold(0.0_f64, |m, e| m.max(e.abs()));
    assert!(
        largest > 1e-3,
        "E changed by only {largest:e} under vibration"
    );
    assert!(vibrated.energy_label.contains("the vibration does work"));
}

/// Newton's method on a gradient of differences accepts a root, not an
/// iterate walking off to where the potential flattens: for
/// V = 1/(1 + x²) the gradient −2x/(1 + x²)² is below any tolerance far
/// out, where Newton's steps grow with x.
#[test]
fn newton_on_a_noisy_gradient_does_not_take_a_flattening_tail_for_a_root() {
    use mechlab::analysis::equilibria::{newton, Convergence};
    use nalgebra::DMatrix;
    let gradient = |q: &[f64]| vec![-2.0 * q[0] / (1.0 + q[0] * q[0]).powi(2)];
    let hessian = |q: &[f64]| {
        let x2 = q[0] * q[0];
        DMatrix::from_element(1, 1, 2.0 * (3.0 * x2 - 1.0) / (1.0 + x2).powi(3))
    };
    let noisy = Convergence::Noisy { gradient: 1e-7 };
    let root = newton(gradient, hessian, vec![0.3], noisy).expect("the maximum at 0");
    assert!(root[0].abs() < 1e-12, "{root:?}");
    assert_eq!(newton(gradient, hessian, vec![2.0], noisy), None);
}

/// A flat effective potential (here Kapitza's pendulum with V̄ made
/// constant) is said to be flat, not listed as a grid of "inconclusive"
/// equilibria; the real one is searched.
#[test]
fn a_flat_effective_potential_is_named_not_listed() {
    use mechlab::analysis::equilibria::{effective_equilibria, NotSearched};
    use mechlab::registry::{DynamicModel, ModelInfo};
    struct Flat(&'static dyn DynamicModel);
    impl DynamicModel for Flat {
        fn info(&self) -> &'static ModelInfo {
            self.0.info()
        }
        fn kind(&self) -> Kind {
            self.0.kind()
        }
        fn defaults(&self) -> Vec<f64> {
            self.0.defaults()
        }
        fn periodic(&self) -> Vec<bool> {
            self.0.periodic()
        }
        fn energy(&self, params: &[f64], t: f64, y: &[f64]) -> f64 {
            self.0.energy(params, t, y)
        }
        fn effective_potential(&self, _params: &[f64], _q: &[f64]) -> Option<f64> {
            Some(0.25)
        }
        fn effective_potential_hessian(&self, _params: &[f64], q: &[f64]) -> Option<Vec<f64>> {
            Some(vec![0.0; q.len() * q.len()])
        }
    }
    let kapitza = models::by_name("kapitza").unwrap().dynamic;
    let params = kapitza.defaults();
    let flat = effective_equilibria(&Flat(kapitza), &params).map(|(found, _)| found.len());
    assert_eq!(flat, Err(NotSearched::Flat));
    let (found, _) = effective_equilibria(kapitza, &params).unwrap();
    assert!(!found.is_empty());
}
