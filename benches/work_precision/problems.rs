//! The problems: the Kapitza period map (regular and chaotic orbits), the
//! double and triple pendulums on a vibrating base, the sliding rod.

use crate::harness::{reference_end, reference_orbit, solvers, sweep, BenchError, Failure, Row};
use mechlab::contact::{Mode, Smooth};
use mechlab::models::painleve_klein::{self as painleve, Contacts};
use mechlab::models::{double_pendulum as dp, kapitza, triple_pendulum};
use mechlab::ode::{Method, System};
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
