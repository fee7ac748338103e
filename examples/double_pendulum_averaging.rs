//! Scene `double_pendulum_averaging` (deliverable 2.2): Theorem 2 of the
//! averaging method on the double pendulum with a vibrating base.
//!
//! For every amplitude a and every initial state (a grid of cases), the exact
//! system at large ν and the limiting (averaged) system start from the same
//! (q, p); the figure shows φ1, φ2 of both against t, the deviations
//! |exact − limit| (of order 1/ν), and both systems' generalised velocities,
//! which differ by O(1) at the fast time scale: the velocities converge only
//! weakly, not uniformly.

use mechlab::scene::{knob, run, Scene, SceneError, ValueProblem};
use mechlab::scenes::{method_from, method_knobs};
use mechlab::studies::double_pendulum::{
    averaging_cases, parameter_knobs, params_from_scene, AveragingSettings,
};

fn main() {
    run(|| {
        let mut knobs = parameter_knobs(&[("nu", "1000")]);
        knobs.extend([
            knob("amplitudes", "2.5,5", "values of a, one row of cases each"),
            knob("phi1_starts", "0.2,0.5", "φ1(0) of each initial state"),
            knob(
                "phi2_starts",
                "-0.1,0.3",
                "φ2(0) of each initial state (p(0) = 0)",
            ),
            knob("t_end", "10", "observation time"),
        ]);
        knobs.extend(method_knobs("dop853", "1e-10"));
        let scene = Scene::from_args(
            "double_pendulum_averaging",
            "exact (large ν) against limiting system from the same (q, p): coordinates, deviations, velocities",
            &knobs,
        )?;
        let (phi1, phi2) = (scene.numbers("phi1_starts")?, scene.numbers("phi2_starts")?);
        if phi1.len() != phi2.len() {
            return Err(SceneError::BadValue {
                name: "phi2_starts".into(),
                value: scene.text("phi2_starts").into(),
                reason: ValueProblem::AsManyAs {
                    knob: "phi1_starts",
                    count: phi1.len(),
                },
            });
        }
        let result = averaging_cases(&AveragingSettings {
            params: params_from_scene(&scene)?,
            amplitudes: scene.numbers("amplitudes")?,
            starts: phi1.iter().zip(&phi2).map(|(x, y)| [*x, *y]).collect(),
            t_end: scene.positive("t_end")?,
            method: method_from(&scene)?,
        })?;
        for case in &result.cases {
            println!("{case:?}");
        }
        scene.save_figure(&result.figure(), "averaging.png")?;
        let header = [
            "case",
            "t",
            "phi1_exact",
            "phi2_exact",
            "phi1_limit",
            "phi2_limit",
            "v1_exact",
            "v2_exact",
            "v1_limit",
            "v2_limit",
        ];
        scene.write_csv("series.csv", &header, result.rows())?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
