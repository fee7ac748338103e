//! Scene `kapitza_stability` (deliverables 1.5, 1.6): is the upper position
//! q = 0 of the pendulum with a vibrating pivot stable?
//!
//! q = 0, p = 0 is a T-periodic solution of the exact system for every A.
//! Its stability follows from the Floquet multipliers of the period map's
//! linearisation (the monodromy matrix M); the critical amplitude A* is the
//! lower edge of the stable window (generic `stability` analysis), the
//! averaged system predicts A* = √2 (V = cos q + A²/4 sin²q has V''(0) =
//! A²/2 − 1). Also: orbits near q = 0 either side of A*, the averaged
//! portraits, the (ε, A) stability chart with its boundaries located by
//! bisection, and A*(ε) against √2.

use mechlab::models::kapitza::{Params, INFO};
use mechlab::ode::Method;
use mechlab::scene::{knob, parameter_knobs, run, Scene};
use mechlab::studies::kapitza::{upper_position, UpperPositionSettings};

fn main() {
    run(|| {
        let mut knobs = vec![
            knob(
                "tol",
                "1e-12",
                "DOP853 tolerance of every run (monodromy matrices, orbits, chart)",
            ),
            knob("periods", "2000", "periods per orbit near q = 0"),
            knob("chart_eps", "40", "chart resolution in ε (0.02..0.5)"),
            knob("chart_a", "120", "chart resolution in A (0..A_max)"),
            knob("chart_a_max", "12", "largest A of the chart"),
        ];
        knobs.extend(parameter_knobs(&INFO, &[("A", "1.6")]));
        let scene = Scene::from_args(
            "kapitza_stability",
            "stability of the upper position; critical amplitude A*; stability chart",
            &knobs,
        )?;
        let result = upper_position(&UpperPositionSettings {
            params: Params::from_values(&scene.parameter_values(&INFO)?),
            periods: scene.count("periods")?,
            chart_eps: scene.count("chart_eps")?,
            chart_a: scene.count("chart_a")?,
            chart_a_max: scene.positive("chart_a_max")?,
            method: Method::parse("dop853", scene.positive("tol")?)?,
        })?;
        println!(
            "ε = {}, μ = {}: A* = {:?} (averaged: √2, to second order: {:?}); at A = {}: multipliers {:?}, det M = {} (exp(−μT) = {}): {}",
            result.eps, result.mu, result.a_star, result.a_star_second_order, result.A, result.multipliers,
            result.determinant, result.determinant_expected, result.verdict
        );
        for s in &result.a_star_by_eps {
            println!(
                "ε = {}: A* = {:?}, second order {:?}",
                s.eps, s.a_star, s.a_star_second_order
            );
        }
        scene.save_figure(&result.orbits_figure(), "orbits_near_upper_position.png")?;
        let header = ["A", "mu", "orbit", "period", "q", "p"];
        scene.write_csv(
            "orbits_near_upper_position.csv",
            &header,
            result.orbit_rows(),
        )?;
        scene.save_figure(&result.averaged_figure(), "averaged_portraits.png")?;
        scene.save_figure(&result.chart_figure(), "stability_chart.png")?;
        scene.write_csv(
            "stability_chart.csv",
            &["eps", "A_boundary"],
            result.chart_rows(),
        )?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
