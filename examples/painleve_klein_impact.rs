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

use mechlab::scene::{knob, run, Scene};
use mechlab::scenes::{method_from, method_knobs};
use mechlab::studies::painleve::impact::{impact, ImpactSettings};
use mechlab::studies::painleve::{parameter_knobs, params_from_scene};

fn main() {
    run(|| {
        let mut knobs = parameter_knobs();
        knobs.extend([
            knob(
                "x2_starts",
                "-0.65,-0.78",
                "x2(0) of each case (x1 = 0, x1' = x2' = 10)",
            ),
            knob("t_end", "4", "end time (a case at rest ends earlier)"),
            knob("samples", "4000", "samples per case for the figures"),
        ]);
        knobs.extend(method_knobs("dop853", "1e-10"));
        let scene = Scene::from_args(
            "painleve_klein_impact",
            "the worked example: stick–slip switching, friction impact, event table",
            &knobs,
        )?;
        let result = impact(&ImpactSettings {
            params: params_from_scene(&scene)?,
            x2_starts: scene.numbers("x2_starts")?,
            t_end: scene.positive("t_end")?,
            method: method_from(&scene)?,
            samples: scene.count("samples")?,
        })?;
        for c in &result.cases {
            println!(
                "x2(0) = {}: δ(0) = {:.4}; {} switches, {} phases, {} steps; {} at t = {:.6}, accelerations {:?}",
                c.x2_0, c.delta_0, c.events.len(), c.phases, c.steps, c.r#final, c.t_end, c.acceleration
            );
            for e in &c.events {
                println!(
                    "  t = {:.6}  point {}  case {:>2}  {} -> {}  v1 = {:+.6}  v2 = {:+.6}  R = {:.6}",
                    e.t, e.point, e.case, e.from, e.to, e.v1, e.v2, e.R
                );
            }
        }
        scene.save_figure(&result.figure(), "impact.png")?;
        let header = ["x2_0", "t", "point", "case", "from", "to", "v1", "v2", "R"];
        scene.write_csv("events.csv", &header, result.event_rows())?;
        let header = [
            "x2_0",
            "t",
            "x1",
            "x2",
            "v1",
            "v2",
            "delta",
            "delta_rate",
            "R",
        ];
        scene.write_csv("series.csv", &header, result.series_rows())?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
