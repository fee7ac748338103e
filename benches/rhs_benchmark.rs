//! Benchmark `rhs_benchmark` (`cargo bench --bench rhs_benchmark`, a scene
//! writing to `out/rhs_benchmark/`): speed of the generated right-hand sides against
//! careful hand-written ones (symbolic-inverse form: ratio ≤ 1.1; the
//! triple pendulum's numeric-solve form against a hand-written field with the
//! same Cholesky solve: ≤ 1.3). All are evaluated on the same pseudo-random
//! states in one run.

use mechlab::linalg::Cholesky;
use mechlab::models::{double_pendulum as dp, kapitza, triple_pendulum as tp};
use mechlab::scene::{knob, run, Scene, SceneError};
use std::hint::black_box;
use std::time::Instant;

fn kapitza_by_hand(t: f64, y: &[f64; 2], p: &kapitza::Params) -> [f64; 2] {
    let (s, c) = y[0].sin_cos();
    let st = (t / p.eps).sin();
    let qd = y[1] - p.A * st * s;
    [qd, s + p.A * st * c * qd - p.mu * qd]
}

fn double_pendulum_by_hand(t: f64, y: &[f64; 4], p: &dp::Params) -> [f64; 4] {
    let (s1, c1) = y[0].sin_cos();
    let (s2, c2) = y[1].sin_cos();
    let wd = -p.a * (p.nu * t).sin();
    let (b1, b2) = (-(p.m1 + p.m2) * p.l1 * s1 * wd, -p.m2 * p.l2 * s2 * wd);
    let c12 = c1 * c2 + s1 * s2;
    let s12 = s1 * c2 - c1 * s2;
    let a11 = (p.m1 + p.m2) * p.l1 * p.l1;
    let a12 = p.m2 * p.l1 * p.l2 * c12;
    let a22 = p.m2 * p.l2 * p.l2;
    let det = a11 * a22 - a12 * a12;
    let (r1, r2) = (y[2] - b1, y[3] - b2);
    let v1 = (a22 * r1 - a12 * r2) / det;
    let v2 = (a11 * r2 - a12 * r1) / det;
    let k = p.m2 * p.l1 * p.l2 * s12 * v1 * v2;
    let dp1 = -k + (p.m1 + p.m2) * p.l1 * (p.g * s1 - wd * c1 * v1) - p.mu * v1;
    let dp2 = k + p.m2 * p.l2 * (p.g * s2 - wd * c2 * v2) - p.mu * (v2 - v1);
    [v1, v2, dp1, dp2]
}

/// The triple pendulum on the vibrating base, written out: with M_i the
/// mass at or below rod i, A_ij = l_i l_j M_max(i,j) cos(φ_i − φ_j),
/// b_i = −ẇ l_i M_i sin φ_i, and p_i' = −Σ_j l_i l_j M_max(i,j)
/// sin(φ_i − φ_j) φ_i' φ_j' − ẇ l_i M_i cos φ_i φ_i' + g l_i M_i sin φ_i + Q_i.
fn triple_pendulum_by_hand(t: f64, y: &[f64; 6], p: &tp::Params) -> [f64; 6] {
    let l = [p.l1, p.l2, p.l3];
    let below = [p.m1 + p.m2 + p.m3, p.m2 + p.m3, p.m3];
    let wd = -p.a * (p.nu * t).sin();
    let sc: [(f64, f64); 3] = std::array::from_fn(|i| y[i].sin_cos());
    // sin and cos of φ_i − φ_j for i < j.
    let diff = |i: usize, j: usize| {
        let ((si, ci), (sj, cj)) = (sc[i], sc[j]);
        (si * cj - ci * sj, ci * cj + si * sj)
    };
    let (d01, d02, d12) = (diff(0, 1), diff(0, 2), diff(1, 2));
    let k01 = l[0] * l[1] * below[1];
    let k02 = l[0] * l[2] * below[2];
    let k12 = l[1] * l[2] * below[2];
    let a = [
        [l[0] * l[0] * below[0], k01 * d01.1, k02 * d02.1],
        [k01 * d01.1, l[1] * l[1] * below[1], k12 * d12.1],
        [k02 * d02.1, k12 * d12.1, l[2] * l[2] * below[2]],
    ];
    let r: [f64; 3] = std::array::from_fn(|i| y[3 + i] + wd * l[i] * below[i] * sc[i].0);
    let v = Cholesky::new(a).solve(r);
    let coupling = [
        -k01 * d01.0 * v[0] * v[1] - k02 * d02.0 * v[0] * v[2],
        k01 * d01.0 * v[0] * v[1] - k12 * d12.0 * v[1] * v[2],
        k02 * d02.0 * v[0] * v[2] + k12 * d12.0 * v[1] * v[2],
    ];
    let friction = [-p.mu * v[0], -p.mu * (v[1] - v[0]), -p.mu * (v[2] - v[1])];
    let rate = |i: usize| {
        coupling[i] + l[i] * below[i] * (p.g * sc[i].0 - wd * sc[i].1 * v[i]) + friction[i]
    };
    [v[0], v[1], v[2], rate(0), rate(1), rate(2)]
}

fn time<const N: usize>(states: &[[f64; N]], f: impl Fn(f64, &[f64; N]) -> [f64; N]) -> (f64, f64) {
    let start = Instant::now();
    let mut sum = 0.0;
    for (i, y) in states.iter().enumerate() {
        let r = f(black_box(i as f64 * 1e-3), black_box(y));
        sum += r[N - 1];
    }
    (start.elapsed().as_secs_f64(), black_box(sum))
}

/// Generated against hand-written on the same states: one right-hand side
/// timed in nanoseconds per evaluation.
#[derive(serde::Serialize)]
struct Timing {
    generated_ns: f64,
    hand_written_ns: f64,
    ratio: f64,
}

/// Checks that both give the same results on the first 1000 states (the
/// benchmark compares equal work), then times them in five alternating
/// rounds (the best of each).
fn compare<const N: usize>(
    name: &str,
    states: &[[f64; N]],
    generated: impl Fn(f64, &[f64; N]) -> [f64; N],
    by_hand: impl Fn(f64, &[f64; N]) -> [f64; N],
) -> Result<Timing, SceneError> {
    for y in states.iter().take(1000) {
        let (a, b) = (generated(0.3, y), by_hand(0.3, y));
        if !a
            .iter()
            .zip(&b)
            .all(|(x, z)| (x - z).abs() < 1e-8 * (1.0 + z.abs()))
        {
            return Err(SceneError::Disagreement {
                what: format!("{name}: the generated right-hand side"),
                at: y.to_vec(),
                got: a.to_vec(),
                expected: b.to_vec(),
            });
        }
    }
    let mut best = [f64::INFINITY; 2];
    for _ in 0..5 {
        best[0] = best[0].min(time(states, &generated).0);
        best[1] = best[1].min(time(states, &by_hand).0);
    }
    let per = |s: f64| s / states.len() as f64 * 1e9;
    let timing = Timing {
        generated_ns: per(best[0]),
        hand_written_ns: per(best[1]),
        ratio: best[0] / best[1],
    };
    println!(
        "{name} exact_rhs: generated {:.2} ns, hand-written {:.2} ns, ratio {:.3}",
        timing.generated_ns, timing.hand_written_ns, timing.ratio
    );
    Ok(timing)
}

/// `count` states with components uniform in [−3, 3) (a fixed LCG, so
/// every run times the same states).
fn random_states<const N: usize>(count: usize, seed: u64) -> Vec<[f64; N]> {
    let mut seed = seed;
    let mut random = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 6.0 - 3.0
    };
    (0..count)
        .map(|_| std::array::from_fn(|_| random()))
        .collect()
}

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "rhs_benchmark",
            "generated vs hand-written right-hand sides",
            &[knob(
                "evaluations",
                "4000000",
                "evaluations per variant and round",
            )],
        )?;
        let n: usize = scene.get(
            "evaluations",
            mechlab::settings::Range::Count {
                min: 1,
                max: usize::MAX,
            },
        )?;
        let kp = kapitza::Params {
            mu: 0.1,
            ..Default::default()
        };
        let pp = dp::Params {
            mu: 0.1,
            ..Default::default()
        };
        let tpp = tp::Params {
            mu: 0.1,
            m2: 1.3,
            l3: 0.7,
            ..Default::default()
        };
        let kapitza = compare(
            "kapitza",
            &random_states(n, 1),
            |t, y| kapitza::exact_rhs(t, y, &kp),
            |t, y| kapitza_by_hand(t, y, &kp),
        )?;
        let double_pendulum = compare(
            "double_pendulum",
            &random_states(n, 2),
            |t, y| dp::exact_rhs(t, y, &pp),
            |t, y| double_pendulum_by_hand(t, y, &pp),
        )?;
        let triple_pendulum = compare(
            "triple_pendulum (numeric solve)",
            &random_states(n, 3),
            |t, y| tp::exact_rhs(t, y, &tpp),
            |t, y| triple_pendulum_by_hand(t, y, &tpp),
        )?;
        scene.write_summary(&serde_json::json!({
            "kapitza": kapitza,
            "double_pendulum": double_pendulum,
            "triple_pendulum": triple_pendulum,
        }))?;
        Ok(())
    });
}
