//! Scene `painleve_stiff_limit`: the worked example as the rod stiffens,
//! ε = 0.1, 0.03, 0.01, 0.001.
//!
//! Both cases start from the same rod force R(0) as the worked example (the
//! deformation scaled as δ(0) ∝ ε², so that the reduced deformation equation
//! sees the same start): in the regular case R(t) settles to the rigid rod's
//! R* within a time O(ε); in the impact case the stop, the reversal and the
//! final stop happen ever more abruptly. The stiff rod needs the stiff
//! method: Radau IIA 5 between switches. Reported per run: the event times,
//! wall time and steps.

use mechlab::scene::{knob, run, Scene};
use mechlab::scenes::{method_from, method_knobs};
use mechlab::studies::painleve::stiff_limit::{stiff_limit, StiffLimitSettings};

fn main() {
    run(|| {
        let mut knobs = vec![
            knob("eps_values", "0.1,0.03,0.01,0.001", "values of ε"),
            knob(
                "x2_regular",
                "-0.65",
                "x2(0) of the regular case at ε = 0.1",
            ),
            knob("x2_impact", "-0.78", "x2(0) of the impact case at ε = 0.1"),
            knob("t_end", "2", "end time"),
        ];
        knobs.extend(method_knobs("radau5", "1e-8"));
        let scene = Scene::from_args(
            "painleve_stiff_limit",
            "the worked example for ε → 0: R(t) → R*, sharpening friction impact, event times, cost",
            &knobs,
        )?;
        let result = stiff_limit(&StiffLimitSettings {
            eps_values: scene.numbers("eps_values")?,
            x2_regular: scene.number("x2_regular")?,
            x2_impact: scene.number("x2_impact")?,
            t_end: scene.positive("t_end")?,
            method: method_from(&scene)?,
        })?;
        println!("rigid rod: stable root R* = {:?}", result.rigid_R_star);
        for r in &result.runs {
            let events: Vec<(f64, usize, &str)> = r
                .events
                .iter()
                .map(|e| (e.t, e.point, e.case.as_str()))
                .collect();
            println!(
                "{:8} ε = {:<6} {} at t = {:.6}, R = {:.6}, {} steps, {} f, {:.4} s, events {events:?}",
                r.case, r.eps, r.outcome, r.t_end, r.final_R, r.steps, r.f_evals, r.seconds
            );
        }
        scene.save_figure(&result.figure(), "stiff_limit.png")?;
        let header = [
            "case", "eps", "outcome", "t_end", "final_R", "steps", "f_evals", "seconds",
        ];
        scene.write_csv("runs.csv", &header, result.rows())?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
