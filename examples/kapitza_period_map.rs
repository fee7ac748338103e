//! Scene `kapitza_period_map` (deliverables 1.2–1.4): orbits of the period map
//! of the pendulum with a vibrating pivot on the unrolled cylinder
//! (q mod 2π, p). Without q0/p0 it draws the portraits of three presets
//! (A = 0: the ordinary pendulum; small A: chaos near the separatrices;
//! larger A: a wide chaotic sea) or of the given A; with q0 and p0 it
//! computes one orbit and reports its final state and cost.

use mechlab::analysis::period_map::{orbit, orbits};
use mechlab::models::kapitza;
use mechlab::ode::{Integrator, Method};
use mechlab::plot::{palette, Figure, PanelSpec};
use mechlab::scene::{knob, run, Scene, SceneError};
use std::f64::consts::PI;

const KNOBS: &[mechlab::scene::Knob] = &[
    knob(
        "A",
        "presets",
        "pivot amplitude; 'presets' draws A = 0, 0.2 and 1.0",
    ),
    knob("eps", "0.1", "ε: forcing period / 2π"),
    knob("mu", "0", "viscous friction"),
    knob(
        "orbits",
        "24",
        "number of initial conditions (portrait mode)",
    ),
    knob("periods", "3000", "periods per orbit"),
    knob(
        "method",
        "dop853",
        "integrator: dop853, taylor, rk4, gauss4, gauss6, radau5",
    ),
    knob(
        "tol",
        "1e-10",
        "tolerance (dop853, taylor, radau5) or step size (rk4, gauss*)",
    ),
    knob("q0", "", "single-orbit mode: initial q"),
    knob(
        "repeat",
        "1",
        "single-orbit mode: timed runs (the fastest is reported)",
    ),
    knob("p0", "", "single-orbit mode: initial p"),
];

/// Initial conditions: a spread through the lower position q = π, plus points near the separatrix.
fn initial_conditions(count: usize) -> Vec<[f64; 2]> {
    let near = [[PI, 1.98], [PI, 2.02], [0.05, 0.0], [PI, -1.98]];
    let spread = count.saturating_sub(near.len()).max(1);
    let mut points: Vec<[f64; 2]> = (0..spread)
        .map(|i| [PI - 1e-9, 0.1 + 2.9 * i as f64 / (spread - 1).max(1) as f64])
        .collect();
    points.extend(near.iter().take(count.saturating_sub(spread)));
    points
}

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "kapitza_period_map",
            "orbits of the period map of the Kapitza pendulum",
            KNOBS,
        )?;
        let eps = scene.positive("eps")?;
        let mu = scene.non_negative("mu")?;
        let periods = scene.count("periods")?;
        let method = Method::parse(scene.text("method"), scene.number("tol")?)?;
        let amplitudes: Vec<f64> = match scene.text("A") {
            "presets" => vec![0.0, 0.2, 1.0],
            _ => vec![scene.number("A")?],
        };
        let period = 2.0 * PI * eps;

        if !scene.text("q0").is_empty() || !scene.text("p0").is_empty() {
            // Single-orbit mode.
            let y0 = [scene.number("q0")?, scene.number("p0")?];
            let params = kapitza::Params {
                A: amplitudes[0],
                eps,
                mu,
            };
            let mut seconds = f64::INFINITY;
            let (mut points, mut stats) = (Vec::new(), Default::default());
            for _ in 0..scene.count("repeat")? {
                let mut integrator = Integrator::new(method)?;
                let start = std::time::Instant::now();
                points = orbit(
                    &mut integrator,
                    &kapitza::Exact { params },
                    period,
                    &y0,
                    periods,
                    &kapitza::PERIODIC_STATE,
                )?;
                seconds = seconds.min(start.elapsed().as_secs_f64());
                stats = integrator.stats;
            }
            let last = points[points.len() - 1];
            scene.write_csv(
                "orbit.csv",
                &["period", "q", "p"],
                points.iter().enumerate().map(|(k, y)| (k, y[0], y[1])),
            )?;
            let mut figure = Figure::single(
                800,
                600,
                PanelSpec::new(
                    &format!("A = {}, ε = {eps}, μ = {mu}", params.A),
                    "q",
                    "p",
                    (-PI, PI),
                    range_p(&points),
                ),
            );
            figure.points(0, points.iter().map(|y| (y[0], y[1])), palette(0), 1);
            scene.save_figure(&figure, "orbit.png")?;
            #[derive(serde::Serialize)]
            struct Orbit {
                final_state: [f64; 2],
                periods: usize,
                method: &'static str,
                tol: f64,
                seconds: f64,
                f_evals: u64,
                steps: u64,
                rejected: u64,
                /// Taylor method: its order (0 for the others).
                order: u64,
            }
            scene.write_summary(&Orbit {
                final_state: last,
                periods,
                method: method.name(),
                tol: scene.number("tol")?,
                seconds,
                f_evals: stats.f_evals,
                steps: stats.steps,
                rejected: stats.rejected,
                order: stats.order,
            })?;
            return Ok(());
        }

        let initial = initial_conditions(scene.count("orbits")?);
        let mut summary = Vec::new();
        for &a in &amplitudes {
            let params = kapitza::Params { A: a, eps, mu };
            eprintln!("A = {a}: {} orbits × {periods} periods", initial.len());
            let start = std::time::Instant::now();
            let results = orbits(
                method,
                &kapitza::Exact { params },
                period,
                &initial,
                periods,
                &kapitza::PERIODIC_STATE,
            );
            let seconds = start.elapsed().as_secs_f64();
            let mut figure = Figure::single(
                900,
                700,
                PanelSpec::new(
                    &format!(
                        "Kapitza period map, A = {a}, ε = {eps}, μ = {mu} ({periods} periods)"
                    ),
                    "q (0 = upward)",
                    "p",
                    (-PI, PI),
                    (-3.6, 3.6),
                ),
            );
            let mut rows = Vec::new();
            let mut f_evals = 0;
            for (k, result) in results.into_iter().enumerate() {
                let (points, stats) = result.map_err(|e| {
                    SceneError::Numerical(format!("orbit {k} from {:?}: {e}", initial[k]))
                })?;
                f_evals += stats.f_evals;
                figure.points(0, points.iter().map(|y| (y[0], y[1])), palette(k), 1);
                rows.extend(points.iter().enumerate().map(|(n, y)| (k, n, y[0], y[1])));
            }
            figure.legend(
                0,
                &[
                    (format!("A = {a}, ε = {eps}, μ = {mu}"), palette(0)),
                    (
                        format!("{} orbits, {}", initial.len(), method.name()),
                        palette(1),
                    ),
                ],
            );
            let tag = format!("A{a}");
            scene.save_figure(&figure, &format!("portrait_{tag}.png"))?;
            scene.write_csv(
                &format!("orbits_{tag}.csv"),
                &["orbit", "period", "q", "p"],
                rows,
            )?;
            summary.push(Portrait {
                A: a,
                orbits: initial.len(),
                periods,
                seconds,
                f_evals,
            });
        }
        #[derive(serde::Serialize)]
        struct Summary {
            eps: f64,
            mu: f64,
            method: &'static str,
            portraits: Vec<Portrait>,
        }
        scene.write_summary(&Summary {
            eps,
            mu,
            method: method.name(),
            portraits: summary,
        })?;
        Ok(())
    });
}

/// One portrait of the presets.
#[allow(non_snake_case)]
#[derive(serde::Serialize)]
struct Portrait {
    A: f64,
    orbits: usize,
    periods: usize,
    seconds: f64,
    f_evals: u64,
}

fn range_p(points: &[[f64; 2]]) -> (f64, f64) {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
            (lo.min(y[1]), hi.max(y[1]))
        });
    let pad = 0.05 * (hi - lo).max(1e-3);
    (lo - pad, hi + pad)
}
