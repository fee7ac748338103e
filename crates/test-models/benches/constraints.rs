//! Benchmark `constraints` (`cargo bench -p mechlab-test-models --bench
//! constraints`, a scene writing to `crates/test-models/out/constraints/`
//! unless `-- --out DIR` is given): constrained
//! formulations against the same physics in minimal coordinates at equal
//! error (target ≤ 2× the cost), and a closed chain of ten rods run for
//! 1,000 time units (target: residuals ≤ 1e-12; the energy's error
//! reported), and Andrews' squeezing mechanism against the Test Set's
//! reference at t = 0.03 (target: positions to 1e-8 in ≤ 50 ms on one
//! core). Errors are the largest angle error at unit times against a
//! run of the angle model at tolerance 1e-14; cost is the best of five
//! runs' wall time; the constrained run's cost at the angle model's error
//! is interpolated on its work–precision line (log–log). Both sides
//! return states only (the constrained run's projected at every output,
//! without the reactions and energies `on_constraints::run` reports).

use mechlab::analysis::on_constraints::{run, states, ConstrainedError};
use mechlab::models::{double_pendulum as dp, kapitza};
use mechlab::ode::{states_at, Method};
use mechlab::scene::{knob, run as scene_run, Scene};
use mechlab_test_models::{
    andrews_squeezer, cartesian_double_pendulum, cartesian_kapitza, closed_chain10,
};
use std::time::Instant;

const TOLERANCES: [f64; 5] = [1e-6, 1e-7, 1e-8, 1e-10, 1e-12];

fn dop853(tol: f64) -> Method {
    Method::Dop853 {
        rtol: tol,
        atol: tol,
    }
}

/// The best of five runs' seconds and the last run's result.
fn timed<T>(mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..5 {
        let start = Instant::now();
        let value = f();
        best = best.min(start.elapsed().as_secs_f64());
        last = Some(value);
    }
    (best, last.expect("five runs"))
}

/// |x − y| of two angles, modulo 2π.
fn angle_difference(x: f64, y: f64) -> f64 {
    ((x - y + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI).abs()
}

/// One formulation's (error, seconds) at each tolerance.
type Line = Vec<(f64, f64)>;

/// log t at log e on a work–precision line (sorted by error), linear in
/// the logs between its points, clamped at its ends.
fn cost_at(line: &Line, error: f64) -> f64 {
    let mut points: Vec<(f64, f64)> = line.iter().map(|(e, t)| (e.ln(), t.ln())).collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    let x = error.ln();
    let k = points
        .iter()
        .position(|p| p.0 >= x)
        .unwrap_or(points.len() - 1)
        .max(1);
    let (a, b) = (points[k - 1], points[k]);
    let s = ((x - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
    (a.1 + s * (b.1 - a.1)).exp()
}

#[derive(serde::Serialize)]
struct Comparison {
    name: &'static str,
    /// (error, seconds) of the angle model and the constrained one.
    angles: Line,
    constrained: Line,
    /// At each of the angle model's errors, the constrained cost over its.
    ratios: Vec<f64>,
}

fn compare(
    name: &'static str,
    angles: impl Fn(Method) -> Vec<Vec<f64>>,
    constrained: impl Fn(Method) -> Vec<Vec<f64>>,
) -> Comparison {
    let reference = angles(dop853(1e-14));
    let error = |runs: &[Vec<f64>]| {
        runs.iter()
            .zip(&reference)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| angle_difference(*x, *y)))
            .fold(0.0_f64, f64::max)
            .max(1e-16)
    };
    let line = |f: &dyn Fn(Method) -> Vec<Vec<f64>>| -> Line {
        TOLERANCES
            .iter()
            .map(|&tol| {
                let (seconds, runs) = timed(|| f(dop853(tol)));
                (error(&runs), seconds)
            })
            .collect()
    };
    let angle_line = line(&angles);
    let constrained_line = line(&constrained);
    let ratios: Vec<f64> = angle_line
        .iter()
        .map(|(e, t)| cost_at(&constrained_line, *e) / t)
        .collect();
    println!("{name}: cost ratio (constrained / angles) at equal error:");
    for ((e, t), r) in angle_line.iter().zip(&ratios) {
        println!("  error {e:.1e}: angles {:.3} ms, ratio {r:.2}", t * 1e3);
    }
    Comparison {
        name,
        angles: angle_line,
        constrained: constrained_line,
        ratios,
    }
}

#[derive(serde::Serialize)]
struct Chain {
    time_units: f64,
    seconds: f64,
    largest_residual: (f64, f64),
    largest_drift: (f64, f64),
    energy_error: f64,
}

/// A pendulum swinging below its pivot: the angle, and the bob on its rod.
fn pendulum(times: &[f64]) -> Comparison {
    let (q0, qd0) = (2.0f64, 0.3f64);
    let kp = kapitza::Params {
        A: 0.0,
        eps: 0.1,
        mu: 0.0,
    };
    compare(
        "pendulum",
        |method| {
            let states = states_at(
                method,
                &kapitza::Exact { params: kp },
                0.0,
                &[q0, qd0],
                times,
            );
            states.unwrap().into_iter().map(|y| vec![y[0]]).collect()
        },
        |method| {
            let y0 = [q0.sin(), q0.cos(), q0.cos() * qd0, -q0.sin() * qd0];
            let states = states(
                &cartesian_kapitza::SYSTEMS,
                &[0.0, 0.1, 0.0],
                &y0,
                method,
                times,
            );
            states
                .unwrap()
                .iter()
                .map(|y| vec![y[0].atan2(y[1])])
                .collect()
        },
    )
}

/// The double pendulum on its vibrating base, near the held upright.
fn double_pendulum(times: &[f64]) -> Comparison {
    let p = dp::Params {
        mu: 0.0,
        ..dp::Params::default()
    };
    let (q1, q2) = (0.1f64, -0.15f64);
    let base = |t: f64| p.a / p.nu * (p.nu * t).cos();
    compare(
        "double pendulum",
        |method| {
            let system = dp::Exact { params: p };
            let states = states_at(method, &system, 0.0, &[q1, q2, 0.0, 0.0], times);
            states
                .unwrap()
                .into_iter()
                .map(|y| y[..2].to_vec())
                .collect()
        },
        |method| {
            let (x1, z1) = (p.l1 * q1.sin(), base(0.0) + p.l1 * q1.cos());
            let y0 = [
                x1,
                z1,
                x1 + p.l2 * q2.sin(),
                z1 + p.l2 * q2.cos(),
                0.0,
                0.0,
                0.0,
                0.0,
            ];
            let params = [p.m1, p.m2, p.l1, p.l2, p.g, p.a, p.nu];
            let states = states(
                &cartesian_double_pendulum::SYSTEMS,
                &params,
                &y0,
                method,
                times,
            );
            states
                .unwrap()
                .iter()
                .zip(times)
                .map(|(y, t)| {
                    vec![
                        y[0].atan2(y[1] - base(*t)),
                        (y[2] - y[0]).atan2(y[3] - y[1]),
                    ]
                })
                .collect()
        },
    )
}

/// The closed chain from its file's start for `t_end`, reported once per
/// time unit.
fn closed_chain(t_end: f64) -> Result<Chain, ConstrainedError> {
    let times: Vec<f64> = (0..=t_end as usize).map(|k| k as f64).collect();
    let params = closed_chain10::Params::default().values();
    let start = Instant::now();
    let chain = run(
        &closed_chain10::SYSTEMS,
        &params,
        None,
        dop853(1e-12),
        &times,
    )?;
    let e0 = chain.energy[0];
    let result = Chain {
        time_units: t_end,
        seconds: start.elapsed().as_secs_f64(),
        largest_residual: chain.largest_residual,
        largest_drift: chain.largest_drift,
        energy_error: chain
            .energy
            .iter()
            .fold(0.0_f64, |m, e| m.max((e - e0).abs())),
    };
    println!(
        "closed chain of 10 rods, {t_end} time units: {:.2} s, residuals {:.1e} / {:.1e} (before projection {:.1e} / {:.1e}), energy error {:.1e}",
        result.seconds,
        result.largest_residual.0,
        result.largest_residual.1,
        result.largest_drift.0,
        result.largest_drift.1,
        result.energy_error
    );
    Ok(result)
}

/// Andrews' squeezing mechanism to t = 0.03 from its published start: the
/// positions' largest error against the Test Set's reference and the
/// seconds (best of five) at each tolerance.
fn andrews() -> Vec<(f64, f64, f64)> {
    let reference = mechlab_test_models::ANDREWS_AT_0_03;
    let params = andrews_squeezer::Params::default().values();
    let rows: Vec<(f64, f64, f64)> = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12]
        .iter()
        .map(|&tol| {
            let (seconds, run) = timed(|| {
                run(
                    &andrews_squeezer::SYSTEMS,
                    &params,
                    None,
                    dop853(tol),
                    &[0.0, 0.03],
                )
            });
            let end = &run.expect("the squeezer runs").states[1];
            let error = (0..7).fold(0.0_f64, |m, i| m.max((end[i] - reference[i]).abs()));
            (tol, error, seconds)
        })
        .collect();
    println!("Andrews' squeezing mechanism to t = 0.03 (DOP853):");
    for (tol, error, seconds) in &rows {
        println!(
            "  tolerance {tol:.0e}: position error {error:.1e}, {:.2} ms",
            seconds * 1e3
        );
    }
    rows
}

fn main() {
    scene_run(|| {
        let scene = Scene::from_args(
            "constraints",
            "constrained formulations against minimal coordinates, and a closed chain",
            &[knob(
                "chain_time",
                "1000",
                "time units of the closed chain's run",
            )],
        )?;
        let times: Vec<f64> = (0..=100).map(|k| k as f64).collect();
        let summary = serde_json::json!({
            "pendulum": pendulum(&times),
            "double_pendulum": double_pendulum(&times),
            "closed_chain": closed_chain(scene.get("chain_time", mechlab::settings::Range::Positive)?)?,
            "andrews": andrews(),
        });
        scene.write_summary(&summary)?;
        Ok(())
    })
}
