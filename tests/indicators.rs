//! The chaos indicators against closed forms, not against themselves:
//! MEGNO ⟨Y⟩ and the FLI of the pendulum (Kapitza's model at A = 0:
//! q' = p, p' = sin q) at its saddle (0, 0), whose tangent vector from
//! (1, 0) is (cosh t, sinh t); on a libration, where the tangent vector
//! grows linearly (⟨Y⟩ → 2, FLI ≈ ln t); and of two uncoupled harmonic
//! oscillators (Hénon–Heiles at λ = 0), isochronous, where it stays bounded
//! (⟨Y⟩ → 0). In a chaotic sea ⟨Y⟩ grows as λt/2, with λ from Benettin's
//! algorithm on the same orbit (QR of the tangent flow, not MEGNO's
//! integrals).

use mechlab::analysis::lyapunov::{fast_lyapunov_indicator, lyapunov_spectrum, megno_values};
use mechlab::models::{henon_heiles, kapitza};
use mechlab::ode::{Integrator, LaneIntegrator, Method};

fn pendulum() -> kapitza::Exact {
    kapitza::Exact {
        params: kapitza::Params {
            A: 0.0,
            eps: 0.1,
            mu: 0.0,
        },
    }
}

fn taylor() -> Method {
    Method::Taylor { tol: 1e-14 }
}

/// ⟨Y⟩ after `chunks` chunks of length `h` of a tangent vector whose
/// log-growth is `log_norm(t)`: the definition's integrals by the same
/// trapezoid rule the indicator uses.
fn megno_of(log_norm: impl Fn(f64) -> f64, h: f64, chunks: usize) -> f64 {
    let (mut l, mut l_integral, mut y, mut y_integral) = (0.0, 0.0, 0.0, 0.0);
    for k in 1..=chunks {
        let t = k as f64 * h;
        let next = log_norm(t);
        l_integral += 0.5 * h * (l + next);
        l = next;
        let next_y = 2.0 * (l - l_integral / t);
        y_integral += 0.5 * h * (y + next_y);
        y = next_y;
    }
    y_integral / (chunks as f64 * h)
}

/// At the saddle, ‖w(t)‖ = √cosh 2t: ⟨Y⟩ is the closed form's to 1e-9, and
/// grows as λt/2 with λ = 1; the FLI after n steps is ½ ln cosh 2t.
#[test]
fn at_the_saddle_megno_and_fli_are_the_closed_forms() {
    let (h, chunks) = (0.1, 300);
    let mut lanes = LaneIntegrator::new(taylor()).unwrap();
    let megno = megno_values::<_, 2, 4>(
        &mut lanes,
        &pendulum(),
        h,
        &[[0.0, 0.0]],
        &[1.0, 0.0],
        chunks,
    );
    let megno = megno[0].clone().unwrap();
    let exact = megno_of(|t| 0.5 * (2.0 * t).cosh().ln(), h, chunks);
    assert!(
        (megno - exact).abs() < 1e-9 * exact,
        "⟨Y⟩ {megno} vs {exact}"
    );
    let t = h * chunks as f64;
    assert!(
        (megno / (0.5 * t) - 1.0).abs() < 0.1,
        "⟨Y⟩ {megno} at t = {t}"
    );
    let mut integrator = Integrator::new(taylor()).unwrap();
    let fli = fast_lyapunov_indicator::<_, 2, 4>(
        &mut integrator,
        &pendulum(),
        0.5,
        &[0.0, 0.0],
        &[1.0, 0.0],
        40,
    )
    .unwrap();
    let closed = 0.5 * (2.0 * 20.0f64).cosh().ln();
    assert!(
        (fli - closed).abs() < 1e-9 * closed,
        "FLI {fli} vs {closed}"
    );
}

/// On a libration of the pendulum (about the hanging q = π) the frequency
/// changes with the amplitude, so the tangent vector grows linearly:
/// ⟨Y⟩ → 2 and the FLI grows by ln 4 when the run is four times longer.
#[test]
fn on_a_libration_megno_tends_to_two_and_the_fli_to_ln_t() {
    let start = [std::f64::consts::PI - 0.8, 0.0];
    let mut lanes = LaneIntegrator::new(taylor()).unwrap();
    // ⟨Y⟩ = 2 − O(ln t / t): four times longer, at least 2.5 times closer.
    let mut megno = |chunks| {
        let values =
            megno_values::<_, 2, 4>(&mut lanes, &pendulum(), 0.5, &[start], &[1.0, 0.0], chunks);
        values[0].clone().unwrap()
    };
    let (shorter, longer) = (megno(8000), megno(32000));
    assert!(
        (longer - 2.0).abs() < 0.02 && (longer - 2.0).abs() * 2.5 < (shorter - 2.0).abs(),
        "⟨Y⟩ = {shorter} at t = 4000, {longer} at t = 16000"
    );
    let fli = |periods| {
        let mut integrator = Integrator::new(taylor()).unwrap();
        fast_lyapunov_indicator::<_, 2, 4>(
            &mut integrator,
            &pendulum(),
            1.0,
            &start,
            &[1.0, 0.0],
            periods,
        )
        .unwrap()
    };
    let growth = fli(4000) - fli(1000);
    assert!((growth - 4f64.ln()).abs() < 0.02, "FLI grew by {growth}");
}

/// Two uncoupled harmonic oscillators are isochronous: no tangent vector
/// grows, and ⟨Y⟩ → 0.
#[test]
fn on_isochronous_oscillators_megno_tends_to_zero() {
    let free = henon_heiles::Exact {
        params: henon_heiles::Params { lambda: 0.0 },
    };
    let starts = [[0.3, 0.0, 0.1, 0.2], [0.0, 0.4, -0.2, 0.0]];
    let mut lanes = LaneIntegrator::new(taylor()).unwrap();
    for value in megno_values::<_, 4, 8>(&mut lanes, &free, 0.5, &starts, &[0.5; 4], 8000) {
        let megno = value.unwrap();
        assert!(megno.abs() < 0.02, "⟨Y⟩ = {megno}");
    }
}

/// Hénon–Heiles at E = 1/6 from a start in its chaotic sea: ⟨Y⟩ grows as
/// λt/2, with λ the largest Lyapunov exponent Benettin's algorithm gives
/// on the same orbit.
#[test]
fn in_a_chaotic_sea_megno_grows_as_lambda_t_over_two() {
    let system = henon_heiles::Exact {
        params: henon_heiles::Params { lambda: 1.0 },
    };
    // (x, y, p_x, p_y) with x = 0, y = −0.1, p_y = 0 and p_x from E = 1/6.
    let (y, py) = (-0.1f64, 0.0f64);
    let potential = 0.5 * y * y - y.powi(3) / 3.0;
    let px = (2.0 * (1.0 / 6.0 - potential) - py * py).sqrt();
    let start = [0.0, y, px, py];
    let (h, chunks) = (1.0, 20_000);
    let mut lanes = LaneIntegrator::new(taylor()).unwrap();
    let megno = megno_values::<_, 4, 8>(&mut lanes, &system, h, &[start], &[0.5; 4], chunks);
    let megno = megno[0].clone().unwrap();
    let mut integrator = Integrator::new(taylor()).unwrap();
    let (exponents, _) =
        lyapunov_spectrum::<_, 4, 20>(&mut integrator, &system, h, &start, 0, chunks, &[false; 4])
            .unwrap();
    let lambda = exponents[0] / h;
    let from_megno = 2.0 * megno / (h * chunks as f64);
    eprintln!("λ from MEGNO {from_megno}, Benettin {lambda}");
    assert!(lambda > 0.02, "λ = {lambda}: not in the chaotic sea");
    assert!(
        (from_megno / lambda - 1.0).abs() < 0.1,
        "MEGNO's λ {from_megno}, Benettin's {lambda}"
    );
}
