//! The stiff flyball governor, the IFToMM benchmark A05
//! (`test_models/iftomm_flyball_governor.toml`), against its angular
//! momentum, energy and steady spin written out here by hand.

use mechlab::ode::{states_at, Method};
use mechlab_test_models::iftomm_flyball_governor::{Exact, Params};
use std::f64::consts::TAU;

const ROD: f64 = 0.3; // kg: 1 m x 1 cm x 1 cm at 3000 kg/m^3
const ROD_ACROSS: f64 = ROD * (1.0 + 1e-4) / 12.0;
const ROD_ALONG: f64 = ROD * 2e-4 / 12.0;
const SLIDER: f64 = 3.0; // kg: a 10 cm cube
const SLIDER_SPIN: f64 = SLIDER * 2e-2 / 12.0;
const OFFSET: f64 = 0.05; // the hinges off the axis (m)
const BALL: f64 = 5.0;
const GRAVITY: f64 = 9.81;
const K: f64 = 8e5;
const REST: f64 = 0.5;

/// The whole governor's moment of inertia about the shaft with its rods
/// at b₁, b₂ from the upward shaft: shaft and slider spinning, each rod's
/// centre and ball off the axis, each rod's own moment about the vertical.
fn spin_inertia(b: [f64; 2]) -> f64 {
    let own = ROD_ALONG + SLIDER_SPIN;
    own + b
        .iter()
        .map(|b| {
            let (s, c) = b.sin_cos();
            ROD * (OFFSET + 0.5 * s).powi(2)
                + ROD_ACROSS * s * s
                + ROD_ALONG * c * c
                + BALL * (OFFSET + s).powi(2)
        })
        .sum::<f64>()
}

/// The springs' length: from the slider's hook (5 cm off the axis at the
/// slider's height) to the rod's centre, in the shaft's plane.
fn spring(s: f64, b: f64) -> f64 {
    (0.5 * b.sin()).hypot(1.0 + 0.5 * b.cos() - s)
}

/// Gravity's and the springs' potential.
fn potential(s: f64, b: [f64; 2]) -> f64 {
    let mut v = GRAVITY * (ROD * 0.5 + SLIDER * s);
    for b in b {
        v += GRAVITY * (ROD * (1.0 + 0.5 * b.cos()) + BALL * (1.0 + b.cos()));
        v += K * (spring(s, b) - REST).powi(2) / 2.0;
    }
    v
}

/// Each rod's moment about its hinge, with its ball.
const SWING: f64 = ROD_ACROSS + ROD * 0.25 + BALL;

/// T + V from the state [φ, s, b₁, b₂, p_φ, p_s, p_b₁, p_b₂]: the spin's
/// energy p_φ²/2I, the slider's sliding and each rod's swing about its
/// hinge, which moves at right angles to the spin and adds no cross term.
fn energy(y: &[f64; 8]) -> f64 {
    let b = [y[2], y[3]];
    y[4] * y[4] / (2.0 * spin_inertia(b))
        + y[5] * y[5] / (2.0 * SLIDER)
        + (y[6] * y[6] + y[7] * y[7]) / (2.0 * SWING)
        + potential(y[1], b)
}

/// The steady spin with angular momentum `momentum`: the rest point of
/// Routh's amended potential W(s, b) = V(s, b, b) + L²/2I(b), by Newton's
/// method on its gradient (central differences), from `guess`.
fn steady(momentum: f64, guess: [f64; 2]) -> [f64; 2] {
    let w = |x: [f64; 2]| {
        potential(x[0], [x[1]; 2]) + momentum.powi(2) / (2.0 * spin_inertia([x[1]; 2]))
    };
    let gradient = |x: [f64; 2]| {
        let h = 1e-6;
        [0, 1].map(|i| {
            let (mut up, mut down) = (x, x);
            up[i] += h;
            down[i] -= h;
            (w(up) - w(down)) / (2.0 * h)
        })
    };
    let mut x = guess;
    for _ in 0..50 {
        let g = gradient(x);
        let h = 1e-5;
        let column = |i: usize| {
            let (mut up, mut down) = (x, x);
            up[i] += h;
            down[i] -= h;
            let (a, b) = (gradient(up), gradient(down));
            [(a[0] - b[0]) / (2.0 * h), (a[1] - b[1]) / (2.0 * h)]
        };
        let (c0, c1) = (column(0), column(1));
        let det = c0[0] * c1[1] - c1[0] * c0[1];
        x[0] -= (g[0] * c1[1] - c1[0] * g[1]) / det;
        x[1] -= (c0[0] * g[1] - g[0] * c0[1]) / det;
    }
    x
}

/// The springs' rates of stretch, from the state's momenta (s' = p_s/m,
/// b' = p_b/J).
fn stretch_rates(y: &[f64; 8]) -> [f64; 2] {
    let sd = y[5] / SLIDER;
    [2, 3].map(|k| {
        let (b, bd) = (y[k], y[k + 4] / SWING);
        let h = 1e-6;
        let ds = (spring(y[1] + h, b) - spring(y[1] - h, b)) / (2.0 * h);
        let db = (spring(y[1], b + h) - spring(y[1], b - h)) / (2.0 * h);
        ds * sd + db * bd
    })
}

/// The benchmark's start: rods 120° from the upward shaft, slider 0.5 m
/// up, the shaft at 2π rad/s; as the state [q, p] the generated
/// equations integrate, p_φ = 2π I(b).
fn benchmark_start() -> [f64; 8] {
    let b0 = TAU / 3.0;
    [
        0.0,
        0.5,
        b0,
        b0,
        TAU * spin_inertia([b0, b0]),
        0.0,
        0.0,
        0.0,
    ]
}

const RADAU: Method = Method::Radau5 {
    rtol: 1e-13,
    atol: 1e-13,
};

/// With the benchmark's angular momentum, the governor spins steadily
/// where Routh's amended potential, written out here by hand, is least:
/// started there it stays (slider and rods to 1e-8 over 10 s), though
/// the stiff springs and dampers make an explicit method take steps of
/// 1e-4 s.
#[test]
fn the_flyball_governor_spins_steadily_where_its_amended_potential_is_least() {
    let exact = Exact {
        params: Params::default(),
    };
    let momentum = benchmark_start()[4];
    let [s, b] = steady(momentum, [0.6, 2.0]);
    assert!(
        (0.0..1.0).contains(&s) && b > std::f64::consts::FRAC_PI_2,
        "{s} {b}"
    );
    let y0 = [0.0, s, b, b, momentum, 0.0, 0.0, 0.0];
    let times: Vec<f64> = (0..=100).map(|k| 0.1 * k as f64).collect();
    let states = states_at(RADAU, &exact, 0.0, &y0, &times).unwrap();
    let moved = states
        .iter()
        .map(|y| (y[1] - s).abs().max((y[2] - b).abs()).max((y[3] - b).abs()))
        .fold(0.0, f64::max);
    assert!(moved < 1e-8, "moved {moved:e} from s = {s}, b = {b}");
}

/// From the benchmark's start the governor swings out and back about its
/// steady spin for the benchmark's 10 s. Its angular momentum is kept
/// (its momentum is the state's, and the spin φ' = p/I(b) by the
/// hand-written inertia), its two rods turn alike, and its energy,
/// written out here by hand, falls by exactly the work its dampers take,
/// ∫ C (d₁'² + d₂'²) dt, to 3e-9 J of its 270 J.
#[test]
fn the_flyball_governor_loses_the_energy_its_dampers_take() {
    let exact = Exact {
        params: Params::default(),
    };
    let damper = Params::default().C;
    let y0 = benchmark_start();
    // Outputs fine enough for Simpson's rule on the dampers' power: the
    // springs' first pull decays within 1e-3 s, and their residual
    // vibration (hundreds of rad/s) rides on the swing over a second.
    let mut times = vec![0.0];
    for (step, until) in [(1e-6, 2e-3), (1e-5, 2e-2), (1e-4, 10.0)] {
        while *times.last().unwrap() < until - step / 2.0 {
            times.push(times.last().unwrap() + step);
        }
    }
    let started = std::time::Instant::now();
    let states = states_at(RADAU, &exact, 0.0, &y0, &times).unwrap();
    let seconds = started.elapsed().as_secs_f64();
    let e0 = energy(&y0);
    let power = |y: &[f64; 8]| {
        let [a, b] = stretch_rates(y);
        damper * (a * a + b * b)
    };
    // Simpson's rule over pairs of steps.
    let (mut taken, mut worst, mut asymmetry) = (0.0, 0.0_f64, 0.0_f64);
    for k in (2..states.len()).step_by(2) {
        let dt = times[k] - times[k - 1];
        taken +=
            dt / 3.0 * (power(&states[k - 2]) + 4.0 * power(&states[k - 1]) + power(&states[k]));
        worst = worst.max((energy(&states[k]) - e0 + taken).abs());
        asymmetry = asymmetry.max((states[k][2] - states[k][3]).abs());
    }
    let swing = states.iter().map(|y| y[1]).fold(0.0, f64::max);
    eprintln!(
        "flyball governor: 10 s in {seconds:.3} s (Radau5 1e-13), dampers took {taken:.3e} J, balance {worst:.1e} J, slider up to {swing:.4} m"
    );
    assert!(swing > 0.7, "the slider rose to {swing} only");
    assert!(taken > 0.0, "{taken}");
    assert!(
        worst < 3e-9,
        "energy balance off by {worst:e} J (dampers took {taken:e})"
    );
    assert!(asymmetry < 1e-9, "{asymmetry:e}");
}
