//! Frequency analysis (NAFF): the transform against the direct sum, the
//! frequencies' error falling as T⁻⁴ with the Hanning window, uncoupled
//! oscillators' frequencies and amplitudes, and the pendulum's frequency
//! against its closed form through the arithmetic–geometric mean.

use mechlab::analysis::frequency::{fft, naff, FrequencyError, NaffSettings};
use mechlab::ode::Method;
use nalgebra::Complex;
use std::f64::consts::PI;

fn sampled(f: impl Fn(f64) -> Complex<f64>, dt: f64, n: usize) -> Vec<Complex<f64>> {
    (0..n).map(|j| f(j as f64 * dt)).collect()
}

#[test]
fn the_fft_is_the_direct_sum() {
    let x = sampled(|t| Complex::new((3.0 * t).sin() + t * t, t.cos()), 0.37, 64);
    let mut transformed = x.clone();
    fft(&mut transformed);
    for (k, got) in transformed.iter().enumerate() {
        let direct: Complex<f64> = x
            .iter()
            .enumerate()
            .map(|(j, z)| z * Complex::from_polar(1.0, -2.0 * PI * (j * k) as f64 / 64.0))
            .sum();
        assert!(
            (got - direct).norm() < 1e-11 * (1.0 + direct.norm()),
            "bin {k}"
        );
    }
}

/// Two incommensurate terms: the first frequency's error over times T
/// from 200 to 3200 falls as T⁻⁴ with the Hanning window (Laskar's
/// T^−(2p+2), p = 1: the least-squares slope of log error against log T
/// below −3.5, and error·T⁴ within a factor 20 of itself, the error
/// oscillating with T), and only as T⁻² without a window (p = 0).
#[test]
fn the_frequency_error_falls_as_the_fourth_power_of_the_time() {
    let (w1, w2) = (1.234_567_8, 0.765_432_1 * 2f64.sqrt());
    let signal = |t: f64| Complex::from_polar(1.0, w1 * t) + Complex::from_polar(0.4, w2 * t + 0.3);
    let dt = 0.25;
    let times: Vec<f64> = (0..9).map(|k| 200.0 * 2f64.powf(k as f64 / 2.0)).collect();
    let errors = |window_order| -> Vec<f64> {
        times
            .iter()
            .map(|&time| {
                let n = (time / dt) as usize + 1;
                let settings = NaffSettings {
                    terms: 2,
                    window_order,
                };
                let terms = naff(&sampled(signal, dt, n), dt, &settings).unwrap();
                (terms[0].frequency - w1).abs()
            })
            .collect()
    };
    let slope = |errors: &[f64]| {
        let (x, y): (Vec<f64>, Vec<f64>) = times
            .iter()
            .zip(errors)
            .map(|(t, e)| (t.ln(), e.ln()))
            .unzip();
        let (mx, my) = (x.iter().sum::<f64>() / 9.0, y.iter().sum::<f64>() / 9.0);
        let covariance: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
        covariance / x.iter().map(|a| (a - mx).powi(2)).sum::<f64>()
    };
    let hanning = errors(1);
    let scaled: Vec<f64> = hanning
        .iter()
        .zip(&times)
        .map(|(e, t)| e * t.powi(4))
        .collect();
    let (low, high) = scaled
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(l, h), &s| (l.min(s), h.max(s)));
    assert!(
        slope(&hanning) < -3.5,
        "slope {} of {hanning:?}",
        slope(&hanning)
    );
    assert!(high / low < 20.0, "error·T⁴ {scaled:?}");
    let bare = errors(0);
    assert!(
        slope(&bare) > -2.6,
        "without a window: slope {} of {bare:?}",
        slope(&bare)
    );
}

/// Two uncoupled oscillators' signal: both frequencies to 1e-12 and their
/// amplitudes (with phases) to 1e-8, in decreasing order of amplitude;
/// the terms after them are rounding (amplitudes below 1e-8).
#[test]
fn uncoupled_oscillators_give_their_frequencies_and_amplitudes() {
    let a1 = Complex::from_polar(2.0, 0.7);
    let a2 = Complex::from_polar(0.5, -1.1);
    let (w1, w2) = (0.9, -2.0_f64.sqrt());
    let signal =
        |t: f64| a1 * Complex::from_polar(1.0, w1 * t) + a2 * Complex::from_polar(1.0, w2 * t);
    let terms = naff(&sampled(signal, 0.1, 20_001), 0.1, &NaffSettings::default()).unwrap();
    // Past the two terms only the rounding is left.
    assert!(
        terms[2..].iter().all(|t| t.amplitude.norm() < 1e-8),
        "{terms:?}"
    );
    assert!((terms[0].frequency - w1).abs() < 1e-12, "{terms:?}");
    assert!((terms[1].frequency - w2).abs() < 1e-12, "{terms:?}");
    assert!((terms[0].amplitude - a1).norm() < 1e-8, "{terms:?}");
    assert!((terms[1].amplitude - a2).norm() < 1e-8, "{terms:?}");
}

/// The pendulum q'' = −√2 sin q from rest at θ₀ librates with the angular
/// frequency ω = 2^{1/4} AGM(1, cos(θ₀/2)) (its period 4K(k)/2^{1/4} with
/// k = sin(θ₀/2) and K(k) = π / (2 AGM(1, √(1 − k²)))): NAFF of q + i p
/// over 2000 time units gives it to 1e-11.
#[test]
fn the_pendulums_frequency_is_its_elliptic_closed_form() {
    use crate::common::agm;
    let model = &mechlab_test_models::bare_pendulum::MODEL;
    let system = model.systems().unwrap().exact(&[]);
    for theta in [0.5, 2.0, 3.0] {
        let dt = 0.1;
        let times: Vec<f64> = (0..=20_000).map(|j| j as f64 * dt).collect();
        let states = system
            .states_at(Method::Taylor { tol: 1e-15 }, 0.0, &[theta, 0.0], &times)
            .unwrap();
        let signal: Vec<Complex<f64>> = states.iter().map(|y| Complex::new(y[0], y[1])).collect();
        let terms = naff(&signal, dt, &NaffSettings::default()).unwrap();
        let expected = 2f64.powf(0.25) * agm(1.0, (theta / 2.0).cos());
        let got = terms[0].frequency.abs();
        assert!(
            (got - expected).abs() < 1e-11,
            "θ₀ = {theta}: {got} against {expected}"
        );
    }
}

#[test]
fn bad_signals_are_named() {
    let settings = NaffSettings::default();
    let short = vec![Complex::new(1.0, 0.0); 8];
    assert_eq!(
        naff(&short, 0.1, &settings),
        Err(FrequencyError::TooFewSamples { given: 8 })
    );
    let mut signal = vec![Complex::new(1.0, 0.0); 64];
    assert_eq!(
        naff(&signal, 0.0, &settings),
        Err(FrequencyError::Step(0.0))
    );
    signal[5].im = f64::NAN;
    assert_eq!(
        naff(&signal, 0.1, &settings),
        Err(FrequencyError::NotFinite { index: 5 })
    );
    signal[5].im = 0.0;
    let many = NaffSettings {
        terms: 17,
        window_order: 1,
    };
    assert_eq!(
        naff(&signal, 0.1, &many),
        Err(FrequencyError::Terms { given: 17, max: 16 })
    );
}

/// A period map's tunes: a libration about an offset centre, (3, 1) +
/// r e^{−2πiνn} (turning clockwise in (q, p), as Hamilton's equations turn
/// a libration), and a circulating angle q = 0.3 + 2πνn (wrapped to
/// [−π, π) as a plane shows it) give +ν to 1e-10, and a constant tune a
/// diffusion index at the rounding.
#[test]
fn tunes_of_a_libration_and_a_circulation() {
    use mechlab::analysis::frequency_map::tunes;
    let nu = 0.1234567;
    let libration: Vec<Vec<f64>> = (0..1024)
        .map(|n| {
            let phase = 2.0 * PI * nu * n as f64;
            vec![3.0 + 0.2 * phase.cos(), 1.0 - 0.2 * phase.sin()]
        })
        .collect();
    let (got, index) = tunes(&libration, &[false, false]);
    assert!((got[0] - nu).abs() < 1e-10, "{got:?}");
    assert!(index < -9.0, "{index}");
    let circulation: Vec<Vec<f64>> = (0..1024)
        .map(|n| {
            let q = 0.3 + 2.0 * PI * nu * n as f64;
            vec![(q + PI).rem_euclid(2.0 * PI) - PI, 1.0]
        })
        .collect();
    let (got, _) = tunes(&circulation, &[true, false]);
    assert!((got[0] - nu).abs() < 1e-10, "{got:?}");
}

/// The tune of the libration through (q, p) of the pendulum
/// H = p²/2 + cos q under the period map of period 2πε: ε ω(φ₀), with
/// ω = AGM(1, cos(φ₀/2)) at the amplitude φ₀ about the hanging state.
fn pendulum_tune(q: f64, p: f64, eps: f64) -> f64 {
    let amplitude = (-(p * p / 2.0 + q.cos())).acos();
    // (Quadratic convergence: 8 steps reach the rounding from any a, b.)
    let (mut a, mut b) = (1.0f64, (amplitude / 2.0).cos());
    for _ in 0..8 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    eps * a
}

/// Kapitza's pendulum without vibration (A = 0) is the pendulum
/// H = p²/2 + cos q: its period map (period 2πε) turns each libration of
/// amplitude φ₀ about the hanging state (clockwise) by ε ω(φ₀) turns, with
/// ω = AGM(1, cos(φ₀/2)), the closed form derived in the test above. The
/// frequency map's tunes equal it to 1e-8 at every pixel well inside the
/// separatrix (E < 0.9), where the diffusion index is below −7.
#[test]
fn the_unshaken_pendulums_period_map_has_the_closed_form_tunes() {
    use mechlab::analysis::chaos_map::ChaosMapSettings;
    use mechlab::analysis::frequency_map::period_map_frequencies;
    let model = mechlab::models::by_name("kapitza").unwrap();
    let eps = 0.1;
    let ranges = [(1.2, 5.0), (-1.5, 1.5)];
    let settings = ChaosMapSettings {
        check: 0,
        accuracy: None,
        axes: [0, 1],
        ranges: ranges.map(Some),
        p_max: 1.0,
        through: None,
        pixels: 12,
        periods: 1024,
        method: Method::Taylor { tol: 1e-12 },
        tiles: None,
    };
    let map = period_map_frequencies(model, &[0.0, eps, 0.0], &settings, &|_| ()).unwrap();
    let mut checked = 0;
    for k in 0..144 {
        let centre = |(lo, hi): (f64, f64), i: usize| lo + (hi - lo) * (i as f64 + 0.5) / 12.0;
        let (q, p) = (centre(ranges[0], k % 12), centre(ranges[1], k / 12));
        let energy = p * p / 2.0 + q.cos();
        if energy >= 0.9 {
            continue;
        }
        let expected = pendulum_tune(q, p, eps);
        let got = map.frequencies[k][0];
        assert!(
            (got - expected).abs() < 1e-8,
            "({q}, {p}): {got} against {expected}"
        );
        assert!(map.diffusion[k] < -7.0, "({q}, {p}): {}", map.diffusion[k]);
        checked += 1;
    }
    assert!(checked > 60, "{checked} pixels inside the separatrix");
}

/// The tunes' stated error is their error: at a loose tolerance, where the
/// integration decides it, the tune check (a rerun at a hundredth of the
/// tolerance) states the largest and the median change within a factor 2
/// of the tunes' distance to the closed form above, on librations well
/// inside the separatrix.
#[test]
fn the_tunes_stated_error_is_their_distance_to_the_closed_form() {
    use mechlab::analysis::frequency_map::period_map_frequencies;
    let model = mechlab::models::by_name("kapitza").unwrap();
    let (eps, ranges) = (0.1, LIBRATIONS);
    let settings = librations(None);
    let map = period_map_frequencies(model, &[0.0, eps, 0.0], &settings, &|_| ()).unwrap();
    let errors: Vec<f64> = (0..64)
        .map(|k| {
            let centre = |(lo, hi): (f64, f64), i: usize| lo + (hi - lo) * (i as f64 + 0.5) / 8.0;
            let (q, p) = (centre(ranges[0], k % 8), centre(ranges[1], k / 8));
            (map.frequencies[k][0] - pendulum_tune(q, p, eps)).abs()
        })
        .collect();
    assert_eq!(errors.len(), 64);
    crate::common::assert_tune_check_states(&map.tune_check.unwrap(), errors);
}

/// Tunes asked to an accuracy: from DOP853 at 1e-7, whose tunes are off
/// by up to some 1e-8 (the test above), `accuracy = 1e-10` tightens the
/// tolerance until the check's largest change is within it, and then every
/// tune lies within twice that of its closed form.
#[test]
fn tunes_asked_to_an_accuracy_meet_the_closed_form() {
    use mechlab::analysis::frequency_map::period_map_frequencies;
    let model = mechlab::models::by_name("kapitza").unwrap();
    let (eps, ranges, accuracy) = (0.1, LIBRATIONS, 1e-10);
    let settings = librations(Some(accuracy));
    let map = period_map_frequencies(model, &[0.0, eps, 0.0], &settings, &|_| ()).unwrap();
    let said = map.accuracy.clone().unwrap();
    assert!(said.contains("reached") && !said.contains("NOT"), "{said}");
    assert!(
        map.tune_check.as_ref().unwrap().largest <= accuracy,
        "{said}"
    );
    let worst = (0..64).fold(0.0_f64, |worst, k| {
        let centre = |(lo, hi): (f64, f64), i: usize| lo + (hi - lo) * (i as f64 + 0.5) / 8.0;
        let (q, p) = (centre(ranges[0], k % 8), centre(ranges[1], k / 8));
        worst.max((map.frequencies[k][0] - pendulum_tune(q, p, eps)).abs())
    });
    eprintln!("{said}; largest distance to the closed form {worst:e}");
    assert!(worst <= 2.0 * accuracy, "{worst:e} ({said})");
}

/// Kapitza's pendulum at A = 0 around its hanging position, well inside
/// the separatrix: 8² librations of 1024 periods by DOP853 at 1e-7, where
/// the integration decides the tunes' error.
const LIBRATIONS: [(f64, f64); 2] = [(2.2, 4.0), (-0.6, 0.6)];

fn librations(accuracy: Option<f64>) -> mechlab::analysis::chaos_map::ChaosMapSettings {
    mechlab::analysis::chaos_map::ChaosMapSettings {
        check: 64,
        accuracy,
        axes: [0, 1],
        ranges: LIBRATIONS.map(Some),
        p_max: 1.0,
        through: None,
        pixels: 8,
        periods: 1024,
        method: Method::Dop853 {
            rtol: 1e-7,
            atol: 1e-7,
        },
        tiles: None,
    }
}
