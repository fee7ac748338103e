//! Scene `kapitza_stability` (deliverables 1.5, 1.6): is the upper position
//! q = 0 of the pendulum with a vibrating pivot stable?
//!
//! q = 0, p = 0 is a T-periodic solution of the exact system for every A.
//! Its stability follows from the Floquet multipliers of the linearised
//! period map (the monodromy matrix M, from the generated Jacobian). For this
//! 2×2 map the multipliers lie in the closed unit disc iff |tr M| ≤ 1 + det M
//! (det M = exp(−μT) by Liouville); the critical amplitude A* is the root of
//! |tr M| − 1 − det M, bracketed on a scan and bisected to 1e-10. The
//! averaged system predicts A* = √2 (V = cos q + A²/4 sin²q has V''(0) = A²/2 − 1).

use mechlab::analysis::floquet::{floquet_multipliers, monodromy, Verdict};
use mechlab::analysis::period_map::orbit;
use mechlab::analysis::stability::{stability, stability_chart, ChartSettings, Settings};
use mechlab::models::kapitza;
use mechlab::ode::{Integrator, Method};
use mechlab::plot::{palette, Figure, PanelSpec, BLUE, RED};
use mechlab::scene::{knob, run, Scene, SceneError};
use rayon::prelude::*;
use std::f64::consts::{PI, SQRT_2};

const KNOBS: &[mechlab::scene::Knob] = &[
    knob("A", "1.6", "pivot amplitude to judge"),
    knob("eps", "0.1", "ε: forcing period / 2π"),
    knob("mu", "0", "viscous friction"),
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

/// The monodromy matrix of the upper position over one period.
fn upper_monodromy(a: f64, eps: f64, mu: f64, method: Method) -> Result<[[f64; 2]; 2], SceneError> {
    let params = kapitza::Params { A: a, eps, mu };
    let mut integrator = Integrator::new(method)?;
    let y0 = [0.0, 0.0];
    let (_, m) = monodromy::<_, 2, 6>(
        &mut integrator,
        &kapitza::Exact { params },
        2.0 * PI * eps,
        &y0,
    )?;
    Ok(m)
}

/// The exact A* at which the upper position becomes stable (the lower
/// edge of its window in (0, 4], from the generic `stability`), or None.
fn critical_amplitude(eps: f64, mu: f64, method: Method) -> Result<Option<f64>, SceneError> {
    let settings = Settings {
        amplitude: "A".into(),
        a_max: Some(4.0),
        samples: 400,
        edge_tolerance: 1e-10,
        method,
    };
    let params = kapitza::Params { A: SQRT_2, eps, mu };
    let result = stability("kapitza", &params.values(), &settings)?;
    let upper = result.equilibria.iter().find(|e| e.q[0].abs() < 1e-9);
    Ok(upper.and_then(|e| e.exact_window).and_then(|[low, _]| low))
}

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "kapitza_stability",
            "stability of the upper position; critical amplitude A*; stability chart",
            KNOBS,
        )?;
        let (a, eps, mu) = (
            scene.non_negative("A")?,
            scene.positive("eps")?,
            scene.non_negative("mu")?,
        );
        let method = Method::parse("dop853", scene.positive("tol")?)?;
        let period = 2.0 * PI * eps;

        let a_star = critical_amplitude(eps, mu, method)?;
        let m = upper_monodromy(a, eps, mu, method)?;
        let multipliers = floquet_multipliers(&m);
        let verdict = Verdict::from_multipliers(&multipliers, 1e-7);
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        println!("ε = {eps}, μ = {mu}: A* = {a_star:?} (averaged: √2 = {SQRT_2})");
        println!(
            "A = {a}: multipliers {multipliers:?}, det M = {det} (exp(−μT) = {}): {}",
            (-mu * period).exp(),
            verdict.name()
        );

        // Orbits near q = 0 below and above A*, and with friction above A*.
        let a_ref = a_star.unwrap_or(SQRT_2);
        let cases = [
            (a_ref - 0.15, mu, "below A*"),
            (a_ref + 0.15, mu, "above A*"),
            (a_ref + 0.15, mu.max(0.1), "above A*, with friction"),
        ];
        let periods = scene.count("periods")?;
        let starts = [[0.05, 0.0], [0.15, 0.0], [0.3, 0.0], [0.0, 0.25]];
        let titles: Vec<String> = cases
            .iter()
            .map(|(ca, cmu, label)| format!("{label}: A = {ca:.3}, μ = {cmu}"))
            .collect();
        let specs: Vec<PanelSpec> = titles
            .iter()
            .map(|t| PanelSpec::new(t, "q", "p", (-1.0, 1.0), (-1.0, 1.0)))
            .collect();
        let mut figure = Figure::grid(3, 1, 460, 460, &specs);
        let mut rows = Vec::new();
        for (k, (ca, cmu, _)) in cases.iter().enumerate() {
            let system = kapitza::Exact {
                params: kapitza::Params {
                    A: *ca,
                    eps,
                    mu: *cmu,
                },
            };
            for (s, y0) in starts.iter().enumerate() {
                let mut integrator = Integrator::new(method)?;
                let points = orbit(
                    &mut integrator,
                    &system,
                    period,
                    y0,
                    periods,
                    &kapitza::PERIODIC_STATE,
                )?;
                figure.points(
                    k,
                    points.iter().map(|y| (y[0], y[1])),
                    palette(s),
                    if *cmu > 0.0 { 2 } else { 1 },
                );
                rows.extend(
                    points
                        .iter()
                        .enumerate()
                        .map(|(n, y)| (*ca, *cmu, s, n, y[0], y[1])),
                );
            }
        }
        scene.save_figure(&figure, "orbits_near_upper_position.png")?;
        scene.write_csv(
            "orbits_near_upper_position.csv",
            &["A", "mu", "orbit", "period", "q", "p"],
            rows,
        )?;

        // Averaged phase portraits just below and above √2: level sets of H̄.
        let averaged_cases = [SQRT_2 - 0.3, SQRT_2 + 0.3];
        let titles: Vec<String> = averaged_cases
            .iter()
            .map(|ca| format!("levels of the averaged Hamiltonian, A = {ca:.3}"))
            .collect();
        let specs: Vec<PanelSpec> = titles
            .iter()
            .map(|t| PanelSpec::new(t, "q", "p", (-PI, PI), (-2.5, 2.5)))
            .collect();
        let mut figure = Figure::grid(2, 1, 560, 460, &specs);
        for (k, ca) in averaged_cases.iter().enumerate() {
            let params = kapitza::Params {
                A: *ca,
                eps,
                mu: 0.0,
            };
            let h_top = kapitza::averaged_hamiltonian(&[0.0, 0.0], &params);
            figure.contours(
                k,
                &|q, p| kapitza::averaged_hamiltonian(&[q, p], &params),
                0.15,
                BLUE,
                h_top,
                RED,
            );
        }
        scene.save_figure(&figure, "averaged_portraits.png")?;

        // Stability chart in the (ε, A) plane: the boundaries located by
        // bisection (the generic chart of `stability`).
        let (ne, na) = (scene.count("chart_eps")?, scene.count("chart_a")?);
        let chart_settings = ChartSettings {
            q: vec![0.0],
            x: "eps".into(),
            x_values: (0..ne)
                .map(|i| 0.02 + 0.48 * i as f64 / (ne - 1).max(1) as f64)
                .collect(),
            y: "A".into(),
            y_max: scene.positive("chart_a_max")?,
            y_samples: na,
            edge_tolerance: 1e-6,
            method,
        };
        let params = kapitza::Params { A: a, eps, mu };
        let chart = stability_chart("kapitza", &params.values(), &chart_settings)?;
        let mut figure = chart.figure();
        figure.line(0, &[(0.02, SQRT_2), (0.5, SQRT_2)], RED);
        figure.legend(
            0,
            &[
                ("averaged A* = √2".into(), RED),
                ("exact boundaries".into(), BLUE),
            ],
        );
        scene.save_figure(&figure, "stability_chart.png")?;
        let rows = chart
            .boundaries
            .iter()
            .zip(&chart.x_values)
            .flat_map(|(edges, e)| edges.iter().map(move |a| (*e, *a)));
        scene.write_csv("stability_chart.csv", &["eps", "A_boundary"], rows)?;

        // A*(ε) against √2.
        let eps_list = [0.02, 0.05, 0.1, 0.15, 0.2, 0.3];
        let a_star_by_eps: Vec<(f64, Option<f64>)> = eps_list
            .par_iter()
            .map(|&e| critical_amplitude(e, 0.0, method).map(|s| (e, s)))
            .collect::<Result<_, _>>()?;
        for (e, s) in &a_star_by_eps {
            println!("ε = {e}: A* = {s:?}, A* − √2 = {:?}", s.map(|x| x - SQRT_2));
        }
        #[derive(serde::Serialize)]
        struct AStar {
            eps: f64,
            a_star: Option<f64>,
        }
        #[allow(non_snake_case)]
        #[derive(serde::Serialize)]
        struct Summary {
            eps: f64,
            mu: f64,
            A: f64,
            a_star: Option<f64>,
            a_star_averaged: f64,
            multipliers: Vec<[f64; 2]>,
            determinant: f64,
            determinant_expected: f64,
            verdict: &'static str,
            a_star_by_eps: Vec<AStar>,
        }
        scene.write_summary(&Summary {
            eps,
            mu,
            A: a,
            a_star,
            a_star_averaged: SQRT_2,
            multipliers: multipliers.iter().map(|(re, im)| [*re, *im]).collect(),
            determinant: det,
            determinant_expected: (-mu * period).exp(),
            verdict: verdict.name(),
            a_star_by_eps: a_star_by_eps
                .iter()
                .map(|&(eps, a_star)| AStar { eps, a_star })
                .collect(),
        })?;
        Ok(())
    });
}
