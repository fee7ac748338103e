//! The IFToMM library of multibody benchmark problems, each from one
//! command: the simple pendulum (A01), the N-four-bar through its
//! singular positions (A02), Andrews' squeezing mechanism (A03), Bricard's
//! overconstrained mechanism (A04) and the stiff flyball governor (A05),
//! over the library's spans from its starts. Prints each run's CPU time,
//! steps, energy error and constraint residual beside the OpenSim 3.2
//! times its implementers published; writes `out/iftomm/iftomm.png` (each
//! problem's energy change over its span; A05's slider), `<id>.csv`
//! (time, state, energy) and `summary.json`. The tests in `tests/constrained.rs`,
//! `tests/bricard.rs` and `tests/flyball_governor.rs` check each against
//! references written out by hand.
//!
//! `cargo run --release -p mechlab-test-models --example iftomm [-- A04]`

use mechlab_runtime::analysis::on_constraints::run;
use mechlab_runtime::ode::{states_at, Method};
use mechlab_runtime::plot::{Figure, PanelSpec, BLUE};
use mechlab_runtime::registry::ConstrainedSystems;
use mechlab_test_models as models;
use std::f64::consts::TAU;
use std::time::Instant;

/// One benchmark: its id, model, parameters, start (None: the file's),
/// span and OpenSim's published CPU time (s, Intel i5-4570).
struct Benchmark {
    id: &'static str,
    model: &'static dyn ConstrainedSystems,
    params: Vec<f64>,
    start: Option<Vec<f64>>,
    span: f64,
    opensim: f64,
}

#[derive(serde::Serialize)]
struct Row {
    id: &'static str,
    model: &'static str,
    span: f64,
    steps: u64,
    seconds: f64,
    energy_error: f64,
    residual: f64,
    opensim_seconds: f64,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let only = std::env::args().nth(1);
    let tight = Method::Dop853 {
        rtol: 1e-13,
        atol: 1e-13,
    };
    let out = std::path::Path::new("out/iftomm");
    std::fs::create_dir_all(out)?;
    let benchmarks = benchmarks();
    let (mut rows, mut panels) = (Vec::new(), Vec::new());
    println!("id   model                 span     steps  CPU (s)   energy error  residual   OpenSim 3.2 (s)");
    for b in benchmarks
        .iter()
        .filter(|b| only.as_deref().is_none_or(|id| id == b.id))
    {
        let times: Vec<f64> = (0..=1000).map(|k| b.span * k as f64 / 1000.0).collect();
        let started = Instant::now();
        let r = run(b.model, &b.params, b.start.as_deref(), tight, &times)?;
        let seconds = started.elapsed().as_secs_f64();
        // A03's motor does work: its energy balance is T + V − τ(β − β₀),
        // τ the model's parameter `mom`.
        let torque = models::andrews_squeezer::Params::default().mom;
        let work = |k: usize| match b.id {
            "A03" => torque * (r.states[k][0] - r.states[0][0]),
            _ => 0.0,
        };
        let energy_error = (0..r.energy.len())
            .map(|k| (r.energy[k] - r.energy[0] - work(k)).abs())
            .fold(0.0, f64::max);
        let residual = r.largest_residual.0.max(r.largest_residual.1);
        let row = Row {
            id: b.id,
            model: r.model,
            span: b.span,
            steps: r.steps,
            seconds,
            energy_error,
            residual,
            opensim_seconds: b.opensim,
        };
        println!(
            "{:<4} {:<21} {:<8.4} {:<6} {:<9.4} {:<13.1e} {:<10.1e} {}",
            row.id,
            row.model,
            row.span,
            row.steps,
            row.seconds,
            row.energy_error,
            row.residual,
            row.opensim_seconds
        );
        let mut csv = String::from("t,state...,energy\n");
        for ((t, y), e) in r.times.iter().zip(&r.states).zip(&r.energy) {
            let state: Vec<String> = y.iter().map(|v| format!("{v:.17e}")).collect();
            csv += &format!("{t},{},{e:.17e}\n", state.join(","));
        }
        std::fs::write(out.join(format!("{}.csv", b.id)), csv)?;
        let change = (0..r.energy.len())
            .map(|k| (r.times[k], r.energy[k] - r.energy[0] - work(k)))
            .collect();
        panels.push((format!("{} {}", b.id, r.model), "E(t) − E(0)", change));
        rows.push(row);
    }
    if only.as_deref().is_none_or(|id| id == "A05") {
        let slider = flyball_governor(out)?;
        panels.push(("A05 iftomm_flyball_governor".into(), "slider s (m)", slider));
    }
    std::fs::write(
        out.join("summary.json"),
        serde_json::to_string_pretty(&rows)?,
    )?;
    draw(&panels)?.save(&out.join("iftomm.png"))?;
    println!("wrote {}/", out.display());
    Ok(())
}

/// The library's problems that are constrained, with their starts.
fn benchmarks() -> [Benchmark; 4] {
    [
        // A point on a massless 1 m rod released horizontal, in units where
        // g = l = 1: the library's 10 s are 31.3 units.
        Benchmark {
            id: "A01",
            model: &models::cartesian_kapitza::SYSTEMS,
            params: vec![0.0, 0.1, 0.0],
            start: Some(vec![1.0, 0.0, 0.0, 0.0]),
            span: 10.0 * 9.81_f64.sqrt(),
            opensim: 0.637,
        },
        Benchmark {
            id: "A02",
            model: &models::iftomm_n_four_bar::SYSTEMS,
            params: vec![1.0, 1.0, 1.0, 9.81],
            start: None,
            span: 10.0,
            opensim: 0.455,
        },
        Benchmark {
            id: "A03",
            model: &models::andrews_squeezer::SYSTEMS,
            params: models::andrews_squeezer::Params::default().values(),
            start: None,
            span: 0.05,
            opensim: 0.384,
        },
        Benchmark {
            id: "A04",
            model: &models::iftomm_bricard::SYSTEMS,
            params: vec![1.0, 1.0, 9.81],
            start: None,
            span: 10.0,
            opensim: 0.258,
        },
    ]
}

/// A05: the flyball governor is not constrained; its springs and
/// dampers make it stiff, and Radau5 integrates it.
fn flyball_governor(out: &std::path::Path) -> Result<Vec<(f64, f64)>, Box<dyn std::error::Error>> {
    use models::iftomm_flyball_governor::{Exact, Params};
    let exact = Exact {
        params: Params::default(),
    };
    let b0 = TAU / 3.0;
    // The state is [q, p]: the shaft's momentum is 2π times its inertia.
    let q0 = [0.0, 0.5, b0, b0];
    let spin = models::iftomm_flyball_governor::mass_matrix(&q0, &Params::default())[0][0];
    let y0 = [0.0, 0.5, b0, b0, TAU * spin, 0.0, 0.0, 0.0];
    let times: Vec<f64> = (0..=1000).map(|k| 0.01 * k as f64).collect();
    let started = Instant::now();
    let states = states_at(
        Method::Radau5 {
            rtol: 1e-11,
            atol: 1e-11,
        },
        &exact,
        0.0,
        &y0,
        &times,
    )?;
    let seconds = started.elapsed().as_secs_f64();
    let (low, high) = states
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), y| (l.min(y[1]), h.max(y[1])));
    println!("A05  iftomm_flyball_governor 10       -      {seconds:<9.4} (dissipative: the slider between {low:.4} and {high:.4} m)");
    let csv: String = times
        .iter()
        .zip(&states)
        .map(|(t, y)| format!("{t},{}\n", y.map(|v| format!("{v:.17e}")).join(",")))
        .collect();
    std::fs::write(
        out.join("A05.csv"),
        format!("t,phi,s,b1,b2,p_phi,p_s,p_b1,p_b2\n{csv}"),
    )?;
    Ok(times.iter().zip(&states).map(|(&t, y)| (t, y[1])).collect())
}

/// One panel a problem: the energy's change over its span (A05: the
/// slider's height), each on its own scale.
fn draw(panels: &[(String, &str, Vec<(f64, f64)>)]) -> Result<Figure, Box<dyn std::error::Error>> {
    let specs: Vec<PanelSpec> = panels
        .iter()
        .map(|(title, label, series)| {
            let (low, high) = series.iter().fold((f64::MAX, f64::MIN), |(l, h), (_, y)| {
                (l.min(*y), h.max(*y))
            });
            let pad = 0.05 * (high - low).max(f64::MIN_POSITIVE) + 1e-300;
            let span = series.last().map_or(1.0, |(t, _)| *t);
            PanelSpec::new(title, "t", label, (0.0, span), (low - pad, high + pad))
        })
        .collect();
    let mut figure = Figure::grid(specs.len(), 1, 320, 260, &specs);
    for (k, (_, _, series)) in panels.iter().enumerate() {
        figure.line(k, series, BLUE);
    }
    Ok(figure)
}
