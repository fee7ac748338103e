//! The problems: the Kapitza period map (regular and chaotic orbits), the
//! double and triple pendulums on a vibrating base, the sliding rod.

use crate::harness::{
    end_state, max_difference, reference_end, reference_orbit, solvers, sweep, timed, BenchError,
    Failure, Row, RunError, Solver,
};
use mechlab::analysis::floquet::{monodromies, monodromy};
use mechlab::contact::{Mode, Smooth};
use mechlab::models::painleve_klein::{self as painleve, Contacts};
use mechlab::models::{double_pendulum as dp, kapitza, triple_pendulum};
use mechlab::ode::{Integrator, LaneIntegrator, Method, Orbit, System};
use mechlab::studies::painleve::state_with_deformation;
use std::collections::BTreeMap;
use std::f64::consts::TAU;

/// Every run of every problem, and each problem's reference agreement.
pub struct Runs {
    pub rows: Vec<Row>,
    pub failures: Vec<Failure>,
    pub agreements: BTreeMap<String, f64>,
}

/// The Kapitza pendulum of the benchmark and its regular start.
pub const KAPITZA: kapitza::Params = kapitza::Params {
    A: 1.5,
    eps: 0.1,
    mu: 0.0,
};
pub const REGULAR: [f64; 2] = [0.3, 0.0];

/// Sweeps every method over every problem.
pub fn run_all(min_seconds: f64, periods: usize, budget: f64) -> Result<Runs, BenchError> {
    let mut runs = Runs {
        rows: Vec::new(),
        failures: Vec::new(),
        agreements: BTreeMap::new(),
    };
    kapitza_map(&mut runs, min_seconds, periods, budget)?;
    kapitza_ensemble(&mut runs, min_seconds)?;
    triple_monodromy_sweep(&mut runs, min_seconds)?;
    vibrating_bases(&mut runs, min_seconds, budget)?;
    sliding_rod(&mut runs, min_seconds, budget)?;
    Ok(runs)
}

/// Steps of `span / k` for each k.
fn per_period(n: &[usize], span: f64) -> Vec<f64> {
    n.iter().map(|&k| span / k as f64).collect()
}

/// (a) The Kapitza period map over `periods` periods: the worst one-period
/// error along regular and chaotic reference orbits, and the global error
/// of the regular orbit.
fn kapitza_map(
    runs: &mut Runs,
    min_seconds: f64,
    periods: usize,
    budget: f64,
) -> Result<(), BenchError> {
    // (a) The Kapitza period map.
    let kp = KAPITZA;
    let kapitza_system = kapitza::Exact { params: kp };
    let period = TAU * kp.eps;
    let check = Method::Gauss {
        stages: 3,
        step: period / 512.0,
    };
    let list = solvers(
        &per_period(&[8, 16, 32, 64, 128, 256, 512, 1024], period),
        false,
    );
    let (regular, chaotic) = (REGULAR, [1.0, 0.0]);
    let kapitza_problems = [
        (
            "kapitza_regular",
            regular,
            reference_orbit(&kapitza_system, &regular, period, periods, check)?,
        ),
        (
            "kapitza_regular_global",
            regular,
            reference_end::<_, 2, 3>(&kapitza_system, &regular, period, periods, check)?,
        ),
        (
            "kapitza_chaotic",
            chaotic,
            reference_orbit(&kapitza_system, &chaotic, period, periods, check)?,
        ),
    ];
    for (problem, y0, (how, agreement)) in &kapitza_problems {
        runs.agreements.insert(problem.to_string(), *agreement);
        sweep::<_, 2, 3>(
            problem,
            &kapitza_system,
            y0,
            how,
            &list,
            min_seconds,
            budget,
            &mut runs.rows,
            &mut runs.failures,
        );
    }

    Ok(())
}

/// Periods of each orbit of the ensemble.
const ENSEMBLE_PERIODS: usize = 20;

/// (a′) An ensemble, the sweeps' workload: 64 Kapitza orbits from an 8×8
/// grid over (q, p) ∈ [−3, 3] × [−2, 2], 20 periods each, one orbit at a
/// time (`dop853`, `taylor`) and streamed through the batch lanes
/// (`taylor_lanes`, one core). The error is the worst end state's against
/// DOP853 at 1e-14; the time is the whole ensemble's.
fn kapitza_ensemble(runs: &mut Runs, min_seconds: f64) -> Result<(), BenchError> {
    const PROBLEM: &str = "kapitza_ensemble";
    let system = kapitza::Exact { params: KAPITZA };
    let period = TAU * KAPITZA.eps;
    let cell = |k: usize, low: f64, width: f64| low + width * (k as f64 + 0.5) / 8.0;
    let starts: Vec<[f64; 2]> = (0..64)
        .map(|k| [cell(k % 8, -3.0, 6.0), cell(k / 8, -2.0, 4.0)])
        .collect();
    let one_by_one = |solver: Solver| -> Result<(Vec<[f64; 2]>, u64), RunError> {
        let (mut ends, mut evals) = (Vec::new(), 0);
        for y0 in &starts {
            let (y, e) = end_state::<_, 2, 3>(solver, &system, y0, period, ENSEMBLE_PERIODS)?;
            ends.push(y);
            evals += e;
        }
        Ok((ends, evals))
    };
    let streamed = |tol: f64| -> Result<(Vec<[f64; 2]>, u64), RunError> {
        let mut lanes = LaneIntegrator::new(Method::Taylor { tol })?;
        let (mut ends, mut done) = (starts.clone(), vec![0; starts.len()]);
        let orbits = Orbit::of_one_system(&system, period, &starts);
        let errors = lanes.stream(&orbits, |k, y| {
            (ends[k], done[k]) = (*y, done[k] + 1);
            done[k] < ENSEMBLE_PERIODS
        });
        match errors.into_iter().flatten().next() {
            Some(e) => Err(e.into()),
            None => Ok((ends, lanes.stats.f_evals)),
        }
    };
    let (reference, _) = one_by_one(Solver::Ours(Method::parse("dop853", 1e-14)?))?;
    let worst = |ends: &[[f64; 2]]| {
        ends.iter()
            .zip(&reference)
            .map(|(a, b)| max_difference(a, b))
            .fold(0.0, f64::max)
    };
    lanes_rows(runs, PROBLEM, min_seconds, |method, tol| {
        let (ends, evals) = match method {
            "taylor_lanes" => streamed(tol)?,
            _ => one_by_one(Solver::Ours(Method::parse(method, tol)?))?,
        };
        Ok((worst(&ends), evals))
    });
    Ok(())
}

/// The rows of a problem for `dop853`, `taylor` and `taylor_lanes` at the
/// tolerances 1e-3 … 1e-14: `run(method, tol)` gives the error and the
/// f-evaluations of one run, [`timed`] its time.
fn lanes_rows(
    runs: &mut Runs,
    problem: &'static str,
    min_seconds: f64,
    run: impl Fn(&'static str, f64) -> Result<(f64, u64), RunError>,
) {
    for k in 3..=14 {
        let tol = 10f64.powi(-k);
        for method in ["dop853", "taylor", "taylor_lanes"] {
            match timed(min_seconds, || run(method, tol)) {
                Ok(((error, f_evals), seconds)) => runs.rows.push(Row {
                    problem,
                    method,
                    tol_or_step: tol,
                    error,
                    seconds,
                    f_evals,
                }),
                Err(reason) => runs.failures.push(Failure {
                    problem,
                    method,
                    tol_or_step: tol,
                    reason: reason.to_string(),
                }),
            }
        }
    }
}

/// (a″) A sweep over parameters, the stability charts' workload: the
/// monodromy matrices of the triple pendulum's upright over one base
/// period at 32 points (ν, a) of a 4 × 8 grid, each with its own period,
/// one at a time (`dop853`, `taylor`) and through the batch lanes with
/// each lane's own parameters (`taylor_lanes`, one core). The error is the
/// worst matrix entry's against DOP853 at 1e-14; the time is the sweep's.
fn triple_monodromy_sweep(runs: &mut Runs, min_seconds: f64) -> Result<(), BenchError> {
    const PROBLEM: &str = "triple_monodromy_sweep";
    let problems: Vec<(triple_pendulum::Exact, f64, [f64; 6])> = (0..32)
        .map(|k| {
            let params = triple_pendulum::Params {
                nu: 50.0 + 25.0 * (k % 4) as f64,
                a: 1.0 + 0.25 * (k / 4) as f64,
                ..Default::default()
            };
            (triple_pendulum::Exact { params }, TAU / params.nu, [0.0; 6])
        })
        .collect();
    type Matrices = Vec<[[f64; 6]; 6]>;
    let one_by_one = |method: Method| -> Result<(Matrices, u64), RunError> {
        let (mut matrices, mut f_evals) = (Vec::new(), 0);
        for (system, period, y0) in &problems {
            let mut integrator = Integrator::new(method)?;
            matrices.push(monodromy::<_, 6, 42>(&mut integrator, system, *period, y0)?.1);
            f_evals += integrator.stats.f_evals;
        }
        Ok((matrices, f_evals))
    };
    let in_lanes = |tol: f64| -> Result<(Matrices, u64), RunError> {
        let (results, stats) = monodromies::<_, 6, 42>(Method::Taylor { tol }, &problems);
        let matrices = results
            .into_iter()
            .map(|r| r.map(|(_, m)| m))
            .collect::<Result<_, _>>()?;
        Ok((matrices, stats.f_evals))
    };
    let (reference, _) = one_by_one(Method::parse("dop853", 1e-14)?)?;
    let worst = |matrices: &Matrices| {
        matrices
            .iter()
            .zip(&reference)
            .flat_map(|(m, r)| m.iter().zip(r).map(|(a, b)| max_difference(a, b)))
            .fold(0.0, f64::max)
    };
    lanes_rows(runs, PROBLEM, min_seconds, |method, tol| {
        let (matrices, f_evals) = match method {
            "taylor_lanes" => in_lanes(tol)?,
            _ => one_by_one(Method::parse(method, tol)?)?,
        };
        Ok((worst(&matrices), f_evals))
    });
    Ok(())
}

fn vibrating_bases(runs: &mut Runs, min_seconds: f64, budget: f64) -> Result<(), BenchError> {
    // (b) Pendulums on the vibrating base, t ∈ [0, 10]: the double pendulum
    // at ν = 100 (symbolic inverse), the triple at ν = 200 (numeric solve).
    let settings = (min_seconds, budget);
    let pp = dp::Params {
        nu: 100.0,
        ..Default::default()
    };
    let y0 = [0.3, -0.2, 0.0, 0.0];
    let agreement = vibrating_base::<_, 4, 5>(
        "double_pendulum",
        &dp::Exact { params: pp },
        &y0,
        pp.nu,
        settings,
        &mut runs.rows,
        &mut runs.failures,
    )?;
    runs.agreements.insert("double_pendulum".into(), agreement);
    let tp = triple_pendulum::Params {
        nu: 200.0,
        ..Default::default()
    };
    let y0 = [0.3, -0.2, 0.1, 0.0, 0.0, 0.0];
    let agreement = vibrating_base::<_, 6, 7>(
        "triple_pendulum",
        &triple_pendulum::Exact { params: tp },
        &y0,
        tp.nu,
        settings,
        &mut runs.rows,
        &mut runs.failures,
    )?;
    runs.agreements.insert("triple_pendulum".into(), agreement);

    Ok(())
}

fn sliding_rod(runs: &mut Runs, min_seconds: f64, budget: f64) -> Result<(), BenchError> {
    // (c) The sliding deformable rod, ε = 0.01 and 0.001, t ∈ [0, 2], from R(0) = 3.
    for (problem, eps) in [("rod_eps_0.01", 1e-2), ("rod_eps_0.001", 1e-3)] {
        let model = Contacts {
            params: painleve::Params {
                eps,
                ..Default::default()
            },
        };
        // Both points sliding right: the smooth phase of the contact model.
        let rod = Smooth {
            model: &model,
            modes: [Mode::Slide(1); 2],
        };
        let y0 = state_with_deformation(&model.params, 3.0 * eps * eps, 10.0);
        let list = solvers(
            &per_period(&[64, 128, 256, 512, 1024, 2048, 4096, 8192, 16384], 2.0),
            true,
        );
        let (how, agreement) =
            reference_end::<_, 4, 5>(&rod, &y0, 2.0, 1, Method::parse("radau5", 1e-13)?)?;
        runs.agreements.insert(problem.to_string(), agreement);
        sweep::<_, 4, 5>(
            problem,
            &rod,
            &y0,
            &how,
            &list,
            min_seconds,
            budget,
            &mut runs.rows,
            &mut runs.failures,
        );
    }

    Ok(())
}

/// A pendulum on a base vibrating at `nu`, t ∈ [0, 10]: every method against
/// a DOP853 reference checked with Gauss 6; returns the references' agreement.
pub fn vibrating_base<S: System<N>, const N: usize, const M: usize>(
    problem: &'static str,
    system: &S,
    y0: &[f64; N],
    nu: f64,
    (min_seconds, budget): (f64, f64),
    rows: &mut Vec<Row>,
    failures: &mut Vec<Failure>,
) -> Result<f64, BenchError> {
    let forcing = TAU / nu;
    let steps: Vec<f64> = [4, 8, 16, 32, 64, 128, 256]
        .iter()
        .map(|&k| forcing / k as f64)
        .collect();
    let list = solvers(&steps, false);
    let check = Method::Gauss {
        stages: 3,
        step: forcing / 256.0,
    };
    let (how, agreement) = reference_end::<_, N, M>(system, y0, 10.0, 1, check)?;
    sweep::<_, N, M>(
        problem,
        system,
        y0,
        &how,
        &list,
        min_seconds,
        budget,
        rows,
        failures,
    );
    Ok(agreement)
}
