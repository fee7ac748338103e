//! Scene `kapitza_attractor` (deliverable 1.7): a strange attractor of the
//! dissipative period map of the pendulum with a vibrating pivot. With
//! friction μ > 0 the map contracts areas by exp(−μT) per period, so orbits
//! settle on an attractor; at the default parameters (found by a scan of
//! (ε, A, μ) for a positive largest Lyapunov exponent, see the README) it is
//! a folded, layered set like the Hénon attractor. Draws the attractor after
//! transients, a zoom on its layers, the box-counting plot, and reports the
//! Lyapunov exponents (their sum is −μT) and the box-counting dimension.

use mechlab::analysis::dimension::{bounds, box_counting, kaplan_yorke_dimension};
use mechlab::analysis::lyapunov::lyapunov_spectrum;
use mechlab::analysis::period_map::orbit;
use mechlab::models::kapitza;
use mechlab::ode::{Integrator, Method};
use mechlab::plot::{Figure, PanelSpec, BLACK, BLUE, RED};
use mechlab::scene::{knob, run, Scene};
use std::f64::consts::PI;

/// The centre of the most populated cell of a coarse grid: where the zoom
/// shows the most layers.
fn densest_cell(points: &[[f64; 2]], cells: usize) -> [f64; 2] {
    let (lo, hi) = bounds(points);
    let mut counts = vec![0usize; cells * cells];
    let index = |p: &[f64; 2], d: usize| {
        (((p[d] - lo[d]) / (hi[d] - lo[d]) * cells as f64) as usize).min(cells - 1)
    };
    for p in points {
        counts[index(p, 1) * cells + index(p, 0)] += 1;
    }
    let best = (0..counts.len()).max_by_key(|&k| counts[k]).unwrap();
    let (i, j) = (best % cells, best / cells);
    [
        lo[0] + (i as f64 + 0.5) * (hi[0] - lo[0]) / cells as f64,
        lo[1] + (j as f64 + 0.5) * (hi[1] - lo[1]) / cells as f64,
    ]
}

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "kapitza_attractor",
            "strange attractor of the dissipative Kapitza period map",
            &[
                knob("A", "1.5", "pivot amplitude"),
                knob("eps", "0.7", "ε: forcing period / 2π"),
                knob("mu", "0.4", "viscous friction"),
                knob("points", "100000", "points of the attractor"),
                knob("transient", "1000", "periods dropped first"),
                knob(
                    "lyapunov_periods",
                    "20000",
                    "periods for the Lyapunov exponents",
                ),
                knob(
                    "method",
                    "dop853",
                    "integrator (rk4, dop853, taylor, gauss4, gauss6, radau5)",
                ),
                knob("tol", "1e-9", "tolerance (dop853, radau5) or step size"),
                knob(
                    "zoom",
                    "8",
                    "the zoom shows 1/zoom of the attractor's extent",
                ),
            ],
        )?;
        let params = kapitza::Params {
            A: scene.non_negative("A")?,
            eps: scene.positive("eps")?,
            mu: scene.positive("mu")?,
        };
        let (count, transient) = (scene.count("points")?, scene.count("transient")?);
        let method = Method::parse(scene.text("method"), scene.number("tol")?)?;
        let zoom = scene.positive("zoom")?;
        let system = kapitza::Exact { params };
        let period = 2.0 * PI * params.eps;
        let wrap = [true, false];
        let y0 = [1.0, 0.3];

        // The attractor: the orbit after the transient.
        let mut integrator = Integrator::new(method)?;
        let start = std::time::Instant::now();
        let settled = *orbit(&mut integrator, &system, period, &y0, transient, &wrap)?
            .last()
            .unwrap();
        let points = orbit(&mut integrator, &system, period, &settled, count, &wrap)?;
        eprintln!("{count} points in {:.1} s", start.elapsed().as_secs_f64());

        // Lyapunov exponents per period; their sum is fixed by the friction.
        let mut integrator = Integrator::new(method)?;
        let (lyapunov, _) = lyapunov_spectrum::<_, 2, 6>(
            &mut integrator,
            &system,
            period,
            &settled,
            0,
            scene.count("lyapunov_periods")?,
            &wrap,
        )?;
        let expected_sum = -params.mu * period;
        let kaplan_yorke = kaplan_yorke_dimension(&lyapunov);

        // Box counting over box sides 1/4 … 1/256 of the extent; the fit
        // leaves out the coarsest and the finest, which 10⁵ points cannot fill.
        let sides: Vec<f64> = (2..=8).map(|k| 0.5f64.powi(k)).collect();
        let counted = box_counting(&points, &sides, 1..sides.len() - 1);
        let (dimension, intercept) = (counted.dimension, counted.intercept);
        let log_points: Vec<(f64, f64)> = sides
            .iter()
            .zip(&counted.boxes)
            .map(|(s, n)| ((1.0 / s).ln(), (*n as f64).ln()))
            .collect();

        // Pictures: the attractor with the zoom window, the zoom, the box counts.
        let (lo, hi) = bounds(&points);
        let centre = densest_cell(&points, 8);
        let half = [0.5 * (hi[0] - lo[0]) / zoom, 0.5 * (hi[1] - lo[1]) / zoom];
        let window = (
            (centre[0] - half[0], centre[0] + half[0]),
            (centre[1] - half[1], centre[1] + half[1]),
        );
        let title = format!(
            "attractor, A = {}, ε = {}, μ = {}, {count} points",
            params.A, params.eps, params.mu
        );
        let zoom_title = format!("zoom ×{zoom}: layers");
        let pad = 0.05 * (hi[1] - lo[1]);
        let mut figure = Figure::grid(
            2,
            1,
            700,
            700,
            &[
                PanelSpec::new(&title, "q", "p", (-PI, PI), (lo[1] - pad, hi[1] + pad)),
                PanelSpec::new(&zoom_title, "q", "p", window.0, window.1),
            ],
        );
        let xy: Vec<(f64, f64)> = points.iter().map(|p| (p[0], p[1])).collect();
        figure.points(0, xy.iter().copied(), BLACK, 1);
        figure.points(1, xy.iter().copied(), BLACK, 2);
        let (q0, q1) = window.0;
        let (p0, p1) = window.1;
        figure.line(0, &[(q0, p0), (q1, p0), (q1, p1), (q0, p1), (q0, p0)], RED);
        scene.save_figure(&figure, "attractor.png")?;

        let fit_title = format!("box counting: dimension {dimension:.3}");
        let (x_lo, x_hi) = (log_points[0].0 - 0.3, log_points.last().unwrap().0 + 0.3);
        let y_lo = log_points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min) - 0.5;
        let y_hi = log_points
            .iter()
            .map(|p| p.1)
            .fold(f64::NEG_INFINITY, f64::max)
            + 0.5;
        let mut boxes = Figure::single(
            640,
            480,
            PanelSpec::new(
                &fit_title,
                "ln(1/box side)",
                "ln(boxes)",
                (x_lo, x_hi),
                (y_lo, y_hi),
            ),
        );
        boxes.points(0, log_points.iter().copied(), BLUE, 6);
        boxes.line(
            0,
            &[
                (x_lo, intercept + dimension * x_lo),
                (x_hi, intercept + dimension * x_hi),
            ],
            RED,
        );
        scene.save_figure(&boxes, "box_counting.png")?;

        scene.write_csv(
            "attractor.csv",
            &["q", "p"],
            points.iter().map(|p| (p[0], p[1])),
        )?;
        scene.write_csv(
            "box_counting.csv",
            &["box_side", "boxes"],
            sides.iter().zip(&counted.boxes),
        )?;
        println!(
            "lyapunov exponents per period {:.4} {:.4}, sum {:.4} (expected -mu T = {expected_sum:.4}), box-counting dimension {dimension:.3}, Kaplan-Yorke {kaplan_yorke:.3}",
            lyapunov[0], lyapunov[1], lyapunov[0] + lyapunov[1]
        );
        if lyapunov[0] <= 0.0 {
            eprintln!("note: the largest exponent is not positive: at these parameters the attractor is not chaotic");
        }
        #[derive(serde::Serialize)]
        struct Window {
            q: [f64; 2],
            p: [f64; 2],
        }
        #[allow(non_snake_case)]
        #[derive(serde::Serialize)]
        struct Summary {
            A: f64,
            eps: f64,
            mu: f64,
            lyapunov: Vec<f64>,
            lyapunov_sum_expected: f64,
            lyapunov_sum: f64,
            dimension: f64,
            kaplan_yorke_dimension: f64,
            points: usize,
            zoom_window: Window,
        }
        scene.write_summary(&Summary {
            A: params.A,
            eps: params.eps,
            mu: params.mu,
            lyapunov_sum_expected: expected_sum,
            lyapunov_sum: lyapunov[0] + lyapunov[1],
            lyapunov,
            dimension,
            kaplan_yorke_dimension: kaplan_yorke,
            points: count,
            zoom_window: Window {
                q: [q0, q1],
                p: [p0, p1],
            },
        })?;
        Ok(())
    });
}
