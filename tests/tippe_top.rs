//! The tippe top (`test_models/tippe_top.toml`): a ball with its centre
//! of mass below its centre, sliding with viscous friction on the plane
//! (`[[sliding]]`), in Euler parameters. Checked against what holds for
//! any friction at the contact: Jellett's quantity kept, the energy's
//! loss equal to the friction's work, and the spin the turned-over top
//! ends with; and against Hugenholtz's condition for turning over.

use mechlab::analysis::on_constraints::{run, ConstrainedRun};
use mechlab::ode::Method;
use mechlab_test_models::tippe_top;

/// A run from the file's start (its tilt and spin) with `changes` to the
/// default parameters, sampled every `step` seconds up to `end`.
fn spun(changes: &[(&str, f64)], end: f64, step: f64) -> (ConstrainedRun, tippe_top::Params) {
    let mut params = tippe_top::Params::default();
    for (name, value) in changes {
        params.set(name, *value).unwrap();
    }
    let count = (end / step).round() as usize;
    let times: Vec<f64> = (0..=count).map(|k| k as f64 * step).collect();
    let method = Method::Dop853 {
        rtol: 1e-12,
        atol: 1e-12,
    };
    let result = run(
        tippe_top::MODEL.constrained.unwrap(),
        &params.values(),
        None,
        method,
        &times,
    )
    .unwrap();
    (result, params)
}

/// The symmetry axis k and the angular velocity ω in space, from the
/// state (x, y, e, x', y', e'), written out here: k the rotation's third
/// column, ω = 2 E(e) e'.
fn axis_and_rate(state: &[f64]) -> ([f64; 3], [f64; 3]) {
    let [e0, e1, e2, e3] = [state[2], state[3], state[4], state[5]];
    let [d0, d1, d2, d3] = [state[8], state[9], state[10], state[11]];
    let k = [
        2.0 * (e1 * e3 + e0 * e2),
        2.0 * (e2 * e3 - e0 * e1),
        e0 * e0 - e1 * e1 - e2 * e2 + e3 * e3,
    ];
    let w = [
        2.0 * (-e1 * d0 + e0 * d1 - e3 * d2 + e2 * d3),
        2.0 * (-e2 * d0 + e3 * d1 + e0 * d2 - e1 * d3),
        2.0 * (-e3 * d0 - e2 * d1 + e1 * d2 + e0 * d3),
    ];
    (k, w)
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The contact's slip, the horizontal velocity of the ball's material
/// point on the floor: v + ω × d with d = a k − R e_z from the centre of
/// mass to the contact.
fn slip(state: &[f64], a: f64, r: f64) -> [f64; 2] {
    let (k, w) = axis_and_rate(state);
    let d = [a * k[0], a * k[1], a * k[2] - r];
    [
        state[6] + w[1] * d[2] - w[2] * d[1],
        state[7] + w[2] * d[0] - w[0] * d[2],
    ]
}

/// Jellett's quantity L·(a k − R e_z), L = I1 ω + (I3 − I1)(ω·k) k.
fn jellett(state: &[f64], params: &tippe_top::Params) -> f64 {
    let get = |n: &str| params.get(n).unwrap();
    let (i1, i3, a, r) = (get("I1"), get("I3"), get("a"), get("R"));
    let (k, w) = axis_and_rate(state);
    let spin = dot(&k, &w);
    let l: Vec<f64> = (0..3)
        .map(|i| i1 * w[i] + (i3 - i1) * spin * k[i])
        .collect();
    let d = [a * k[0], a * k[1], a * k[2] - r];
    (0..3).map(|i| l[i] * d[i]).sum()
}

/// Turning over, the top keeps Jellett's quantity (the contact force's
/// torque about the centre of mass is normal to it, whatever the
/// friction) to 1e-10 of itself, and its energy falls by exactly the
/// friction's work, ∫ μ |slip|² dt (Simpson's rule on the samples), to
/// 1e-10 of the energy lost.
#[test]
fn turning_over_it_keeps_jellett_s_quantity_and_loses_the_friction_s_work() {
    let step = 2.5e-4;
    let (result, params) = spun(&[], 4.0, step);
    let get = |n: &str| params.get(n).unwrap();
    let (mu, a, r) = (get("mu"), get("a"), get("R"));
    let j0 = jellett(&result.states[0], &params);
    let kept = result
        .states
        .iter()
        .map(|s| (jellett(s, &params) - j0).abs())
        .fold(0.0, f64::max);
    let power: Vec<f64> = result
        .states
        .iter()
        .map(|s| {
            let v = slip(s, a, r);
            mu * (v[0] * v[0] + v[1] * v[1])
        })
        .collect();
    // Simpson's rule on pairs of steps: the work done by each output time
    // 2k (an even count of steps).
    let mut work = 0.0;
    let mut balance = 0.0_f64;
    for k in (2..power.len()).step_by(2) {
        work += step / 3.0 * (power[k - 2] + 4.0 * power[k - 1] + power[k]);
        let lost = result.energy[0] - result.energy[k];
        balance = balance.max((lost - work).abs());
    }
    let lost = result.energy[0] - result.energy.last().unwrap();
    let (k_end, _) = axis_and_rate(result.states.last().unwrap());
    println!(
        "Jellett {j0:e} kept to {kept:e}; energy lost {lost:e}, friction's work {work:e}, \
         balance to {balance:e}; k_z at the end {}; {} steps, residuals {:?}",
        k_end[2], result.steps, result.largest_residual
    );
    assert!(
        k_end[2] < -0.999,
        "the top has not turned over: k_z {}",
        k_end[2]
    );
    assert!(
        kept <= 1e-10 * j0.abs(),
        "Jellett's quantity moved by {kept:e} of {j0:e}"
    );
    assert!(
        balance <= 1e-10 * lost,
        "energy balance off by {balance:e} of {lost:e}"
    );
    assert!(
        result.largest_residual.0 < 1e-12,
        "{:?}",
        result.largest_residual
    );
}

/// Where the sliding stops, the top rolls steadily: ω along d = a k − R e_z
/// (the contact at rest), k precessing at a constant tilt cos θ = c, and
/// the normal force's torque a m g k × e_z turning L: λ² R A = a m g with
/// A = I3 a − (I3 − I1) R c and ω = λ d. Jellett's quantity, kept from the
/// start, then fixes c: λ [A (a − R c) − I1 R (a c − R)] = J. Straight up
/// or over (c = ±1) any spin is steady, and J gives it: ω_z = ±J/(I3 (a ∓ R)).
/// Below Hugenholtz's range (I1/I3 < 1 − a/R) the top stays up; inside
/// it goes over, fully where the tilted motion does not exist (at
/// I1/I3 = 0.889 here) and else tilted at the root (1.2); above it too
/// (1.35). Each end state, after 60 s, to 1e-8.
#[test]
fn it_ends_in_the_steady_rolling_motion_jellett_s_quantity_gives() {
    for ratio in [0.5, 0.889, 1.2, 1.35] {
        let i3 = tippe_top::Params::default().get("I3").unwrap();
        let (result, params) = spun(&[("I1", ratio * i3)], 60.0, 0.01);
        let get = |n: &str| params.get(n).unwrap();
        let (m, g, a, r, i1) = (get("m"), get("g"), get("a"), get("R"), get("I1"));
        let j = jellett(&result.states[0], &params);
        let tilted = |c: f64| {
            let area = i3 * a - (i3 - i1) * r * c;
            let lambda = -(a * m * g / (r * area)).sqrt();
            (
                lambda * (area * (a - r * c) - i1 * r * (a * c - r)) - j,
                lambda * (a * c - r),
            )
        };
        // The tilted motion's root in (−1, 1), where there is one.
        let grid: Vec<f64> = (0..=2000).map(|i| -1.0 + i as f64 / 1000.0).collect();
        let root = grid.windows(2).find_map(|w| {
            let (f0, f1) = (tilted(w[0]).0, tilted(w[1]).0);
            (f0.is_finite() && f1.is_finite() && f0 * f1 <= 0.0).then(|| {
                let (mut lo, mut hi) = (w[0], w[1]);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if tilted(lo).0 * tilted(mid).0 <= 0.0 {
                        hi = mid
                    } else {
                        lo = mid
                    }
                }
                lo
            })
        });
        let (k, w) = axis_and_rate(result.states.last().unwrap());
        let (c, spin) = match (ratio < 1.0 - a / r, root) {
            (true, _) => (1.0, j / (i3 * (a - r))),
            (false, Some(c)) => (c, tilted(c).1),
            (false, None) => (-1.0, -j / (i3 * (a + r))),
        };
        println!(
            "I1/I3 = {ratio}: ends at k_z {} and ω_z {}; by hand {c} and {spin}",
            k[2], w[2]
        );
        assert!(
            (k[2] - c).abs() < 1e-5,
            "I1/I3 = {ratio}: k_z {} against {c}",
            k[2]
        );
        assert!(
            (w[2] - spin).abs() < 1e-5 * spin,
            "I1/I3 = {ratio}: ω_z {} against {spin}",
            w[2]
        );
    }
}
