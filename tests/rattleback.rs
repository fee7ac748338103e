//! Kane and Levinson's rattleback (`test_models/rattleback.toml`): an
//! ellipsoidal body with skewed inertia rolling on a plane, its energy,
//! rolling and contact derived from the body and the ellipsoid's lowest
//! point. Checked against forms written here: the rocking frequencies at
//! rest, the time reversal of its spinning motions' spectra, its spin
//! reversal with the energy kept.

use mechlab::analysis::declared::{no_progress, Analysis};
use mechlab::analysis::on_constraints::run;
use mechlab::analysis::on_constraints::steady::study::{SteadyMotionOptions, SteadyStudy};
use mechlab::ode::Method;
use mechlab_test_models::rattleback;

fn spinning(spin: f64) -> SteadyStudy {
    let options = SteadyMotionOptions {
        speed: Some("psi".into()),
        at: Some(spin),
        sweep: 0,
        ..Default::default()
    };
    options
        .run(
            &rattleback::MODEL,
            &rattleback::Params::default().values(),
            &no_progress,
        )
        .unwrap()
}

/// At rest the rattleback rocks in two modes. With ℓ = c − h the centre of
/// mass's height over the contact and the radii of curvature a²/c (along
/// the length: pitch θ) and b²/c (across: roll φ), V ≈ m g ℓ + ½ m g
/// (a²/c − ℓ) θ² + ½ m g (b²/c − ℓ) φ² and T ≈ ½ (B + m ℓ²) θ'² +
/// D θ' φ' + ½ (A + m ℓ²) φ'²: the frequencies solve det(K − ω² M) = 0.
#[test]
fn at_rest_it_rocks_at_the_hand_written_frequencies() {
    let p = rattleback::Params::default();
    let get = |n: &str| p.get(n).unwrap();
    let (m, a, b, c, h, g) = (get("m"), get("a"), get("b"), get("c"), get("h"), get("g"));
    let (ia, ib, d) = (get("A"), get("B"), get("D"));
    let l = c - h;
    let k = nalgebra::Matrix2::new(m * g * (a * a / c - l), 0.0, 0.0, m * g * (b * b / c - l));
    let mass = nalgebra::Matrix2::new(ib + m * l * l, d, d, ia + m * l * l);
    let omega2 = (mass.try_inverse().unwrap() * k).eigenvalues().unwrap();
    let mut frequencies: Vec<f64> = omega2.iter().map(|w| w.sqrt()).collect();
    frequencies.sort_by(f64::total_cmp);
    let study = spinning(0.0);
    let mut shape = study.shape.clone();
    shape.sort();
    assert_eq!(shape, ["phi", "theta"]);
    let motion = &study.motion;
    let mut rocking: Vec<f64> = motion
        .eigenvalues
        .iter()
        .filter(|v| v.1 > 1.0)
        .map(|v| v.1)
        .collect();
    rocking.sort_by(f64::total_cmp);
    println!(
        "{:?} ± {:?}; by hand {frequencies:?}",
        motion.eigenvalues, motion.errors
    );
    assert_eq!(rocking.len(), 2, "{:?}", motion.eigenvalues);
    for (got, want) in rocking.iter().zip(&frequencies) {
        assert!((got - want).abs() < 1e-9 * want, "{got} against {want}");
    }
    for (v, e) in motion.eigenvalues.iter().zip(&motion.errors) {
        assert!(
            v.0.abs() <= *e,
            "at rest no eigenvalue grows or decays: {v:?} ± {e:e}"
        );
    }
}

/// Rolling without slipping does no work and the equations are reversible
/// in time, which maps the spin ω to −ω: the spectrum at −ω is the
/// negative of that at ω, so a mode that decays one way grows the other.
/// The skew couples the spin to the rocking (Walker, 1896): the pitch
/// mode grows spun one way, the slower roll mode the other.
#[test]
fn time_reversal_mirrors_the_spinning_spectrum() {
    for spin in [1.0, 3.0, 8.0] {
        let (plus, minus) = (spinning(spin), spinning(-spin));
        println!("{spin}: {} / {}", plus.motion.verdict, minus.motion.verdict);
        for (v, e) in plus.motion.eigenvalues.iter().zip(&plus.motion.errors) {
            let mirrored = minus
                .motion
                .eigenvalues
                .iter()
                .zip(&minus.motion.errors)
                .map(|(w, f)| ((w.0 + v.0).hypot(w.1.abs() - v.1.abs()), e + f))
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .unwrap();
            assert!(
                mirrored.0 <= mirrored.1,
                "ω = {spin}: {v:?} not mirrored: {mirrored:?}"
            );
        }
        // The spin's own rate drops out (a neighbouring steady spin): the
        // pitch and roll pairs are left, and they do not sit on the axis.
        assert_eq!(
            plus.motion.eigenvalues.len(),
            4,
            "{:?}",
            plus.motion.reduced
        );
        assert!(plus.motion.verdict.is_unstable() || minus.motion.verdict.is_unstable());
    }
}

/// The direction in which the rattleback's fastest mode grows: the sign
/// of the spin whose spectral abscissa is larger.
fn wrong_way(spin: f64) -> f64 {
    let abscissa = |s: &SteadyStudy| s.motion.eigenvalues[0].0;
    if abscissa(&spinning(spin)) > abscissa(&spinning(-spin)) {
        spin
    } else {
        -spin
    }
}

/// Spun the unstable way, the rattleback rocks, stops and spins the
/// other way, its energy kept to 1e-10 of itself and its rolling kept.
#[test]
fn spun_the_wrong_way_it_reverses_with_its_energy_kept() {
    let model = rattleback::MODEL.constrained.unwrap();
    let params = rattleback::Params::default().values();
    let wrong = wrong_way(3.0);
    let n = 5;
    let mut y0 = vec![0.0; 2 * n];
    y0[3] = 0.005; // a small pitch
    y0[n + 2] = wrong;
    let times: Vec<f64> = (0..=400).map(|k| 0.05 * k as f64).collect();
    let result = run(
        model,
        &params,
        Some(&y0),
        Method::Dop853 {
            rtol: 1e-12,
            atol: 1e-12,
        },
        &times,
    )
    .unwrap();
    let yaw_rates: Vec<f64> = result.states.iter().map(|s| s[n + 2]).collect();
    let reversed = yaw_rates
        .iter()
        .position(|r| r * wrong < -0.1 * wrong * wrong);
    println!(
        "yaw rate from {wrong}: reversed at {:?}",
        reversed.map(|k| times[k])
    );
    let least = yaw_rates
        .iter()
        .fold(f64::INFINITY, |m, r| m.min(r * wrong.signum()));
    assert!(
        reversed.is_some(),
        "no reversal in 20 s (least yaw rate {least})"
    );
    let e0 = result.energy[0];
    let drift = result
        .energy
        .iter()
        .fold(0.0_f64, |m, e| m.max((e - e0).abs()));
    println!(
        "energy {e0}, drift {drift:e}, residuals {:?}",
        result.largest_residual
    );
    assert!(drift <= 1e-10 * e0.abs(), "energy drift {drift:e} of {e0}");
    assert!(
        result.largest_residual.1 < 1e-12,
        "{:?}",
        result.largest_residual
    );
}
