//! Every generic analysis on every model file in `models/`: a result with
//! properties that hold for any model, or a typed refusal with its reason.

use super::model_of;
use mechlab::analysis::averaging::{convergence, AveragingError, ConvergenceSettings};
use mechlab::analysis::chaos_map::{chaos_map, ChaosMapError, ChaosMapSettings};
use mechlab::analysis::period_map::{portrait, PortraitSettings};
use mechlab::analysis::stability::{stability, Settings, StabilityError};
use mechlab::models;
use mechlab::ode::Method;
use mechlab::registry::Kind;
use nalgebra::DMatrix;
use std::f64::consts::PI;

#[test]
fn every_analysis_runs_on_every_model_or_says_why_not() {
    // Models whose averaging exponents were all checked (a model may skip
    // one with its reason, but not every model).
    let mut averaging_checked = 0;
    for info in models::ALL {
        let model = mechlab::models::by_name(info.name).unwrap().dynamic;
        let params = model.defaults();
        let (n, fast_phase) = match model.kind() {
            Kind::Hamiltonian { dof, fast_phase } => (dof, fast_phase),
            Kind::Constrained { .. } => {
                constrained_model_on_its_constraints(info.name, &params);
                continue;
            }
            Kind::Contacts { .. } => {
                contact_model_is_refused(info.name, &params);
                continue;
            }
        };
        // A model without a fast phase has no period map and nothing to
        // average: each analysis says so.
        if !fast_phase {
            no_fast_phase_is_refused(info.name, &params);
            continue;
        }
        // The amplitude is optional in a model file: without one, the
        // stability analysis (which varies it) says so and how to choose it.
        match info.amplitude {
            Some(amplitude) => check_stability(info.name, &params, amplitude, n),
            None => {
                let e =
                    stability(model_of(info.name), &params, &stability_settings("")).unwrap_err();
                assert!(
                    matches!(e, StabilityError::NoAmplitude { .. }),
                    "{}: {e}",
                    info.name
                );
            }
        }
        // Averaging's error falls with ε as a whole power: ε for a vibration
        // of fixed velocity amplitude (Kapitza's A/ε scaling), ε² for a
        // drive of fixed amplitude (Ueda's B cos ωt, whose response is
        // B/ω²); no slope at all would mean averaging is wrong.
        // Where a coordinate's slope has not settled at the model's own
        // frequencies (nor 8 and 64 times higher), there is no exponent to
        // check: the test says so.
        let slopes =
            crate::common::asymptotic_slopes(model_of(info.name), &params, &averaging_settings())
                .unwrap();
        if crate::common::assert_whole_power_slopes(info.name, &slopes, -1.0) {
            averaging_checked += 1;
        }
        check_chaos_map_and_portrait(info.name, &params, n, &model.periodic());
    }
    assert!(
        averaging_checked > 0,
        "no model's averaging exponent was checked"
    );
}

/// A constrained model: the analyses of Hamiltonian forms refuse it by
/// name; its averaging error falls as a whole power of the frequency, or
/// the analysis says why it does not apply (no fast phase, constraints
/// that move with it); its portrait (with a fast phase) runs on its constraints from
/// seeds put on them; its stabilisation by vibration gives an equilibrium
/// on the constraints, or says why it cannot.
fn constrained_model_on_its_constraints(name: &str, params: &[f64]) {
    use mechlab::analysis::on_constraints::vibration::{
        vibration_stability, VibrationError, VibrationSettings,
    };
    let handle = model_of(name);
    let constrained = handle.constrained.unwrap();
    let refused = mechlab::analysis::Refusal::Constrained {
        model: name.to_string(),
    };
    let e = stability(handle, params, &stability_settings("")).unwrap_err();
    assert!(
        matches!(e, StabilityError::Refused(ref r) if *r == refused),
        "{e}"
    );
    match crate::common::asymptotic_slopes(handle, params, &averaging_settings()) {
        Ok(slopes) => {
            crate::common::assert_whole_power_slopes(name, &slopes, -1.0);
        }
        Err(AveragingError::Refused(mechlab::analysis::Refusal::NoFastPhase { .. }))
        | Err(AveragingError::MovingConstraints { .. }) => {}
        Err(e) => panic!("{name}: {e}"),
    }
    let n = handle.info.coordinates.len();
    // The chaos map on a plane of a coordinate and its velocity through the
    // file's start: a pixel with no state of the model there is NaN,
    // every other an FLI of at least 0.
    let settings = ChaosMapSettings {
        axes: [0, n],
        method: Method::Dop853 {
            rtol: 1e-9,
            atol: 1e-9,
        },
        ..map_settings(5)
    };
    match chaos_map(handle, params, &settings, &|| true) {
        Ok(map) => {
            let nan = map.fli.iter().filter(|f| f.is_nan()).count();
            assert_eq!(map.without_state, nan);
            assert!(
                map.fli.iter().all(|f| f.is_nan() || *f >= 0.0),
                "{name}: {:?}",
                map.fli
            );
        }
        Err(ChaosMapError::Refused(mechlab::analysis::Refusal::NoFastPhase { .. })) => {}
        Err(e) => panic!("{name}: {e}"),
    }
    let settings = PortraitSettings {
        axes: [0, n],
        seeds: None,
        count: 3,
        p_max: 0.1,
        periods: 20,
        method: Method::Dop853 {
            rtol: 1e-10,
            atol: 1e-10,
        },
        check: 0,
        accuracy: None,
    };
    match portrait(handle, params, &settings) {
        Ok(result) => {
            for seed in &result.seeds {
                let (g, c) = constrained.residuals(params, 0.0, seed).unwrap();
                assert!(g < 1e-12 && c < 1e-12, "{name}: a seed off the constraints");
            }
            assert!(result.failed.is_empty(), "{name}: {:?}", result.failed);
        }
        Err(e) => assert!(e.to_string().contains("no fast phase"), "{name}: {e}"),
    }
    match vibration_stability(
        constrained,
        params,
        &VibrationSettings {
            scan: 4,
            check: false,
            ..Default::default()
        },
    ) {
        Ok(result) => {
            let statics = constrained
                .statics(params, 0.0, &result.equilibrium)
                .unwrap();
            assert!(
                statics.residual.amax() < 1e-9,
                "{name}: q* off the constraints"
            );
            assert_eq!(
                result.averaged_stable,
                result.squared_frequencies.first().is_some_and(|w| *w > 0.0)
            );
        }
        Err(
            VibrationError::Refused(_)
            | VibrationError::MovingConstraints { .. }
            | VibrationError::Gyroscopic { .. }
            | VibrationError::NoEquilibrium { .. },
        ) => {}
        Err(e) => panic!("{name}: {e}"),
    }
}

/// One refusal, the same value from every analysis, naming the contact model.
fn contact_model_is_refused(name: &str, params: &[f64]) {
    let refused = mechlab::analysis::Refusal::ContactModel {
        model: name.to_string(),
    };
    let (a, b, c) = (
        stability(model_of(name), params, &stability_settings("mu1")).unwrap_err(),
        convergence(model_of(name), params, &averaging_settings()).unwrap_err(),
        chaos_map(model_of(name), params, &map_settings(5), &|| true).unwrap_err(),
    );
    assert!(
        matches!(a, StabilityError::Refused(ref r) if *r == refused)
            && a.to_string().contains("contact model"),
        "{a}"
    );
    assert!(
        matches!(b, AveragingError::Refused(ref r) if *r == refused),
        "{b}"
    );
    assert!(
        matches!(c, ChaosMapError::Refused(ref r) if *r == refused),
        "{c}"
    );
    assert!(portrait(model_of(name), params, &portrait_settings(1)).is_err());
}

/// Without a fast phase there is no period map and nothing to average.
fn no_fast_phase_is_refused(name: &str, params: &[f64]) {
    use mechlab::analysis::Refusal::NoFastPhase;
    let e = stability(model_of(name), params, &stability_settings("x")).unwrap_err();
    assert!(
        matches!(e, StabilityError::Refused(NoFastPhase { .. })),
        "{name}: {e}"
    );
    let e = convergence(model_of(name), params, &averaging_settings()).unwrap_err();
    assert!(
        matches!(e, AveragingError::Refused(NoFastPhase { .. })),
        "{name}: {e}"
    );
    let e = chaos_map(model_of(name), params, &map_settings(4), &|| true).unwrap_err();
    assert!(
        matches!(e, ChaosMapError::Refused(NoFastPhase { .. })),
        "{name}: {e}"
    );
}

/// The FLI never falls with more periods; portraits start at their seeds
/// with angles in [−π, π).
fn check_chaos_map_and_portrait(name: &str, params: &[f64], n: usize, periodic: &[bool]) {
    // The FLI is a maximum over the iterations: more periods never lower it.
    let (short, long) = (
        chaos_map(model_of(name), params, &map_settings(4), &|| true).unwrap(),
        chaos_map(model_of(name), params, &map_settings(8), &|| true).unwrap(),
    );
    assert_eq!(short.fli.len(), 9);
    // A pixel whose orbit left the model's domain (+∞: the elastic
    // pendulum's plane crosses r = 0) stays so.
    for (a, b) in short.fli.iter().zip(&long.fli) {
        assert!(
            *b >= *a && !a.is_nan(),
            "{}: FLI {a} after 4 periods, {b} after 8",
            name
        );
    }
    assert_eq!(
        short.diverged,
        short.fli.iter().filter(|f| f.is_infinite()).count()
    );
    // Orbits start at their seeds; angles stay in [−π, π).
    let orbits = portrait(model_of(name), params, &portrait_settings(n)).unwrap();
    for (seed, orbit) in orbits.seeds.iter().zip(&orbits.orbits) {
        if orbit.is_empty() {
            continue; // stopped (listed in `failed` with its reason)
        }
        assert_eq!(orbit.len(), 21);
        assert_eq!(orbit[0], (seed[0], seed[n]));
        if periodic[0] {
            assert!(orbit.iter().all(|p| (-PI..PI).contains(&p.0)), "{}", name);
        }
    }
    let stopped = orbits.orbits.iter().filter(|o| o.is_empty()).count();
    assert_eq!(orbits.failed.len(), stopped);
}

/// Each reported equilibrium is one of V + V_vibr, has n roots λ, and where
/// there is a threshold C + a²K is positive definite just above a* and not
/// just below.
fn check_stability(name: &str, params: &[f64], amplitude: &str, n: usize) {
    let model = mechlab::models::by_name(name).unwrap().dynamic;
    let result = stability(model_of(name), params, &stability_settings(amplitude)).unwrap();
    let k = model
        .info()
        .parameter_names
        .iter()
        .position(|p| *p == amplitude)
        .unwrap();
    let hessian = |a: f64, q: &[f64]| {
        let mut p = params.to_vec();
        p[k] = a;
        DMatrix::from_row_slice(n, n, &model.effective_potential_hessian(&p, q).unwrap())
    };
    for e in &result.equilibria {
        // (At a pole, the roots are the reduced system's.)
        assert_eq!(e.lambdas.len(), n - e.reduced_by.len(), "{name}");
        let v = |q: &[f64]| model.effective_potential(params, q).unwrap();
        for i in 0..n {
            let h = 1e-5;
            let (mut up, mut down) = (e.q.clone(), e.q.clone());
            up[i] += h;
            down[i] -= h;
            assert!(
                ((v(&up) - v(&down)) / (2.0 * h)).abs() < 1e-6,
                "{name}: not stationary at {:?}",
                e.q
            );
        }
        assert_eq!(
            e.stable_without_vibration,
            e.lambdas.iter().all(|l| *l > 0.0)
        );
        match e.a_star {
            Some(a) => {
                assert!(
                    hessian(a * (1.0 + 1e-6), &e.q).cholesky().is_some(),
                    "{name} {:?}",
                    e.q
                );
                assert!(
                    hessian(a * (1.0 - 1e-6), &e.q).cholesky().is_none(),
                    "{name} {:?}",
                    e.q
                );
            }
            None => assert!(e.reason.is_some(), "{name}: no a* and no reason"),
        }
    }
    // A moved equilibrium's window lies on the amplitudes searched, in order.
    for moved in &result.moved_by_vibration {
        if let Some([lower, upper]) = moved.exact_window {
            let lower = lower.expect("a window has its lower edge");
            assert!(lower >= 0.0, "{name} {:?}: {lower}", moved.q);
            if let Some(upper) = upper {
                assert!(upper >= lower, "{name} {:?}: [{lower}, {upper}]", moved.q);
            }
        }
    }
}

fn stability_settings(amplitude: &str) -> Settings {
    Settings {
        amplitude: amplitude.into(),
        a_max: None,
        samples: 6,
        edge_tolerance: 1e-4,
        method: Method::parse("taylor", 1e-10).unwrap(),
        // Every equilibrium of a model of up to 3 degrees of freedom gets
        // its window; a chain of 6 or 12 links has 64 or 4,096 equilibria,
        // each a Floquet sweep of its size, and what this test asserts of
        // a window holds of the first 8 as of all.
        max_windows: 8,
        accuracy: None,
        first: Default::default(),
    }
}

fn averaging_settings() -> ConvergenceSettings {
    ConvergenceSettings {
        check: false,
        accuracy: None,
        parameter: None,
        values: None,
        y0: None,
        t_obs: 2.0,
        method: Method::parse("dop853", 1e-11).unwrap(),
        order: 1,
    }
}

/// Three orbits on the plane (q₁, p₁) of a model of n degrees of freedom.
fn portrait_settings(n: usize) -> PortraitSettings {
    PortraitSettings {
        axes: [0, n],
        seeds: None,
        count: 3,
        p_max: 0.5,
        periods: 20,
        method: Method::parse("taylor", 1e-10).unwrap(),
        check: 0,
        accuracy: None,
    }
}

fn map_settings(periods: usize) -> ChaosMapSettings {
    ChaosMapSettings {
        check: 0,
        accuracy: None,
        axes: [0, 1],
        ranges: [None, None],
        p_max: 1.0,
        through: None,
        pixels: 3,
        periods,
        method: Method::parse("taylor", 1e-8).unwrap(),
        tiles: None,
    }
}
