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

use mechlab::analysis::vibrational_stability::Stabilization;
use mechlab::models::double_pendulum::{Averaged, Params};
use mechlab::ode::{Integrator, Method};
use mechlab::plot::{Figure, PanelSpec, BLACK, BLUE, GREY, RED};
use mechlab::scene::{knob, run, Progress, Scene, SceneError};
use mechlab::studies::double_pendulum::{
    analyse_equilibrium, exact_multipliers, exact_stability_window, parameter_knobs,
    params_from_scene, threshold_formula, EQUILIBRIA,
};
use rayon::prelude::*;

/// What the summary says of one equilibrium (null where not applicable).
#[derive(serde::Serialize)]
struct EquilibriumEntry {
    phi1: f64,
    phi2: f64,
    lambdas: [f64; 2],
    stable_without_vibration: bool,
    a_star: Option<f64>,
    a_star_formula: Option<String>,
    a_star_formula_latex: Option<String>,
    /// [lower edge, upper edge or null] of the exact system at ν.
    exact_window: Option<(f64, Option<f64>)>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<&'static str>,
}

/// What the figure shows of one unstable equilibrium.
struct Panels {
    /// φ − φ_eq against t, per coordinate, slightly above and below a*.
    above: Vec<Vec<(f64, f64)>>,
    below: Vec<Vec<(f64, f64)>>,
    /// (a, spectral radius of the exact monodromy matrix).
    chart: Vec<(f64, f64)>,
    a_star: f64,
}

/// A long run of the limiting system at amplitude `a` from `y0`: the
/// coordinates' distances from the equilibrium against t.
fn limiting_run(
    method: Method,
    params: &Params,
    a: f64,
    phi: (f64, f64),
    y0: &[f64; 4],
    t_long: f64,
) -> Result<Vec<Vec<(f64, f64)>>, SceneError> {
    let system = Averaged {
        params: Params { a, ..*params },
    };
    let grid: Vec<f64> = (0..=3000).map(|i| t_long * i as f64 / 3000.0).collect();
    let states = Integrator::new(method)?.advance_sampled(&system, 0.0, y0, &grid)?;
    Ok([phi.0, phi.1]
        .iter()
        .enumerate()
        .map(|(i, eq)| {
            states
                .iter()
                .zip(&grid)
                .map(|(y, t)| (*t, y[i] - eq))
                .collect()
        })
        .collect())
}

/// The exact system's spectral radius at the equilibrium for `points`
/// amplitudes in (0, a_max], in parallel.
fn spectral_radius_chart(
    params: &Params,
    phi: (f64, f64),
    a_max: f64,
    points: usize,
    tol: f64,
) -> Result<Vec<(f64, f64)>, SceneError> {
    Ok((1..=points)
        .into_par_iter()
        .map(|i| {
            let a = a_max * i as f64 / points as f64;
            exact_multipliers(&Params { a, ..*params }, phi, tol).map(|(r, _)| (a, r))
        })
        .collect::<Result<_, _>>()?)
}

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
            knob("method", "dop853", "integration method of the long runs"),
            knob(
                "tol",
                "1e-10",
                "tolerance (long runs and monodromy matrices)",
            ),
        ]);
        let scene = Scene::from_args(
            "double_pendulum_stabilization",
            "equilibria, criterion (11), a*, long runs of the limiting system, the exact stability window",
            &knobs,
        )?;
        let params = params_from_scene(&scene)?;
        let offset = scene.number("offset")?;
        let t_long = scene.positive("t_long")?;
        let margin = scene.positive("margin")?;
        let factor = scene.positive("a_max_factor")?;
        let chart_points = scene.count("chart_points")?;
        let tol = scene.positive("tol")?;
        let method = Method::parse(scene.text("method"), tol)?;

        let mut entries = Vec::new();
        let mut titles = Vec::new();
        let mut panels: Vec<Panels> = Vec::new();
        let progress = Progress::new("equilibria", EQUILIBRIA.len());
        for (k, phi) in EQUILIBRIA.iter().enumerate() {
            let analysis = analyse_equilibrium(&params, *phi);
            let formula = threshold_formula(*phi);
            let name = format!(
                "({}, {})",
                if phi.0 == 0.0 { "0" } else { "π" },
                if phi.1 == 0.0 { "0" } else { "π" }
            );
            println!(
                "equilibrium {name}: λ = {:?}, stable without vibration: {}",
                analysis.lambdas, analysis.stable_without_vibration
            );
            let mut entry = EquilibriumEntry {
                phi1: phi.0,
                phi2: phi.1,
                lambdas: analysis.lambdas,
                stable_without_vibration: analysis.stable_without_vibration,
                a_star: None,
                a_star_formula: None,
                a_star_formula_latex: None,
                exact_window: None,
                reason: None,
            };
            match analysis.stabilization {
                Stabilization::AlreadyStable => println!("  stable for every a (all λ > 0)"),
                Stabilization::Degenerate => {
                    println!("  not decided: a root λ is zero (degenerate equilibrium)");
                    entry.reason =
                        Some("a root of det(C − λA) is zero: the criterion does not apply");
                }
                Stabilization::Threshold {
                    lambda_star,
                    a_star,
                } => {
                    let (text, latex) = formula.expect("unstable equilibria have a formula");
                    let a_max = factor * a_star;
                    let window = exact_stability_window(&params, *phi, a_max, 240, tol)?;
                    println!("  λ* = {lambda_star:.6}, a* = {a_star:.6}: {text}");
                    println!(
                        "  exact system at ν = {}: stable for a in {window:?}",
                        params.nu
                    );
                    entry.a_star = Some(a_star);
                    entry.a_star_formula = Some(text);
                    entry.a_star_formula_latex = Some(latex);
                    entry.exact_window = window;
                    let y0 = [phi.0 + offset, phi.1 - offset, 0.0, 0.0];
                    let above =
                        limiting_run(method, &params, (1.0 + margin) * a_star, *phi, &y0, t_long)?;
                    let below =
                        limiting_run(method, &params, (1.0 - margin) * a_star, *phi, &y0, t_long)?;
                    let chart = spectral_radius_chart(&params, *phi, a_max, chart_points, tol)?;
                    titles.push(format!(
                        "{name} limit, a = (1 + {margin}) a* = {:.3}: stays",
                        (1.0 + margin) * a_star
                    ));
                    titles.push(format!(
                        "{name} limit, a = (1 − {margin}) a* = {:.3}: leaves",
                        (1.0 - margin) * a_star
                    ));
                    titles.push(format!("{name} exact, ν = {}: spectral radius", params.nu));
                    panels.push(Panels {
                        above,
                        below,
                        chart,
                        a_star,
                    });
                }
            }
            entries.push(entry);
            progress.update(k + 1);
        }

        let figure = draw(&panels, &titles, offset, t_long);
        let rows: Vec<(usize, f64, f64)> = panels
            .iter()
            .enumerate()
            .flat_map(|(p, panel)| panel.chart.iter().map(move |(a, r)| (p, *a, *r)))
            .collect();
        scene.save_figure(&figure, "stabilization.png")?;
        scene.write_csv(
            "exact_spectral_radius.csv",
            &["panel", "a", "spectral_radius"],
            rows,
        )?;
        #[derive(serde::Serialize)]
        struct Masses {
            m1: f64,
            m2: f64,
            l1: f64,
            l2: f64,
            g: f64,
            mu: f64,
        }
        #[derive(serde::Serialize)]
        struct Summary {
            params: Masses,
            nu: f64,
            mean_h2: f64,
            equilibria: Vec<EquilibriumEntry>,
        }
        scene.write_summary(&Summary {
            params: Masses {
                m1: params.m1,
                m2: params.m2,
                l1: params.l1,
                l2: params.l2,
                g: params.g,
                mu: params.mu,
            },
            nu: params.nu,
            mean_h2: mechlab::studies::double_pendulum::MEAN_H2,
            equilibria: entries,
        })?;
        Ok(())
    });
}

/// Per unstable equilibrium: the limiting runs above and below a*, and the
/// exact spectral radius against a with a* marked.
fn draw(panels: &[Panels], titles: &[String], offset: f64, t_long: f64) -> Figure {
    let mut specs = Vec::new();
    for (
        p,
        Panels {
            above,
            below,
            chart,
            ..
        },
    ) in panels.iter().enumerate()
    {
        let extent = |runs: &Vec<Vec<(f64, f64)>>| {
            runs.iter()
                .flatten()
                .fold(offset.abs(), |m, (_, y)| m.max(y.abs()))
                .min(3.5)
                * 1.1
        };
        let (ea, eb) = (extent(above), extent(below));
        let r_max = chart.iter().fold(1.0f64, |m, (_, r)| m.max(*r)).min(3.0);
        specs.push(PanelSpec::new(
            &titles[3 * p],
            "t",
            "angle − equilibrium",
            (0.0, t_long),
            (-ea, ea),
        ));
        specs.push(PanelSpec::new(
            &titles[3 * p + 1],
            "t",
            "angle − equilibrium",
            (0.0, t_long),
            (-eb, eb),
        ));
        specs.push(PanelSpec::new(
            &titles[3 * p + 2],
            "a",
            "spectral radius ρ",
            (0.0, chart.last().map_or(1.0, |c| c.0)),
            (0.95, r_max * 1.02),
        ));
    }
    let mut figure = Figure::grid(3, panels.len(), 520, 340, &specs);
    for (
        p,
        Panels {
            above,
            below,
            chart,
            a_star,
        },
    ) in panels.iter().enumerate()
    {
        for (i, color) in [(0, BLUE), (1, RED)] {
            figure.line(3 * p, &above[i], color);
            figure.line(3 * p + 1, &below[i], color);
        }
        let top = figure.panel(3 * p + 2).y_range.1;
        figure.line(3 * p + 2, &[(*a_star, 0.95), (*a_star, top)], GREY);
        figure.line(3 * p + 2, chart, BLACK);
        figure.points(3 * p + 2, chart.iter().copied(), BLACK, 3);
        figure.legend(3 * p, &[("φ₁".into(), BLUE), ("φ₂".into(), RED)]);
        figure.legend(
            3 * p + 2,
            &[("exact".into(), BLACK), ("a* (limit)".into(), GREY)],
        );
    }
    figure
}
