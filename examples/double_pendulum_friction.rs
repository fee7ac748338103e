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

use mechlab::analysis::averaging::{compare, time_grid};
use mechlab::analysis::vibrational_stability::linearization_eigenvalues;
use mechlab::models::double_pendulum::{self as model, Averaged, Exact};
use mechlab::ode::Method;
use mechlab::plot::{Figure, PanelSpec, BLACK, BLUE, GREY};
use mechlab::scene::{knob, run, Scene, SceneError};
use mechlab::studies::double_pendulum::{
    analyse_equilibrium, exact_multipliers, parameter_knobs, params_from_scene,
};
use std::f64::consts::PI;

/// The exact system's multipliers at one frequency.
#[derive(serde::Serialize)]
struct ExactMultipliers {
    nu: f64,
    spectral_radius: f64,
    /// exp(max Re λ · 2π/ν) from the averaged eigenvalues.
    predicted: f64,
    multipliers: Vec<[f64; 2]>,
}

#[derive(serde::Serialize)]
struct Summary {
    equilibrium: [f64; 2],
    mu: f64,
    a: f64,
    nu: f64,
    averaged_eigenvalues: Vec<[f64; 2]>,
    max_real_part: f64,
    exact: Vec<ExactMultipliers>,
}

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
        let params = params_from_scene(&scene)?;
        let phi = (scene.number("phi1_eq")?, scene.number("phi2_eq")?);
        let offset = scene.number("offset")?;
        let t_end = scene.positive("t_end")?;
        let nus = scene.numbers("nus")?;
        let tol = scene.positive("tol")?;
        let method = Method::parse("dop853", tol)?;
        let analysis = analyse_equilibrium(&params, phi);
        println!("equilibrium {phi:?}: {:?}", analysis.stabilization);

        let y_eq = [phi.0, phi.1, 0.0, 0.0];
        let eigenvalues = linearization_eigenvalues(&model::averaged_jacobian(&y_eq, &params));
        let max_re = eigenvalues.iter().fold(f64::MIN, |m, (re, _)| m.max(*re));
        println!("averaged linearisation: eigenvalues {eigenvalues:?}, max Re λ = {max_re:.6}");
        if max_re >= 0.0 {
            eprintln!(
                "note: max Re λ ≥ 0: not asymptotically stable at a = {} (raise a or μ)",
                params.a
            );
        }

        // Decay of a perturbation in both systems from the same (q, p).
        let y0 = [phi.0 + offset, phi.1 - offset, 0.0, 0.0];
        let grid = time_grid(t_end, 2.0 * PI / params.nu, 8, 2000);
        let c = compare(method, &Exact { params }, &Averaged { params }, &y0, &grid)?;
        let distance = |y: &[f64; 4]| (y[0] - phi.0).hypot(y[1] - phi.1);
        let exact_curve: Vec<(f64, f64)> = c
            .times
            .iter()
            .zip(&c.exact)
            .map(|(t, y)| (*t, distance(y)))
            .collect();
        let averaged_curve: Vec<(f64, f64)> = c
            .times
            .iter()
            .zip(&c.averaged)
            .map(|(t, y)| (*t, distance(y)))
            .collect();
        let predicted: Vec<(f64, f64)> = c
            .times
            .iter()
            .map(|t| (*t, offset * std::f64::consts::SQRT_2 * (max_re * t).exp()))
            .collect();

        // Exact Floquet multipliers for several ν.
        let mut radii = Vec::new();
        let mut rows = Vec::new();
        for &nu in &nus {
            let p = model::Params { nu, ..params };
            let (radius, multipliers) = exact_multipliers(&p, phi, tol)?;
            let expected = (max_re * 2.0 * PI / nu).exp();
            println!(
                "ν = {nu}: exact spectral radius {radius:.9}, averaged prediction {expected:.9}"
            );
            rows.push((nu, radius, expected));
            radii.push(ExactMultipliers {
                nu,
                spectral_radius: radius,
                predicted: expected,
                multipliers: multipliers.iter().map(|(re, im)| [*re, *im]).collect(),
            });
        }
        if radii.iter().any(|r| r.spectral_radius >= 1.0) {
            eprintln!("note: some exact multipliers are not inside the unit circle");
        }

        let floor = exact_curve
            .iter()
            .chain(&averaged_curve)
            .map(|p| p.1)
            .filter(|d| *d > 0.0)
            .fold(f64::MAX, f64::min)
            .max(1e-12);
        let decay_title = format!(
            "decay, μ = {}, a = {}, ν = {}",
            params.mu, params.a, params.nu
        );
        let mut decay = PanelSpec::new(
            &decay_title,
            "t",
            "distance to the equilibrium",
            (0.0, t_end),
            (floor / 2.0, 2.0 * offset.abs().max(1e-9) * 1.5),
        );
        decay.log_y = true;
        let gaps: Vec<f64> = nus
            .iter()
            .zip(&radii)
            .map(|(_, r)| 1.0 - r.spectral_radius)
            .collect();
        let gap_max = gaps.iter().fold(0.0f64, |m, g| m.max(*g)).max(1e-12);
        let gap_min = gaps.iter().fold(f64::MAX, |m, g| m.min(*g)).max(1e-12);
        let nu_range = (
            nus.iter().fold(f64::MAX, |m, v| m.min(*v)) / 1.3,
            nus.iter().fold(0.0f64, |m, v| m.max(*v)) * 1.3,
        );
        let multiplier_spec = PanelSpec::new(
            "exact system: 1 − spectral radius ρ",
            "ν",
            "1 − ρ",
            nu_range,
            (gap_min / 2.0, gap_max * 2.0),
        )
        .log_log();
        let mut figure = Figure::grid(2, 1, 620, 460, &[decay, multiplier_spec]);
        figure.line(0, &exact_curve, BLUE);
        figure.line(0, &averaged_curve, BLACK);
        figure.line(0, &predicted, GREY);
        figure.legend(
            0,
            &[
                ("exact".into(), BLUE),
                ("limit".into(), BLACK),
                ("exp(max Re λ · t)".into(), GREY),
            ],
        );
        let exact_gap: Vec<(f64, f64)> = nus.iter().copied().zip(gaps.iter().copied()).collect();
        let predicted_gap: Vec<(f64, f64)> = nus
            .iter()
            .map(|nu| (*nu, 1.0 - (max_re * 2.0 * PI / nu).exp()))
            .collect();
        figure.line(1, &exact_gap, BLUE);
        figure.points(1, exact_gap.iter().copied(), BLUE, 7);
        figure.line(1, &predicted_gap, GREY);
        figure.legend(
            1,
            &[
                ("exact (Floquet)".into(), BLUE),
                ("from the averaged eigenvalues".into(), GREY),
            ],
        );
        scene.save_figure(&figure, "friction.png")?;
        scene.write_csv(
            "multipliers.csv",
            &["nu", "spectral_radius", "predicted"],
            rows,
        )?;
        scene.write_csv(
            "decay.csv",
            &["t", "distance_exact", "distance_limit"],
            exact_curve
                .iter()
                .zip(&averaged_curve)
                .map(|(e, a)| (e.0, e.1, a.1)),
        )?;
        if !max_re.is_finite() {
            return Err(SceneError::Numerical("no eigenvalues".into()));
        }
        scene.write_summary(&Summary {
            equilibrium: [phi.0, phi.1],
            mu: params.mu,
            a: params.a,
            nu: params.nu,
            averaged_eigenvalues: eigenvalues.iter().map(|(re, im)| [*re, *im]).collect(),
            max_real_part: max_re,
            exact: radii,
        })?;
        Ok(())
    });
}
