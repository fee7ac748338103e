//! The Whipple–Carvallo bicycle written as four rigid bodies in a model
//! file (`test_models/whipple_bicycle.toml`: its energy, gravity, the front
//! wheel's contact and both wheels' rolling derived by mechlab), linearised
//! about its upright straight-ahead motion by `steady_motion`, against the
//! benchmark of Meijaard, Papadopoulos, Ruina and Schwab (2007), Proc. R.
//! Soc. A 463, 1955–1982: the eigenvalues at 5 m/s (their Table 2) and the
//! weave and capsize speeds bounding the self-stable range (their §5).

use mechlab::analysis::on_constraints::steady::{
    speed_sweep, steady_motion, SteadyMotion, SteadyMotionError, SteadySettings,
};
use mechlab::registry::ConstrainedSystems;
use mechlab_test_models::whipple_bicycle as bicycle;

/// The published eigenvalues at v = 5 m/s (re, im): castering, weave,
/// capsize.
const AT_FIVE: [(f64, f64); 4] = [
    (-14.07838969279822, 0.0),
    (-0.77534188219585, 4.46486771378823),
    (-0.77534188219585, -4.46486771378823),
    (-0.32286642900409, 0.0),
];
const WEAVE_SPEED: f64 = 4.29238253634111;
const CAPSIZE_SPEED: f64 = 6.02426201538837;

fn model() -> &'static dyn ConstrainedSystems {
    bicycle::MODEL.constrained.unwrap()
}

fn index(name: &str) -> usize {
    let names = model().info().coordinates;
    names.iter().position(|c| *c == name).unwrap()
}

/// The upright motion at forward speed v: the rear wheel turns at v/rR.
fn linearised(v: f64) -> SteadyMotion {
    let model = model();
    let params = bicycle::Params::default().values();
    let r_rear = bicycle::Params::default().get("rR").unwrap();
    let q = vec![0.0; model.info().coordinates.len()];
    let shape = [index("phi"), index("delta")];
    let held = [(index("thetaR"), v / r_rear)];
    steady_motion(
        model,
        &params,
        &SteadySettings {
            q: &q,
            shape: &shape,
            held: &held,
        },
    )
    .unwrap()
}

#[test]
fn eigenvalues_at_five_metres_per_second_are_the_benchmarks() {
    let motion = linearised(5.0);
    // The speed decouples from lean and steer on the upright motion: the
    // linearisation is the 4 × 4 of (phi, delta, phi', delta').
    assert_eq!(motion.reduced, ["phi", "delta", "phi'", "delta'"]);
    let mut got = motion.eigenvalues.clone();
    got.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
    for (g, w) in got.iter().zip(AT_FIVE) {
        println!("{g:?} against {w:?}");
        assert!(
            (g.0 - w.0).abs() < 1e-10 && (g.1 - w.1).abs() < 1e-10,
            "{g:?} against the benchmark's {w:?}"
        );
    }
    // The rear wheel's centre moves forward at v.
    let xd = motion.state[model().info().coordinates.len() + index("x")];
    assert!((xd - 5.0).abs() < 1e-12, "x' = {xd}");
}

#[test]
fn the_self_stable_range_is_the_benchmarks() {
    let model = model();
    let defaults = bicycle::Params::default();
    let q = vec![0.0; model.info().coordinates.len()];
    let shape = [index("phi"), index("delta")];
    let held = [(index("thetaR"), 1.0 / defaults.get("rR").unwrap())];
    let settings = SteadySettings {
        q: &q,
        shape: &shape,
        held: &held,
    };
    let speeds: Vec<f64> = (0..=20).map(|k| 0.5 * k as f64).collect();
    let sweep = speed_sweep(model, &defaults.values(), &settings, &speeds).unwrap();
    let [weave, capsize] = sweep.boundaries[..] else {
        panic!("two boundaries in 0..10 m/s, not {:?}", sweep.boundaries);
    };
    println!(
        "weave {:.12} m/s, capsize {:.12} m/s",
        weave.speed, capsize.speed
    );
    assert!(weave.unstable_below && !capsize.unstable_below);
    assert!(
        (weave.speed - WEAVE_SPEED).abs() < 1e-8,
        "weave speed {weave:?}"
    );
    assert!(
        (capsize.speed - CAPSIZE_SPEED).abs() < 1e-8,
        "capsize speed {capsize:?}"
    );
}

/// A leaning bicycle is not a steady motion: the linearisation says so,
/// naming the lean, instead of linearising about a falling state.
#[test]
fn a_leaning_bicycle_is_refused_as_not_steady() {
    let model = model();
    let defaults = bicycle::Params::default();
    let mut q = vec![0.0; model.info().coordinates.len()];
    q[index("phi")] = 0.1;
    let shape = [index("phi"), index("delta")];
    let held = [(index("thetaR"), 5.0 / defaults.get("rR").unwrap())];
    let settings = SteadySettings {
        q: &q,
        shape: &shape,
        held: &held,
    };
    match steady_motion(model, &defaults.values(), &settings) {
        Err(e @ SteadyMotionError::NotSteady { .. }) => {
            let text = e.to_string();
            assert!(
                text.contains("'phi''") || text.contains("'delta''"),
                "{text}"
            );
        }
        other => panic!("a leaning bicycle linearised: {other:?}"),
    }
    // Neither shape nor speed: a setting error naming what is missing.
    let no_shape = SteadySettings {
        shape: &[],
        held: &[],
        ..settings
    };
    let e = steady_motion(model, &defaults.values(), &no_shape).unwrap_err();
    assert!(e.to_string().contains("shape coordinate"), "{e}");
}

/// A model file not written for the linearisation: the thin uniform disk
/// of `test_models/tipping_disk_body.toml` (m = R = g = 1) rolling upright
/// with spin ω about its axle. Routh's tilt equation,
/// (A + mR²) θ'' + (C (C + mR²) ω²/A − m g R) θ = 0 with A = mR²/4 and
/// C = mR²/2, gives λ² = (1 − 3ω²)·4/5: the disk stands up above
/// ω² = 1/3. The heading is in the shape (the tilt turns it); what is
/// left of the spectrum is the heading's double zero.
#[test]
fn a_rolling_disk_stands_up_above_routh_s_spin() {
    use mechlab_test_models::tipping_disk_body as disk;
    let model = disk::MODEL.constrained.unwrap();
    let names = model.info().coordinates;
    let at = |name: &str| names.iter().position(|c| *c == name).unwrap();
    let q = vec![0.0; names.len()];
    let shape = [at("theta"), at("phi")];
    for spin in [0.3, 0.5, 0.577, 0.6, 1.0, 2.0] {
        let held = [(at("psi"), spin)];
        let settings = SteadySettings {
            q: &q,
            shape: &shape,
            held: &held,
        };
        let motion = steady_motion(model, &disk::Params::default().values(), &settings).unwrap();
        let squared = (1.0 - 3.0 * spin * spin) * 4.0 / 5.0;
        let (re, im) = if squared > 0.0 {
            (squared.sqrt(), 0.0)
        } else {
            (0.0, (-squared).sqrt())
        };
        let mut values = motion.eigenvalues.clone();
        values.sort_by(|a, b| (b.0.hypot(b.1)).total_cmp(&a.0.hypot(a.1)));
        println!("spin {spin}: {values:?}, Routh ±({re}, {im})");
        for (k, value) in values.iter().enumerate() {
            if k < 2 {
                assert!(
                    (value.0.abs() - re).abs() < 1e-10 && (value.1.abs() - im).abs() < 1e-10,
                    "spin {spin}: {value:?} against Routh's ±({re}, {im})"
                );
            } else {
                // The heading's zero is double and defective (φ and φ':
                // a steady turn is a neighbouring steady motion), so
                // rounding splits it by about √ε, and by 3e-7 next to the
                // threshold, where the tilt's pair nears it.
                assert!(value.0.hypot(value.1) < 1e-6, "spin {spin}: {value:?}");
            }
        }
    }
    // Without the heading in the shape, its rate is fixed by nothing: the
    // linearisation says so rather than holding it silently.
    let held = [(at("psi"), 1.0)];
    let tilt_only = SteadySettings {
        q: &q,
        shape: &shape[..1],
        held: &held,
    };
    let e = steady_motion(model, &disk::Params::default().values(), &tilt_only).unwrap_err();
    assert!(matches!(e, SteadyMotionError::Undetermined { .. }), "{e}");
    assert!(e.to_string().contains("'phi'"), "{e}");
}

/// The analysis by name (`steady_motion`, as the scene, the studio and
/// Python run it) finds the speed (the rear wheel's forward motion x'),
/// the shape (lean and steer) and what to hold by itself, and its stated
/// errors bound its distance to the benchmark: the eigenvalues at 5 m/s
/// and the weave and capsize speeds.
#[test]
fn the_analysis_by_name_finds_the_bicycle_s_shape_and_bounds_its_errors() {
    use mechlab::analysis::declared::{no_progress, Analysis};
    use mechlab::analysis::on_constraints::steady::study::SteadyMotionOptions;
    use mechlab::analysis::on_constraints::steady::Verdict;
    let options = SteadyMotionOptions {
        at: Some(5.0),
        sweep: 21,
        sweep_range: Some([0.0, 10.0]),
        ..Default::default()
    };
    let study = options
        .run(
            &bicycle::MODEL,
            &bicycle::Params::default().values(),
            &no_progress,
        )
        .unwrap();
    assert_eq!(study.speed, "x");
    let mut shape = study.shape.clone();
    shape.sort();
    assert_eq!(shape, ["delta", "phi"]);
    let motion = &study.motion;
    assert_eq!(motion.eigenvalues.len(), 4, "{:?}", motion.reduced);
    assert_eq!(motion.verdict, Verdict::AsymptoticallyStable);
    for (g, e) in motion.eigenvalues.iter().zip(&motion.errors) {
        let missed = AT_FIVE
            .iter()
            .map(|w| (g.0 - w.0).hypot(g.1.abs() - w.1.abs()))
            .fold(f64::INFINITY, f64::min);
        println!("{g:?} ± {e:e}: {missed:e} from the benchmark");
        // The benchmark's 14 digits: within its rounding or the bound.
        assert!(
            missed <= e + 1e-14 && *e < 1e-10,
            "{g:?}: {missed:e} > {e:e}"
        );
    }
    let sweep = study.sweep.unwrap();
    let [weave, capsize] = sweep.boundaries[..] else {
        panic!("two boundaries in 0..10 m/s, not {:?}", sweep.boundaries);
    };
    for (found, published) in [(weave, WEAVE_SPEED), (capsize, CAPSIZE_SPEED)] {
        let missed = (found.speed - published).abs();
        println!("{found:?}: {missed:e} from {published}");
        assert!(
            missed <= found.error + 1e-13 && found.error < 1e-8,
            "{found:?}"
        );
    }
}

/// Chaplygin's sleigh gliding straight at speed u, by name on the model
/// file of `models/` (written before steady motions were): the analysis
/// finds no shape, holds the heading's rate (which the blade leaves free)
/// and drops the speed (a neighbouring steady motion). The reduced
/// equation J ω' = −m b u ω (J = I + m b²) gives the one eigenvalue
/// −m b u / J: stable forwards, unstable backwards, the boundary at u = 0.
#[test]
fn a_sleigh_glides_stably_forwards_and_not_backwards() {
    use mechlab::analysis::declared::{no_progress, Analysis};
    use mechlab::analysis::on_constraints::steady::study::SteadyMotionOptions;
    let model = mechlab::models::by_name("chaplygin_sleigh").unwrap();
    let params = model.dynamic.defaults();
    let value = |name: &str| {
        params[model
            .info
            .parameter_names
            .iter()
            .position(|p| *p == name)
            .unwrap()]
    };
    let (m, b, i) = (value("m"), value("b"), value("I"));
    for u in [2.0, 0.5, -1.5] {
        let options = SteadyMotionOptions {
            at: Some(u),
            sweep: 40,
            ..Default::default()
        };
        let study = options.run(model, &params, &no_progress).unwrap();
        assert_eq!((study.speed.as_str(), study.shape.len()), ("x", 0));
        assert_eq!(study.motion.reduced, ["phi'"]);
        let exact = -m * b * u / (i + m * b * b);
        let (got, error) = (study.motion.eigenvalues[0], study.motion.errors[0]);
        println!("u = {u}: {got:?} ± {error:e} against {exact}");
        assert!(
            (got.0 - exact).abs() <= error && got.1 == 0.0,
            "{got:?} vs {exact}"
        );
        assert_eq!(study.motion.verdict.is_unstable(), u < 0.0);
        let sweep = study.sweep.unwrap();
        let [boundary] = sweep.boundaries[..] else {
            panic!("one boundary, not {:?}", sweep.boundaries);
        };
        assert!(
            boundary.unstable_below && boundary.speed.abs() <= boundary.error + 1e-12,
            "{boundary:?}"
        );
    }
}

/// The tipping disk by name: the analysis finds the tilt as the shape
/// and holds the heading's rate; the tilt's pair is Routh's, as above.
#[test]
fn the_analysis_by_name_finds_the_disk_s_tilt() {
    use mechlab::analysis::declared::{no_progress, Analysis};
    use mechlab::analysis::on_constraints::steady::study::SteadyMotionOptions;
    use mechlab_test_models::tipping_disk_body as disk;
    for spin in [0.5, 2.0] {
        let options = SteadyMotionOptions {
            speed: Some("psi".into()),
            at: Some(spin),
            sweep: 0,
            ..Default::default()
        };
        let study = options
            .run(
                &disk::MODEL,
                &disk::Params::default().values(),
                &no_progress,
            )
            .unwrap();
        assert_eq!(study.shape, ["theta"]);
        let squared = (1.0 - 3.0 * spin * spin) * 4.0 / 5.0;
        let motion = &study.motion;
        println!(
            "{:?}: {:?} ± {:?}, {}",
            motion.reduced, motion.eigenvalues, motion.errors, motion.verdict
        );
        let routh = motion
            .eigenvalues
            .iter()
            .zip(&motion.errors)
            .filter(|(v, e)| {
                let (re, im) = (v.0.abs(), v.1.abs());
                (re * re - im * im - squared).abs() <= 4.0 * (re + im + 1.0) * **e
                    && re.max(im) > 0.1
            });
        assert_eq!(
            routh.count(),
            2,
            "Routh's pair λ² = {squared} among {:?}",
            motion.eigenvalues
        );
        assert_eq!(
            motion.verdict.is_unstable(),
            squared > 0.0,
            "{}",
            motion.verdict
        );
    }
}

/// `steady_motion` on every model file of `models/`, at its defaults: a
/// linearisation whose verdict follows from its eigenvalues and errors,
/// whose eigenvalues sum to its matrix's trace and whose shape stands
/// still, or a typed refusal that names the model. Never a panic or NaN.
#[test]
fn steady_motion_runs_on_every_model_or_says_why_not() {
    use mechlab::analysis::declared::{no_progress, Analysis};
    use mechlab::analysis::on_constraints::steady::study::SteadyMotionOptions;
    use mechlab::analysis::on_constraints::steady::Verdict;
    let options = SteadyMotionOptions {
        sweep: 5,
        ..Default::default()
    };
    let mut linearised = 0;
    for info in mechlab::models::ALL {
        let model = mechlab::models::by_name(info.name).unwrap();
        match options.run(model, &model.dynamic.defaults(), &no_progress) {
            Ok(study) => {
                let motion = &study.motion;
                assert_eq!(
                    motion.eigenvalues.len(),
                    motion.reduced.len(),
                    "{}",
                    info.name
                );
                let values = motion.eigenvalues.iter().flat_map(|v| [v.0, v.1]);
                assert!(
                    values
                        .chain(motion.errors.iter().copied())
                        .all(f64::is_finite),
                    "{}: {:?}",
                    info.name,
                    motion.eigenvalues
                );
                assert_eq!(
                    motion.verdict,
                    Verdict::of(&motion.eigenvalues, &motion.errors)
                );
                let trace = motion.matrix.trace();
                let sum: f64 = motion.eigenvalues.iter().map(|v| v.0).sum();
                let bound: f64 = motion.errors.iter().sum::<f64>() + 1e-12 * (1.0 + trace.abs());
                assert!(
                    (trace - sum).abs() <= bound,
                    "{}: trace {trace}, Σλ {sum}",
                    info.name
                );
                let n = info.coordinates.len();
                for name in &study.shape {
                    let i = info.coordinates.iter().position(|c| c == name).unwrap();
                    // A constrained model's state is [q; q']: the shape's rate is 0.
                    if model.constrained.is_some() {
                        assert!(motion.state[n + i].abs() < 1e-12, "{}: {name}'", info.name);
                    }
                }
                linearised += 1;
                println!(
                    "{}: {} ({} eigenvalues)",
                    info.name,
                    motion.verdict,
                    motion.eigenvalues.len()
                );
            }
            Err(e) => {
                let text = e.to_string();
                println!("{}: refused: {text}", info.name);
                assert!(
                    text.contains(info.name),
                    "the refusal names the model: {text}"
                );
            }
        }
    }
    assert!(linearised > 0, "no model's steady motion was linearised");
}
