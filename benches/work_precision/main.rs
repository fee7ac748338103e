//! Benchmark `work_precision` (`cargo bench --bench work_precision`): error against cost for every method over a range
//! of tolerances or steps, on mechlab's own systems (issue #3):
//! (a) the Kapitza period map at ε = 0.1, A = 1.5, μ = 0 over 1000 periods,
//!     from a regular orbit (q, p) = (0.3, 0) and a chaotic one (1, 0): the
//!     error of the period map, worst along a 1000-period reference orbit
//!     (each period started from the reference point; the global error of a
//!     chaotic orbit only measures its exponential divergence), plus the
//!     global error of the regular orbit after 1000 periods;
//! (a′) an ensemble of 64 Kapitza orbits over 20 periods, the sweeps'
//!     workload, with the batch Taylor method (`taylor_lanes`, 8 lanes
//!     streamed) beside one orbit at a time;
//! (a″) the monodromy matrices of the triple pendulum over 32 points
//!     (ν, a), the stability charts' workload, with each lane's own
//!     parameters (`taylor_lanes`) beside one matrix at a time;
//! (b) the double pendulum on the vibrating base at ν = 100, t ∈ [0, 10];
//! (c) the deformable rod of Study 3 sliding, ε = 0.01 and 0.001, t ∈ [0, 2].
//! Each run is timed (repeated until it has taken `min_seconds`), and the
//! third-party `ode_solvers` DOP853 runs on the same right-hand sides as a
//! peer. Writes one PNG per problem (error vs seconds and vs f-evaluations,
//! with the fitted slopes), runs.csv, and summary.json with the runs and the//!
//! Output goes where a scene's would (`out/work_precision/`), with the
//! scene's `--set name=value` and `--out DIR` options.

mod harness;
mod performance;
mod problems;

use harness::{plot_problem, speedups, BenchError, Failure, Row, Slopes};
use mechlab::models::kapitza;
use mechlab::scene::{knob, Scene};
use performance::{performance, Performance};
use std::collections::BTreeMap;

const PROBLEMS: [&str; 9] = [
    "kapitza_regular",
    "kapitza_regular_global",
    "kapitza_chaotic",
    "kapitza_ensemble",
    "triple_monodromy_sweep",
    "double_pendulum",
    "triple_pendulum",
    "rod_eps_0.01",
    "rod_eps_0.001",
];

#[derive(serde::Serialize)]
struct Summary<'a> {
    runs: &'a [Row],
    failed: &'a [Failure],
    slopes_error_vs_f_evals: BTreeMap<&'a str, Slopes>,
    reference_agreement: &'a BTreeMap<String, f64>,
    performance: Performance,
    /// dop853 seconds / taylor seconds at equal error (1e-6, 1e-8, 1e-10).
    taylor_speedup_over_dop853: BTreeMap<String, BTreeMap<String, Option<f64>>>,
    /// On the ensemble and the monodromy sweep: taylor (one orbit at a
    /// time) seconds / taylor_lanes (8 lanes streamed) seconds at equal
    /// error, one core each.
    lanes_speedup_over_taylor: BTreeMap<String, BTreeMap<String, Option<f64>>>,
}

fn bench() -> Result<(), BenchError> {
    let scene = Scene::from_args(
        "work_precision",
        "error against cost for every method on the Kapitza, double-pendulum and rod problems",
        &[
            knob(
                "min_seconds",
                "0.02",
                "each run is repeated until it has taken this long",
            ),
            knob("periods", "1000", "periods of the Kapitza map"),
            knob(
                "budget",
                "1",
                "seconds: a method slower than this is not run at tighter settings",
            ),
        ],
    )?;
    use mechlab::settings::Range;
    let periods: usize = scene.get(
        "periods",
        Range::Count {
            min: 1,
            max: usize::MAX,
        },
    )?;
    let runs = problems::run_all(
        scene.get("min_seconds", Range::NonNegative)?,
        periods,
        scene.get("budget", Range::Positive)?,
    )?;
    let mut slopes = BTreeMap::new();
    for problem in PROBLEMS {
        let mine: Vec<&Row> = runs.rows.iter().filter(|r| r.problem == problem).collect();
        slopes.insert(problem, plot_problem(&scene, problem, &mine)?);
    }
    let system = kapitza::Exact {
        params: problems::KAPITZA,
    };
    let period = mechlab::studies::kapitza::period(&problems::KAPITZA);
    let ratios = performance(&system, &problems::REGULAR, period, periods, &runs.rows)?;
    let taylor_over_dop853 = speedups(&runs.rows, &PROBLEMS, ("dop853", "taylor"));
    let lanes_over_taylor = speedups(&runs.rows, &PROBLEMS, ("taylor", "taylor_lanes"));
    let header = [
        "problem",
        "method",
        "tol_or_step",
        "error",
        "seconds",
        "f_evals",
    ];
    let rows = runs.rows.iter().map(|r| {
        (
            &r.problem,
            &r.method,
            r.tol_or_step,
            r.error,
            r.seconds,
            r.f_evals,
        )
    });
    scene.write_csv("runs.csv", &header, rows)?;
    let summary = Summary {
        runs: &runs.rows,
        failed: &runs.failures,
        slopes_error_vs_f_evals: slopes,
        reference_agreement: &runs.agreements,
        performance: ratios,
        taylor_speedup_over_dop853: taylor_over_dop853,
        lanes_speedup_over_taylor: lanes_over_taylor,
    };
    println!("performance: {}", serde_json::json!(summary.performance));
    println!(
        "dop853 time / taylor time at equal error: {}",
        serde_json::json!(summary.taylor_speedup_over_dop853)
    );
    println!(
        "taylor time / taylor_lanes time at equal error: {}",
        serde_json::json!(summary.lanes_speedup_over_taylor)
    );
    scene.write_summary(&summary)?;
    Ok(())
}

fn main() {
    if let Err(e) = bench() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}
