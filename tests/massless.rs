//! Massless parts held by constraints (`test_models/massless_arm.toml`): a
//! point on an arm of two massless rods. Its mass matrix is singular; the
//! equations solve with M + α GᵀG, which must give the motion of the
//! massless mechanism itself: rods that are not aligned carry no force,
//! so the point falls freely, x = l₁, y = −l₂ − g t²/2.

use mechlab::analysis::on_constraints::run;
use mechlab::ode::Method;
use mechlab_test_models::{massless_arm, massless_slider_crank};

const MASS: f64 = 1.0;
const UPPER: f64 = 1.0;
const LOWER: f64 = 1.0;
const GRAVITY: f64 = 9.81;

/// Released at rest with the rods at a right angle, the point falls
/// freely until the rods align, at y = −√3 (t = 0.386 s): over 0.35 s,
/// with DOP853 and Taylor, it keeps x = l₁ and y = −l₂ − g t²/2 to 1e-10,
/// the elbow stays on both rods to 1e-12, the energy holds to 1e-10 and
/// both reactions vanish to 1e-8 (a massless rod's pull must balance the
/// other's at the elbow, and they are not aligned).
#[test]
fn a_point_on_massless_rods_falls_freely_until_they_align() {
    let params = [MASS, UPPER, LOWER, GRAVITY];
    let times: Vec<f64> = (0..=350).map(|k| 1e-3 * k as f64).collect();
    for method in [
        Method::Dop853 {
            rtol: 1e-13,
            atol: 1e-13,
        },
        Method::Taylor { tol: 1e-15 },
    ] {
        let r = run(&massless_arm::SYSTEMS, &params, None, method, &times).unwrap();
        let (mut fall, mut rods, mut energy, mut pull) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
        let e0 = MASS * GRAVITY * -LOWER;
        for ((t, y), lambda) in r.times.iter().zip(&r.states).zip(&r.reactions) {
            let [x1, y1, x2, y2, _, _, x2d, y2d] = y[..] else {
                panic!("a state of 8 numbers")
            };
            fall = fall
                .max((x2 - UPPER).abs())
                .max((y2 - (-LOWER - GRAVITY * t * t / 2.0)).abs());
            rods = rods
                .max((x1 * x1 + y1 * y1 - UPPER * UPPER).abs())
                .max(((x2 - x1).powi(2) + (y2 - y1).powi(2) - LOWER * LOWER).abs());
            let e = MASS * (x2d * x2d + y2d * y2d) / 2.0 + MASS * GRAVITY * y2;
            energy = energy.max((e - e0).abs());
            pull = lambda.iter().fold(pull, |m, l| m.max(l.abs()));
        }
        eprintln!(
            "{method:?}: {} steps, fall {fall:.1e}, rods {rods:.1e}, energy {energy:.1e}, reactions {pull:.1e}",
            r.steps
        );
        assert!(fall < 1e-10, "{method:?}: off the free fall by {fall:e}");
        assert!(rods < 1e-12, "{method:?}: rods off by {rods:e}");
        assert!(energy < 1e-10, "{method:?}: energy off by {energy:e}");
        assert!(pull < 1e-8, "{method:?}: a massless rod pulls {pull:e}");
        assert!(r.near_singular.is_empty(), "{:?}", r.near_singular);
    }
}

/// The slider's position and its first two derivatives along the crank
/// angle: s = l₁ cos θ + √(l₂² − l₁² sin²θ).
fn slider(theta: f64, l1: f64, l2: f64) -> [f64; 3] {
    let (sin, cos) = theta.sin_cos();
    let root = (l2 * l2 - l1 * l1 * sin * sin).sqrt();
    let s = l1 * cos + root;
    let s1 = -l1 * sin - l1 * l1 * sin * cos / root;
    let s2 = -l1 * cos
        - l1 * l1 * (cos * cos - sin * sin) / root
        - l1.powi(4) * sin * sin * cos * cos / root.powi(3);
    [s, s1, s2]
}

/// The slider-crank of one freedom written out here by hand in the crank
/// angle: T = ½(I + m s_θ²) θ'², V = ½k(s − s₀)², so (I + m s_θ²) θ'' =
/// −m s_θ s_θθ θ'² − k (s − s₀) s_θ; by classical RK4 at a step of 1e-4.
fn crank_by_hand(params: &[f64; 6], times: &[f64]) -> Vec<[f64; 2]> {
    let [inertia, m, k, s0, l1, l2] = *params;
    let field = |y: [f64; 2]| {
        let [s, s1, s2] = slider(y[0], l1, l2);
        let accel = (-m * s1 * s2 * y[1] * y[1] - k * (s - s0) * s1) / (inertia + m * s1 * s1);
        [y[1], accel]
    };
    let step: f64 = 1e-4;
    let mut y = [std::f64::consts::FRAC_PI_2, 0.0];
    let (mut t, mut out) = (0.0, Vec::new());
    for &target in times {
        while t < target - 1e-12 {
            let h = step.min(target - t);
            y = crate::common::rk4_step(field, y, h);
            t += h;
        }
        out.push(y);
    }
    out
}

/// A slider-crank whose connecting rod has no mass, released with the
/// crank upright: over 5 s its crank angle and rate follow the equation
/// of its one freedom written out by hand to 1e-9, the energy (written
/// out too) holds to 1e-10, and the slider stays where the rod's length
/// puts it to 1e-12; with DOP853 and Taylor.
#[test]
fn a_slider_crank_with_a_massless_rod_follows_its_hand_written_equation() {
    let params = [0.5, 2.0, 30.0, 2.0, 0.5, 2.0];
    let [inertia, m, k, s0, l1, l2] = params;
    let times: Vec<f64> = (0..=500).map(|j| 1e-2 * j as f64).collect();
    let by_hand = crank_by_hand(&params, &times);
    let energy = |theta: f64, rate: f64| {
        let [s, s1, _] = slider(theta, l1, l2);
        (inertia + m * s1 * s1) * rate * rate / 2.0 + k * (s - s0).powi(2) / 2.0
    };
    let e0 = energy(std::f64::consts::FRAC_PI_2, 0.0);
    for method in [
        Method::Dop853 {
            rtol: 1e-13,
            atol: 1e-13,
        },
        Method::Taylor { tol: 1e-15 },
    ] {
        let r = run(
            &massless_slider_crank::SYSTEMS,
            &params,
            None,
            method,
            &times,
        )
        .unwrap();
        let (mut path, mut drift, mut closed) = (0.0_f64, 0.0_f64, 0.0_f64);
        for (y, hand) in r.states.iter().zip(&by_hand) {
            let (theta, s, rate) = (y[0], y[2], y[3]);
            path = path
                .max((theta - hand[0]).abs())
                .max((rate - hand[1]).abs());
            drift = drift.max((energy(theta, rate) - e0).abs());
            closed = closed.max((s - slider(theta, l1, l2)[0]).abs());
        }
        eprintln!(
            "{method:?}: {} steps, path {path:.1e}, energy {drift:.1e}, slider {closed:.1e}",
            r.steps
        );
        assert!(
            path < 1e-9,
            "{method:?}: off the hand-written motion by {path:e}"
        );
        assert!(drift < 1e-10, "{method:?}: energy off by {drift:e}");
        assert!(closed < 1e-12, "{method:?}: slider off by {closed:e}");
    }
}
