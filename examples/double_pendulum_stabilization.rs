//! Scene `double_pendulum_stabilization` (deliverable 2.4): which equilibria
//! of the double pendulum does vertical vibration stabilise, and from which
//! amplitude on?
//!
//! For every equilibrium (φ1, φ2 ∈ {0, π}): the roots λ of det(C − λA) = 0
//! (from the generated mass matrix and potential Hessian), stability without
//! vibration, and for the unstable ones the threshold a* of the criterion
//! a² > g²/(mean(h²)|λ*|), as a closed formula and as a number. Then long
//! runs of the limiting system from a small neighbourhood slightly above a*
//! (stays near) and slightly below (leaves), and the exact system's
//! stability window in a at the given ν from its Floquet multipliers: its
//! lower edge is close to a*; its upper edge, where parametric resonance
//! destabilises the equilibrium again, the averaged system does not have.

use mechlab::scene::{knob, run, Progress, Scene};
use mechlab::scenes::{method_from, method_knobs};
use mechlab::studies::double_pendulum::{
    parameter_knobs, params_from_scene, stabilization_study, StabilizationSettings, EQUILIBRIA,
};

fn main() {
    run(|| {
        let mut knobs = parameter_knobs(&[]);
        knobs.extend([
            knob(
                "offset",
                "0.05",
                "initial distance of the long runs from the equilibrium (both angles)",
            ),
            knob(
                "t_long",
                "300",
                "length of the long runs of the limiting system",
            ),
            knob("margin", "0.1", "the long runs use a = (1 ± margin) a*"),
            knob(
                "a_max_factor",
                "30",
                "the exact window is searched for a up to this × a*",
            ),
            knob(
                "chart_points",
                "150",
                "amplitudes sampled for the exact spectral-radius chart",
            ),
        ]);
        knobs.extend(method_knobs("dop853", "1e-10"));
        let scene = Scene::from_args(
            "double_pendulum_stabilization",
            "equilibria, criterion (11), a*, long runs of the limiting system, the exact stability window",
            &knobs,
        )?;
        let progress = Progress::new("equilibria", EQUILIBRIA.len());
        let result = stabilization_study(
            &StabilizationSettings {
                params: params_from_scene(&scene)?,
                offset: scene.number("offset")?,
                t_long: scene.positive("t_long")?,
                margin: scene.positive("margin")?,
                a_max_factor: scene.positive("a_max_factor")?,
                chart_points: scene.count("chart_points")?,
                method: method_from(&scene)?,
            },
            &|done| progress.update(done),
        )?;
        for e in &result.equilibria {
            println!(
                "({}, {}): λ = {:?}, stable without vibration: {}, a* = {:?} {}, exact window at ν = {}: {:?}",
                e.phi1, e.phi2, e.lambdas, e.stable_without_vibration, e.a_star,
                e.a_star_formula.as_deref().unwrap_or(""), result.nu, e.exact_window
            );
        }
        scene.save_figure(&result.figure(), "stabilization.png")?;
        let header = ["panel", "a", "spectral_radius"];
        scene.write_csv("exact_spectral_radius.csv", &header, result.chart_rows())?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
