//! Scene `painleve_klein_impact` (deliverables 3.5, 3.6 and the worked
//! example): the Painlevé–Klein rod with exact stick–slip switching.
//!
//! For each initial x2(0) (x1 = 0, x1' = x2' = 10): the full dynamics of the
//! two points on rough guides joined by the visco-elastic rod, integrated by
//! the switching integrator of `mechlab::contact` on the generated contact
//! model. Each case gets a row of panels: the phase curve on (δ, δ'), R(t),
//! v1(t) and v2(t), with the switching events marked; the table of events
//! (time, point, case of the scheme, v1, v2, R) and the final state (rest,
//! or sliding with constant acceleration) go to `summary.json` and
//! `events.csv`. x2(0) = −0.65 starts inside the basin of the stable
//! equilibrium of the deformation equation, −0.78 outside it.

use mechlab::contact::{Outcome, Smooth, StickSlip};
use mechlab::models::painleve_klein::Contacts;
use mechlab::ode::{Method, System};
use mechlab::plot::{Figure, PanelSpec, BLACK, BLUE, RED};
use mechlab::scene::{knob, run, Knob, Scene, SceneError};
use mechlab::studies::painleve::{parameter_knobs, params_from_scene, rod, worked_example_start};

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

/// One switch of the event table.
#[allow(non_snake_case)]
#[derive(serde::Serialize)]
struct Event {
    t: f64,
    point: usize,
    case: String,
    from: String,
    to: String,
    v1: f64,
    v2: f64,
    R: f64,
}

/// One initial condition: its events and how it ends.
#[derive(serde::Serialize)]
struct Case {
    x2_0: f64,
    delta_0: f64,
    events: Vec<Event>,
    /// "rest" or "sliding".
    r#final: &'static str,
    t_end: f64,
    /// The constant accelerations when sliding at the end.
    acceleration: Option<[f64; 2]>,
    final_state: [f64; 4],
    steps: u64,
    phases: usize,
}

fn knobs() -> Vec<Knob> {
    let mut knobs = parameter_knobs();
    knobs.extend([
        knob(
            "x2_starts",
            "-0.65,-0.78",
            "x2(0) of each case (x1 = 0, x1' = x2' = 10)",
        ),
        knob("t_end", "4", "end time (a case at rest ends earlier)"),
        knob(
            "method",
            "dop853",
            "integration method between switches (radau5 for stiff rods)",
        ),
        knob("tol", "1e-10", "tolerance"),
        knob("samples", "4000", "samples per case for the figures"),
    ]);
    knobs
}

fn main() {
    run(|| {
        let knobs = knobs();
        let scene = Scene::from_args(
            "painleve_klein_impact",
            "the worked example: stick–slip switching, friction impact, event table",
            &knobs,
        )?;
        let params = params_from_scene(&scene)?;
        let t_end = scene.positive("t_end")?;
        let method = Method::parse(scene.text("method"), scene.positive("tol")?)?;
        let samples = scene.count("samples")?;
        let times: Vec<f64> = (0..=samples)
            .map(|i| t_end * i as f64 / samples as f64)
            .collect();
        let model = Contacts { params };
        let integrator = StickSlip::new(method);

        let mut cases = Vec::new();
        let mut event_rows = Vec::new();
        let mut figures_data = Vec::new();
        for x2 in scene.numbers("x2_starts")? {
            let y0 = worked_example_start(x2);
            let run = integrator
                .run(&model, 0.0, &y0, t_end, &times)
                .map_err(|e| SceneError::Numerical(format!("x2(0) = {x2}: {e}")))?;
            let steps: u64 = run.phases.iter().map(|p| p.stats.steps).sum();
            println!(
                "x2(0) = {x2}: δ(0) = {:.4}; {} switches, {} phases, {steps} steps; {:?} at t = {:.6}",
                rod(&y0, &params).delta,
                run.switches.len(),
                run.phases.len(),
                run.outcome,
                run.t
            );
            let events: Vec<Event> = run
                .switches
                .iter()
                .map(|s| {
                    let r = rod(&s.y, &params).reaction;
                    println!(
                        "  t = {:.6}  point {}  case {:>2}  {} -> {}  v1 = {:+.6}  v2 = {:+.6}  R = {:.6}",
                        s.t, s.contact + 1, s.case, s.from, s.to, s.y[2], s.y[3], r
                    );
                    event_rows.push((
                        x2,
                        s.t,
                        s.contact + 1,
                        s.case.clone(),
                        s.from.to_string(),
                        s.to.to_string(),
                        [s.y[2], s.y[3], r],
                    ));
                    Event {
                        t: s.t,
                        point: s.contact + 1,
                        case: s.case.clone(),
                        from: s.from.to_string(),
                        to: s.to.to_string(),
                        v1: s.y[2],
                        v2: s.y[3],
                        R: r,
                    }
                })
                .collect();
            let (final_state, acceleration) = match run.outcome {
                Outcome::Rest => ("rest", None),
                Outcome::Moving => {
                    let f = Smooth {
                        model: &model,
                        modes: run.modes,
                    }
                    .rhs(run.t, &run.y);
                    println!(
                        "  sliding at the end with accelerations ({:.6}, {:.6})",
                        f[2], f[3]
                    );
                    ("sliding", Some([f[2], f[3]]))
                }
            };
            cases.push(Case {
                x2_0: x2,
                delta_0: rod(&y0, &params).delta,
                events,
                r#final: final_state,
                t_end: run.t,
                acceleration,
                final_state: run.y,
                steps,
                phases: run.phases.len(),
            });
            figures_data.push((x2, run));
        }

        let titles: Vec<String> = figures_data
            .iter()
            .flat_map(|(x2, _)| {
                ["phase curve (δ, δ′)", "rod force R(t)", "v₁(t)", "v₂(t)"]
                    .map(|what| format!("x₂(0) = {x2}: {what}"))
            })
            .collect();
        let mut specs = Vec::new();
        for (k, (_, run)) in figures_data.iter().enumerate() {
            let rods: Vec<_> = run.samples.iter().map(|(_, y)| rod(y, &params)).collect();
            let t_range = (0.0, run.t.max(1e-9));
            specs.push(PanelSpec::new(
                &titles[4 * k],
                "δ",
                "δ′",
                range(rods.iter().map(|r| r.delta)),
                range(rods.iter().map(|r| r.delta_rate)),
            ));
            specs.push(PanelSpec::new(
                &titles[4 * k + 1],
                "t",
                "R",
                t_range,
                range(rods.iter().map(|r| r.reaction)),
            ));
            specs.push(PanelSpec::new(
                &titles[4 * k + 2],
                "t",
                "v₁",
                t_range,
                range(run.samples.iter().map(|(_, y)| y[2]).chain([0.0])),
            ));
            specs.push(PanelSpec::new(
                &titles[4 * k + 3],
                "t",
                "v₂",
                t_range,
                range(run.samples.iter().map(|(_, y)| y[3]).chain([0.0])),
            ));
        }
        let mut figure = Figure::grid(4, figures_data.len(), 400, 330, &specs);
        let mut series = Vec::new();
        for (k, (x2, run)) in figures_data.iter().enumerate() {
            let rods: Vec<_> = run.samples.iter().map(|(_, y)| rod(y, &params)).collect();
            let phase: Vec<(f64, f64)> = rods.iter().map(|r| (r.delta, r.delta_rate)).collect();
            let force: Vec<(f64, f64)> = run
                .samples
                .iter()
                .zip(&rods)
                .map(|((t, _), r)| (*t, r.reaction))
                .collect();
            let v1: Vec<(f64, f64)> = run.samples.iter().map(|(t, y)| (*t, y[2])).collect();
            let v2: Vec<(f64, f64)> = run.samples.iter().map(|(t, y)| (*t, y[3])).collect();
            figure.line(4 * k, &phase, BLUE);
            figure.line(4 * k + 1, &force, BLACK);
            figure.line(4 * k + 2, &v1, BLUE);
            figure.line(4 * k + 3, &v2, RED);
            for s in &run.switches {
                let r = rod(&s.y, &params);
                figure.points(4 * k, [(r.delta, r.delta_rate)], RED, 7);
                figure.points(4 * k + 1, [(s.t, r.reaction)], RED, 7);
                figure.points(4 * k + 2, [(s.t, s.y[2])], RED, 7);
                figure.points(4 * k + 3, [(s.t, s.y[3])], RED, 7);
            }
            series.extend(
                run.samples
                    .iter()
                    .zip(&rods)
                    .map(|((t, y), r)| (*x2, *t, *y, [r.delta, r.delta_rate, r.reaction])),
            );
        }
        scene.save_figure(&figure, "impact.png")?;
        scene.write_csv(
            "events.csv",
            &["x2_0", "t", "point", "case", "from", "to", "v1", "v2", "R"],
            event_rows,
        )?;
        scene.write_csv(
            "series.csv",
            &[
                "x2_0",
                "t",
                "x1",
                "x2",
                "v1",
                "v2",
                "delta",
                "delta_rate",
                "R",
            ],
            series,
        )?;
        #[derive(serde::Serialize)]
        struct Summary {
            cases: Vec<Case>,
        }
        scene.write_summary(&Summary { cases })?;
        Ok(())
    });
}
