//! Scene `double_pendulum_averaging` (deliverable 2.2): Theorem 2 of the
//! averaging method on the double pendulum with a vibrating base.
//!
//! For every amplitude a and every initial state (a grid of cases), the exact
//! system at large ν and the limiting (averaged) system start from the same
//! (q, p); the figure shows φ1, φ2 of both against t, the deviations
//! |exact − limit| (of order 1/ν), and both systems' generalised velocities,
//! which differ by O(1) at the fast time scale: the velocities converge only
//! weakly, not uniformly.

use mechlab::analysis::averaging::{compare, time_grid};
use mechlab::models::double_pendulum::{self as model, Averaged, Exact, Params};
use mechlab::ode::Method;
use mechlab::plot::{Figure, PanelSpec, BLACK, BLUE, RED};
use mechlab::scene::{knob, run, Scene, SceneError};
use mechlab::studies::double_pendulum::{parameter_knobs, params_from_scene};

/// Limits of a set of values, widened a little (and never empty).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

/// One case of the figure: amplitude, start, deviations.
#[derive(Debug, serde::Serialize)]
struct Case {
    a: f64,
    phi0: [f64; 2],
    max_deviation: Vec<f64>,
    nu_times_max_deviation: [f64; 2],
    max_velocity_difference: Vec<f64>,
}

#[derive(serde::Serialize)]
struct Summary {
    nu: f64,
    t_end: f64,
    cases: Vec<Case>,
}

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
            knob("method", "dop853", "integration method"),
            knob("tol", "1e-10", "tolerance (or step for fixed-step methods)"),
        ]);
        let scene = Scene::from_args(
            "double_pendulum_averaging",
            "exact (large ν) against limiting system from the same (q, p): coordinates, deviations, velocities",
            &knobs,
        )?;
        let base = params_from_scene(&scene)?;
        let amplitudes = scene.numbers("amplitudes")?;
        let (phi1, phi2) = (scene.numbers("phi1_starts")?, scene.numbers("phi2_starts")?);
        if phi1.len() != phi2.len() {
            return Err(SceneError::BadValue {
                name: "phi2_starts".into(),
                value: scene.text("phi2_starts").into(),
                reason: format!("needs as many values as phi1_starts ({})", phi1.len()),
            });
        }
        let t_end = scene.positive("t_end")?;
        let method = Method::parse(scene.text("method"), scene.positive("tol")?)?;
        let grid = time_grid(t_end, 2.0 * std::f64::consts::PI / base.nu, 16, 2000);

        let cases: Vec<(f64, [f64; 4])> = amplitudes
            .iter()
            .flat_map(|&a| {
                phi1.iter()
                    .zip(&phi2)
                    .map(move |(&x, &y)| (a, [x, y, 0.0, 0.0]))
            })
            .collect();
        let mut titles = Vec::new();
        for (a, y0) in &cases {
            let case = format!("a = {a}, φ(0) = ({}, {}), same (q, p)", y0[0], y0[1]);
            titles.push(format!("{case}: φ₁, φ₂"));
            titles.push(format!("{case}: |exact − limit|"));
            titles.push(format!("{case}: velocities"));
        }
        let mut rows = Vec::new();
        let mut summary_cases = Vec::new();
        let mut series = Vec::new();
        for (case, (a, y0)) in cases.iter().enumerate() {
            let params = Params { a: *a, ..base };
            let c = compare(method, &Exact { params }, &Averaged { params }, y0, &grid)?;
            let exact_v: Vec<[f64; 2]> = c
                .times
                .iter()
                .zip(&c.exact)
                .map(|(t, y)| model::velocities(*t, y, &params))
                .collect();
            let averaged_v: Vec<[f64; 2]> = c
                .averaged
                .iter()
                .map(|y| {
                    let f = model::averaged_rhs(y, &params);
                    [f[0], f[1]]
                })
                .collect();
            let deviation = c.max_deviation(0..2);
            let velocity_gap: Vec<f64> = (0..2)
                .map(|i| {
                    exact_v
                        .iter()
                        .zip(&averaged_v)
                        .map(|(e, v)| (e[i] - v[i]).abs())
                        .fold(0.0, f64::max)
                })
                .collect();
            summary_cases.push(Case {
                a: *a,
                phi0: [y0[0], y0[1]],
                nu_times_max_deviation: [deviation[0] * params.nu, deviation[1] * params.nu],
                max_deviation: deviation,
                max_velocity_difference: velocity_gap,
            });
            for (k, t) in c.times.iter().enumerate() {
                let (e, v) = (&c.exact[k], &c.averaged[k]);
                rows.push((
                    case,
                    *t,
                    [e[0], e[1], v[0], v[1]],
                    [
                        exact_v[k][0],
                        exact_v[k][1],
                        averaged_v[k][0],
                        averaged_v[k][1],
                    ],
                ));
            }
            series.push((c, exact_v, averaged_v));
        }

        let specs: Vec<PanelSpec> = titles
            .iter()
            .enumerate()
            .map(|(k, title)| {
                let (c, ev, av) = &series[k / 3];
                let values: Box<dyn Iterator<Item = f64>> = match k % 3 {
                    0 => Box::new(c.exact.iter().chain(&c.averaged).flat_map(|y| [y[0], y[1]])),
                    1 => Box::new(
                        c.exact
                            .iter()
                            .zip(&c.averaged)
                            .flat_map(|(e, a)| [(e[0] - a[0]).abs(), (e[1] - a[1]).abs()])
                            .chain([0.0]),
                    ),
                    _ => Box::new(ev.iter().chain(av.iter()).flat_map(|v| [v[0], v[1]])),
                };
                let y_label = ["angle", "deviation", "velocity"][k % 3];
                PanelSpec::new(title, "t", y_label, (0.0, t_end), range(values))
            })
            .collect();
        let mut figure = Figure::grid(3, cases.len(), 560, 300, &specs);
        for (case, (c, ev, av)) in series.iter().enumerate() {
            let curve = |values: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
                c.times
                    .iter()
                    .enumerate()
                    .map(|(k, t)| (*t, values(k)))
                    .collect()
            };
            let base_panel = 3 * case;
            for (i, color) in [(0, BLUE), (1, RED)] {
                figure.line(base_panel, &curve(&|k| c.exact[k][i]), color);
                figure.line(base_panel, &curve(&|k| c.averaged[k][i]), BLACK);
                figure.line(
                    base_panel + 1,
                    &curve(&|k| (c.exact[k][i] - c.averaged[k][i]).abs()),
                    color,
                );
                figure.line(
                    base_panel + 2,
                    &curve(&|k| ev[k][i]),
                    if i == 0 { BLUE } else { RED },
                );
            }
            for component in 0..2 {
                let limit: Vec<(f64, f64)> = c
                    .times
                    .iter()
                    .zip(av)
                    .map(|(t, v)| (*t, v[component]))
                    .collect();
                figure.line(base_panel + 2, &limit, BLACK);
            }
            figure.legend(
                base_panel,
                &[
                    ("exact φ₁".into(), BLUE),
                    ("exact φ₂".into(), RED),
                    ("limit".into(), BLACK),
                ],
            );
            figure.legend(base_panel + 1, &[("φ₁".into(), BLUE), ("φ₂".into(), RED)]);
            figure.legend(
                base_panel + 2,
                &[
                    ("exact φ₁′".into(), BLUE),
                    ("exact φ₂′".into(), RED),
                    ("limit".into(), BLACK),
                ],
            );
        }
        scene.save_figure(&figure, "averaging.png")?;
        scene.write_csv(
            "series.csv",
            &[
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
            ],
            rows,
        )?;
        for s in &summary_cases {
            println!("{s:?}");
        }
        scene.write_summary(&Summary {
            nu: base.nu,
            t_end,
            cases: summary_cases,
        })?;
        Ok(())
    });
}
