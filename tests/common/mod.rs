//! Helpers shared by the integration tests.
#![allow(dead_code)]

use mechlab::ode::{Integrator, LaneIntegrator, Method, Orbit, System};
use mechlab::registry::Model;

/// The users' model `name`, which the test expects to exist.
pub fn model_of(name: &str) -> &'static Model {
    match name {
        // A test model (test_models/): the scenes' build does not compile it.
        "quadruple_pendulum" => &mechlab_test_models::quadruple_pendulum::MODEL,
        "physical_pendulum_body" => &mechlab_test_models::physical_pendulum_body::MODEL,
        _ => mechlab::models::by_name(name).unwrap_or_else(|e| panic!("{e}")),
    }
}

/// Deterministic pseudo-random numbers (xorshift64), so that a failing
/// case can be rerun.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [a, b).
    pub fn between(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }
}

/// Whether a and b agree to `tol`, relative to their size (absolute near 0).
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// Asserts [`close`], naming the quantity.
pub fn assert_close(what: &str, a: f64, b: f64, tol: f64) {
    assert!(close(a, b, tol), "{what}: {a} vs {b}");
}

/// Each orbit streamed for one segment (Taylor, 1e-10) against its scalar run
/// (its end sampled from the step across it).
pub fn assert_streams_equal_scalar<S: System<N>, const N: usize>(orbits: &[Orbit<'_, S, N>]) {
    let mut ends: Vec<[f64; N]> = orbits.iter().map(|o| o.start).collect();
    let mut batch = LaneIntegrator::new(Method::Taylor { tol: 1e-10 }).unwrap();
    let errors = batch.stream(orbits, |k, y| {
        ends[k] = *y;
        false
    });
    let mut scalar = Integrator::new(Method::Taylor { tol: 1e-10 }).unwrap();
    for (k, orbit) in orbits.iter().enumerate() {
        let mut end = None;
        let expected = scalar
            .stream(orbit.system, &orbit.start, orbit.end, 1, &mut |y| {
                end = Some(*y);
                false
            })
            .map(|()| end.unwrap_or(orbit.start));
        let streamed = match &errors[k] {
            Some(e) => Err(e.clone()),
            None => Ok(ends[k]),
        };
        // Debug text: NaN ≠ NaN, but the errors must read the same.
        assert_eq!(
            format!("{streamed:?}"),
            format!("{expected:?}"),
            "orbit {k}"
        );
    }
    assert_eq!(batch.stats.steps, scalar.stats.steps);
    assert_eq!(batch.stats.f_evals, scalar.stats.f_evals);
}

/// The tangent recurrences of `system` (forward mode or Jacobian form,
/// whichever its derivation chose) against central differences of its
/// solution's recurrences along the tangent: at an arbitrary state, time
/// and tangent vector, every Taylor coefficient of the tangent to order 12
/// equals d/dh of the solution's coefficients at y + h·w, to 1e-6 of the
/// coefficients' size (the differences' own error is about 1e-10).
pub fn assert_tangent_recurrences_differentiate<S: System<N>, const N: usize>(
    system: &S,
    name: &str,
) {
    const ORDER: usize = 12;
    let y: [f64; N] = std::array::from_fn(|i| 0.3 + 0.1 * i as f64);
    let w: [f64; N] = std::array::from_fn(|i| 0.5 - 0.3 * i as f64);
    let t = 0.1;
    let mut work = mechlab::ode::TaylorWork::default();
    let z: Vec<f64> = y.iter().chain(&w).copied().collect();
    let mut tangent = vec![0.0; (ORDER + 1) * 2 * N];
    assert!(
        system.taylor_variational(t, &z, ORDER, &mut work, &mut tangent),
        "{name}: no tangent recurrences"
    );
    let h = 1e-6;
    let mut coefficients = |sign: f64| {
        let shifted: [f64; N] = std::array::from_fn(|i| y[i] + sign * h * w[i]);
        let mut out = vec![[0.0; N]; ORDER + 1];
        assert!(system.taylor(t, &shifted, ORDER, &mut work, &mut out));
        out
    };
    let (up, down) = (coefficients(1.0), coefficients(-1.0));
    for k in 0..=ORDER {
        for i in 0..N {
            let exact = tangent[k * 2 * N + N + i];
            let difference = (up[k][i] - down[k][i]) / (2.0 * h);
            let size = 1.0 + exact.abs() + up[k][i].abs();
            assert!(
                exact.is_finite() && (exact - difference).abs() <= 1e-6 * size,
                "{name}: order {k}, component {i}: tangent {exact}, differences {difference}"
            );
        }
    }
}

/// Each coordinate's asymptotic exponent of the averaging deviation
/// against ν for `model` at `params`, or why it was not reached: where the
/// sweep's last local slopes have not settled (a coordinate whose leading
/// term is small at the model's own frequencies) or settled on a fraction,
/// the sweep is run again at frequencies 8 and 64 times higher before
/// giving up, with the reason.
pub fn asymptotic_slopes(
    model: &Model,
    params: &[f64],
    settings: &mechlab::analysis::averaging::ConvergenceSettings,
) -> Result<Vec<Result<f64, String>>, mechlab::analysis::averaging::AveragingError> {
    use mechlab::analysis::averaging::convergence;
    // A slope settled on a fraction of a power is taken for a
    // pre-asymptotic stretch (a chaotic run's deviation on its way from
    // saturation to c/ν) and looked at again higher up, as an unsettled
    // one is; the last sweep's is kept, whole or not.
    let whole = |s: &Option<f64>| s.is_some_and(|s| (s - s.round()).abs() < 0.2);
    let first = convergence(model, params, settings)?;
    let mut slopes: Vec<Option<f64>> = first.settled_slope.clone();
    let mut last = first;
    for _ in 0..2 {
        if slopes.iter().all(whole) {
            break;
        }
        // 8 times the frequencies, whether ν grows with the parameter or
        // falls with it.
        let (v, f) = (&last.values, &last.frequencies);
        let proportional = ((f[1] / f[0]) / (v[1] / v[0]) - 1.0).abs() < 1e-6;
        let factor = if proportional { 8.0 } else { 1.0 / 8.0 };
        let higher = mechlab::analysis::averaging::ConvergenceSettings {
            check: false,
            accuracy: None,
            values: Some(v.iter().map(|x| x * factor).collect()),
            parameter: Some(last.parameter.clone()),
            ..settings.clone()
        };
        last = convergence(model, params, &higher)?;
        for (s, again) in slopes.iter_mut().zip(&last.settled_slope) {
            if !whole(s) && again.is_some() {
                *s = *again;
            }
        }
    }
    Ok(slopes
        .iter()
        .zip(&last.local_slopes)
        .zip(&last.coordinates)
        .map(|((s, local), c)| {
            let top = last.frequencies.last().unwrap();
            match s {
                Some(s) if whole(&Some(*s)) => Ok(*s),
                // Settled on a fraction as far up as the sweep went: the
                // deviation is not yet c/ν^k there (a chaotic start's, on
                // its way down from saturation), so there is no exponent
                // to check; the dedicated tests hold the known models'.
                Some(s) => Err(format!(
                    "{c}: the local slopes {local:.2?} settled on {s:.2}, a fraction, up to ν = {top:.3e}: not yet the asymptotic regime"
                )),
                None => Err(format!(
                    "{c}: the local slopes {local:.2?} have not settled by ν = {top:.3e}"
                )),
            }
        })
        .collect())
}

/// Asserts that each settled slope of [`asymptotic_slopes`] is a whole
/// power at most `most` (−1 for first-order averaging, −2 for second);
/// prints the reason of each that did not settle. Whether all settled.
pub fn assert_whole_power_slopes(model: &str, slopes: &[Result<f64, String>], most: f64) -> bool {
    for slope in slopes {
        match slope {
            Ok(slope) => assert!(
                *slope < most + 0.2 && (slope - slope.round()).abs() < 0.2,
                "{model}: slope {slope}"
            ),
            Err(reason) => eprintln!("{model}: slope not checked: {reason}"),
        }
    }
    slopes.iter().all(|s| s.is_ok())
}

/// Continuation settings of one branch of period 1 in `parameter` to `to`
/// from `start`, with `method` (the tests change what they need).
pub fn continuation_settings(
    parameter: &str,
    to: f64,
    start: &[f64],
    method: Method,
) -> mechlab::analysis::continuation::ContinuationSettings {
    mechlab::analysis::continuation::ContinuationSettings {
        parameter: parameter.into(),
        to,
        start: start.to_vec(),
        period: 1,
        max_period: 1,
        switch_branch_points: false,
        max_branches: 4,
        points: 2000,
        step: 0.005,
        min_step: 1e-8,
        max_step: 0.02,
        method,
        accuracy: None,
        diagram: None,
        chart: None,
    }
}

/// The first period doubling of Duffing's right-well orbit,
/// x'' + δx' − x + x³ = γ cos ωt, in γ on (γ₀, γ₁), computed without
/// mechlab: classical RK4 with `steps` steps a period on the orbit and its
/// variational equations, Newton on P(x) − x for the orbit, and bisection
/// on the Jury condition 1 + tr M + det M = 0 (a multiplier at −1).
pub fn duffing_period_doubling(
    delta: f64,
    omega: f64,
    (mut low, mut high): (f64, f64),
    steps: usize,
) -> f64 {
    let period = 2.0 * std::f64::consts::PI / omega;
    let h = period / steps as f64;
    // State (x, v, ∂(x, v)/∂(x₀, v₀) by columns).
    let field = |gamma: f64, t: f64, s: &[f64; 6]| -> [f64; 6] {
        let (x, v) = (s[0], s[1]);
        let stiffness = 1.0 - 3.0 * x * x;
        [
            v,
            -delta * v + x - x * x * x + gamma * (omega * t).cos(),
            s[3],
            stiffness * s[2] - delta * s[3],
            s[5],
            stiffness * s[4] - delta * s[5],
        ]
    };
    let period_map = |gamma: f64, x0: [f64; 2]| -> ([f64; 2], [[f64; 2]; 2]) {
        let mut s = [x0[0], x0[1], 1.0, 0.0, 0.0, 1.0];
        for k in 0..steps {
            let t = k as f64 * h;
            let add = |a: &[f64; 6], b: &[f64; 6], c: f64| -> [f64; 6] {
                std::array::from_fn(|i| a[i] + c * b[i])
            };
            let k1 = field(gamma, t, &s);
            let k2 = field(gamma, t + 0.5 * h, &add(&s, &k1, 0.5 * h));
            let k3 = field(gamma, t + 0.5 * h, &add(&s, &k2, 0.5 * h));
            let k4 = field(gamma, t + h, &add(&s, &k3, h));
            s = std::array::from_fn(|i| {
                s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        ([s[0], s[1]], [[s[2], s[4]], [s[3], s[5]]])
    };
    // The orbit by Newton, continued from the last γ's.
    let orbit = |gamma: f64, mut x: [f64; 2]| -> ([f64; 2], [[f64; 2]; 2]) {
        for _ in 0..50 {
            let (image, m) = period_map(gamma, x);
            let (a, b, c, d) = (m[0][0] - 1.0, m[0][1], m[1][0], m[1][1] - 1.0);
            let (r0, r1) = (image[0] - x[0], image[1] - x[1]);
            let det = a * d - b * c;
            let step = [(d * r0 - b * r1) / det, (a * r1 - c * r0) / det];
            x = [x[0] - step[0], x[1] - step[1]];
            if step[0].abs().max(step[1].abs()) < 1e-14 {
                break;
            }
        }
        let (_, m) = period_map(gamma, x);
        (x, m)
    };
    let jury = |m: [[f64; 2]; 2]| 1.0 + m[0][0] + m[1][1] + (m[0][0] * m[1][1] - m[0][1] * m[1][0]);
    let mut start = [1.0, 0.0];
    // Follow the orbit from γ = 0 (near the well's bottom x = 1) to γ₀.
    for k in 0..=20 {
        start = orbit(low * k as f64 / 20.0, start).0;
    }
    let (x, m) = orbit(low, start);
    assert!(jury(m) > 0.0, "no doubling above γ = {low}");
    start = x;
    while high - low > 1e-13 {
        let mid = 0.5 * (low + high);
        let (x, m) = orbit(mid, start);
        if jury(m) > 0.0 {
            (low, start) = (mid, x);
        } else {
            high = mid;
        }
    }
    0.5 * (low + high)
}

/// The arithmetic–geometric mean of a and b: the complete elliptic integral
/// K(k) = π / (2 AGM(1, √(1 − k²))) of the pendulum's closed forms.
pub fn agm(mut a: f64, mut b: f64) -> f64 {
    while (a - b).abs() > 1e-16 * a {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    a
}

/// A frequency map's tune check states the tunes' true errors (`errors`,
/// one a sampled tune, against a closed form): as many tunes, their
/// median and largest within a factor 2, and the integration (not NAFF)
/// deciding them.
pub fn assert_tune_check_states(
    check: &mechlab::analysis::frequency_map::TuneCheck,
    mut errors: Vec<f64>,
) {
    errors.sort_by(f64::total_cmp);
    let (median, largest) = (errors[errors.len() / 2], errors[errors.len() - 1]);
    eprintln!("{check:?}: errors median {median:e}, largest {largest:e}");
    assert_eq!(check.sampled, errors.len());
    assert!(
        largest > 1e-9,
        "the integration does not decide the tunes: {largest}"
    );
    assert!(
        (0.5..2.0).contains(&(check.largest / largest)),
        "{check:?} vs {largest}"
    );
    assert!(
        (0.5..2.0).contains(&(check.median / median)),
        "{check:?} vs {median}"
    );
}

/// One step of classical RK4, written out here for the tests' hand-made
/// references (independent of the library's integrators).
pub fn rk4_step<const D: usize>(
    field: impl Fn([f64; D]) -> [f64; D],
    y: [f64; D],
    h: f64,
) -> [f64; D] {
    let add = |y: [f64; D], k: [f64; D], c: f64| std::array::from_fn(|i| y[i] + c * k[i]);
    let k1 = field(y);
    let k2 = field(add(y, k1, h / 2.0));
    let k3 = field(add(y, k2, h / 2.0));
    let k4 = field(add(y, k3, h));
    std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// The largest relative distance (|a − b|/(1 + |b|)) between a derived
/// field and one written by hand, over 200 states spread by a fixed
/// sequence: state `k` is `state(s)`, with `s(j)` in [−0.5, 0.5).
pub fn worst_field_difference<const N: usize>(
    state: impl Fn(&dyn Fn(usize) -> f64) -> [f64; N],
    derived: impl Fn(&[f64; N]) -> [f64; N],
    by_hand: impl Fn(&[f64; N]) -> [f64; N],
) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..200 {
        let s = |j: usize| ((i * 7919 + j * 104_729) % 1000) as f64 / 1000.0 - 0.5;
        let y = state(&s);
        for (d, e) in derived(&y).iter().zip(by_hand(&y)) {
            worst = worst.max((d - e).abs() / (1.0 + e.abs()));
        }
    }
    worst
}
