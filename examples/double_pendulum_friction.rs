//! Scene `double_pendulum_friction` (deliverable 2.5): Theorem 3 of the
//! averaging method with viscous friction Q1 = −μ φ1', Q2 = −μ(φ2' − φ1').
//!
//! Above a*, the stabilised equilibrium of the limiting system becomes
//! asymptotically stable: the eigenvalues of its linearisation (from the
//! generated averaged Jacobian) have negative real parts. The figure shows a
//! perturbation decaying in both systems, and the exact system's Floquet
//! multipliers inside the unit circle for several large ν: its spectral
//! radius against ν, beside exp(max Re λ · 2π/ν) that the averaged
//! eigenvalues predict.

use mechlab::ode::Method;
use mechlab::scene::{knob, run, Scene};
use mechlab::studies::double_pendulum::{
    friction, parameter_knobs, params_from_scene, FrictionSettings,
};

fn main() {
    run(|| {
        let mut knobs = parameter_knobs(&[("mu", "0.3")]);
        knobs.extend([
            knob("phi1_eq", "0", "φ1 of the equilibrium (0 or π)"),
            knob("phi2_eq", "0", "φ2 of the equilibrium (0 or π)"),
            knob("offset", "0.1", "initial perturbation of both angles"),
            knob("t_end", "150", "length of the decay runs"),
            knob(
                "nus",
                "50,100,200,400,800,1600",
                "frequencies for the exact multipliers",
            ),
            knob("tol", "1e-11", "DOP853 tolerance"),
        ]);
        let scene = Scene::from_args(
            "double_pendulum_friction",
            "Theorem 3: asymptotic stability of the stabilised equilibrium with friction, averaged and exact",
            &knobs,
        )?;
        let result = friction(&FrictionSettings {
            params: params_from_scene(&scene)?,
            equilibrium: (scene.number("phi1_eq")?, scene.number("phi2_eq")?),
            offset: scene.number("offset")?,
            t_end: scene.positive("t_end")?,
            nus: scene.numbers("nus")?,
            method: Method::parse("dop853", scene.positive("tol")?)?,
        })?;
        println!(
            "averaged eigenvalues {:?}, max Re λ = {:.6}",
            result.averaged_eigenvalues, result.max_real_part
        );
        if result.max_real_part >= 0.0 {
            eprintln!(
                "note: max Re λ ≥ 0: not asymptotically stable at a = {} (raise a or μ)",
                result.a
            );
        }
        for r in &result.exact {
            println!(
                "ν = {}: exact spectral radius {:.9}, averaged prediction {:.9}",
                r.nu, r.spectral_radius, r.predicted
            );
        }
        scene.save_figure(&result.figure(), "friction.png")?;
        let rows = result
            .exact
            .iter()
            .map(|r| (r.nu, r.spectral_radius, r.predicted));
        scene.write_csv(
            "multipliers.csv",
            &["nu", "spectral_radius", "predicted"],
            rows,
        )?;
        let decay = result
            .exact_decay
            .iter()
            .zip(&result.limit_decay)
            .map(|(e, l)| (e.0, e.1, l.1));
        scene.write_csv(
            "decay.csv",
            &["t", "distance_exact", "distance_limit"],
            decay,
        )?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
