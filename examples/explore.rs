//! Scene `explore`: any model of `models/`, by name. It integrates the exact
//! system (and the averaged one if the model has a fast phase; the
//! stick–slip integrator for a contact model) with the chosen method and
//! tolerance, and draws the time series and phase portraits per degree of
//! freedom, the period map, exact against averaged, and the energy change;
//! the equilibria of the effective potential with their stability go to the
//! summary. Every parameter of the chosen model is a knob.
//!
//! `cargo run --release --example explore -- --set model=elastic_pendulum --set k=20`

use mechlab::explore::{explore, Exploration, Settings};
use mechlab::models;
use mechlab::ode::Method;
use mechlab::plot::{palette, Figure, PanelSpec, BLACK, GREY, RED};
use mechlab::registry::{display_name, Kind, ModelInfo};
use mechlab::scene::{knob, parameter_knobs, run, Scene, SceneError};

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    if lo > hi {
        return (-1.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

fn main() {
    run(|| {
        let name = Scene::peek("model").unwrap_or_else(|| "kapitza".into());
        let model = models::dynamic(&name).ok_or_else(|| {
            let known: Vec<&str> = models::ALL.iter().map(|m| m.name).collect();
            SceneError::BadValue {
                name: "model".into(),
                value: name.clone(),
                reason: format!("no such model (known: {})", known.join(", ")),
            }
        })?;
        let info = model.info();
        let mut knobs = vec![
            knob("model", "kapitza", "the model (a file models/<name>.toml)"),
            knob("y0", "auto", "initial state, comma-separated: [q; p] or [s; s'] (auto: q = 0.3, 0.5, …, p = 0; contacts: s = 0, −0.3, …, s' = 1)"),
            knob("t_end", "20", "length of the run"),
            knob("method", "dop853", "integration method (rk4, dop853, gauss4, gauss6, radau5, taylor)"),
            knob("tol", "1e-10", "tolerance, or step for fixed-step methods"),
            knob("samples", "2000", "samples of the time series"),
            knob("periods", "300", "periods of the period map (models with a fast phase)"),
        ];
        knobs.extend(parameter_knobs(info, &[]));
        let scene = Scene::from_args(
            "explore",
            "any model by name: runs, portraits, period map, equilibria, energy",
            &knobs,
        )?;
        let params = scene.parameter_values(info)?;
        let (n, contacts) = match model.kind() {
            Kind::Hamiltonian { dof, .. } => (dof, false),
            Kind::Contacts { count } => (count, true),
        };
        let y0: Vec<f64> = match scene.text("y0") {
            "auto" if contacts => (0..n)
                .map(|i| -0.3 * i as f64)
                .chain((0..n).map(|_| 1.0))
                .collect(),
            "auto" => (0..n)
                .map(|i| 0.3 + 0.2 * i as f64)
                .chain((0..n).map(|_| 0.0))
                .collect(),
            _ => scene.numbers("y0")?,
        };
        let settings = Settings {
            method: Method::parse(scene.text("method"), scene.positive("tol")?)?,
            t_end: scene.positive("t_end")?,
            samples: scene.count("samples")?,
            periods: scene.count("periods")?,
        };
        let result = explore(model, &params, &y0, &settings)
            .map_err(|e| SceneError::Numerical(e.to_string()))?;

        let figure = draw(&result, info, n, contacts, &settings);
        scene.save_figure(&figure, "explore.png")?;
        let header: Vec<String> = std::iter::once("t".to_string())
            .chain((0..2 * n).map(|k| format!("exact_{k}")))
            .chain(
                (0..if result.averaged.is_some() { 2 * n } else { 0 })
                    .map(|k| format!("averaged_{k}")),
            )
            .collect();
        scene.write_csv(
            "series.csv",
            &header.iter().map(String::as_str).collect::<Vec<_>>(),
            result.times.iter().enumerate().map(|(k, t)| {
                std::iter::once(*t)
                    .chain(result.exact[k].iter().copied())
                    .chain(result.averaged.iter().flat_map(|a| a[k].iter().copied()))
                    .collect::<Vec<f64>>()
            }),
        )?;
        for e in &result.equilibria {
            println!(
                "equilibrium q = {:?}: Hessian eigenvalues {:?}: {}",
                e.q,
                e.hessian_eigenvalues,
                if e.stable { "stable" } else { "unstable" }
            );
        }
        for s in &result.switches {
            println!("{s}");
        }
        let max_energy = result
            .energy_change
            .iter()
            .fold(0.0f64, |m, e| m.max(e.abs()));
        println!("{}: max |change| {max_energy:.3e}", result.energy_label);
        #[derive(serde::Serialize)]
        struct Energy {
            label: &'static str,
            max_abs_change: f64,
        }
        #[derive(serde::Serialize)]
        struct Summary<'a> {
            model: &'static str,
            params: std::collections::BTreeMap<&'static str, f64>,
            y0: &'a [f64],
            final_state: Option<&'a Vec<f64>>,
            equilibria: &'a [mechlab::explore::Equilibrium],
            energy: Energy,
            switches: &'a [String],
        }
        scene.write_summary(&Summary {
            model: info.name,
            params: info
                .parameter_names
                .iter()
                .copied()
                .zip(params.iter().copied())
                .collect(),
            y0: &y0,
            final_state: result.exact.last(),
            equilibria: &result.equilibria,
            energy: Energy {
                label: result.energy_label,
                max_abs_change: max_energy,
            },
            switches: &result.switches,
        })?;
        Ok(())
    });
}

/// The figure: per degree of freedom the time series, the phase portrait
/// and the period map (or the velocity), then the energy change and the
/// exact−averaged deviation.
fn draw(
    result: &Exploration,
    info: &ModelInfo,
    n: usize,
    contacts: bool,
    settings: &Settings,
) -> Figure {
    // Labels in the model's notation (φ₁, p_φ₁, x₁′).
    let names: Vec<String> = info.coordinates.iter().map(|c| display_name(c)).collect();
    let coordinate_names: Vec<&str> = names.iter().map(String::as_str).collect();
    let velocity = |i: usize| {
        if contacts {
            format!("{}′", coordinate_names[i])
        } else {
            display_name(info.momenta[i])
        }
    };
    let mut titles = Vec::new();
    for (i, q) in coordinate_names.iter().enumerate() {
        titles.push(format!("{q}(t)"));
        titles.push(format!("phase portrait ({q}, {})", velocity(i)));
        titles.push(if result.period_map.is_some() {
            format!("period map ({q}, {})", velocity(i))
        } else {
            format!("{}(t)", velocity(i))
        });
    }
    titles.push(result.energy_label.to_string());
    if result.averaged.is_some() {
        titles.push("|exact − averaged| of the coordinates".into());
    }
    let column = |k: usize, rows: &[Vec<f64>]| rows.iter().map(move |y| y[k]).collect::<Vec<f64>>();
    let mut specs = Vec::new();
    let t_range = (0.0, settings.t_end);
    let averaged = result.averaged.clone().unwrap_or_default();
    for i in 0..n {
        let q: Vec<f64> = column(i, &result.exact)
            .into_iter()
            .chain(column(i, &averaged))
            .collect();
        let p: Vec<f64> = column(n + i, &result.exact)
            .into_iter()
            .chain(column(n + i, &averaged))
            .collect();
        specs.push(PanelSpec::new(
            &titles[3 * i],
            "t",
            coordinate_names[i],
            t_range,
            range(q.iter().copied()),
        ));
        specs.push(PanelSpec::new(
            &titles[3 * i + 1],
            coordinate_names[i],
            "",
            range(q.iter().copied()),
            range(p.iter().copied()),
        ));
        match &result.period_map {
            Some(map) => specs.push(PanelSpec::new(
                &titles[3 * i + 2],
                coordinate_names[i],
                "",
                range(column(i, map).into_iter()),
                range(column(n + i, map).into_iter()),
            )),
            None => specs.push(PanelSpec::new(
                &titles[3 * i + 2],
                "t",
                "",
                t_range,
                range(p.iter().copied()),
            )),
        }
    }
    specs.push(PanelSpec::new(
        &titles[3 * n],
        "t",
        "",
        t_range,
        range(result.energy_change.iter().copied().chain([0.0])),
    ));
    let deviation: Vec<Vec<(f64, f64)>> = (0..n)
        .map(|i| {
            result
                .times
                .iter()
                .zip(result.exact.iter().zip(&averaged))
                .map(|(t, (e, a))| (*t, (e[i] - a[i]).abs()))
                .collect()
        })
        .collect();
    if result.averaged.is_some() {
        specs.push(PanelSpec::new(
            &titles[3 * n + 1],
            "t",
            "",
            t_range,
            range(deviation.iter().flatten().map(|p| p.1).chain([0.0])),
        ));
    }
    let mut figure = Figure::grid(3, specs.len().div_ceil(3), 460, 340, &specs);
    let series = |k: usize, rows: &[Vec<f64>]| {
        result
            .times
            .iter()
            .zip(rows)
            .map(|(t, y)| (*t, y[k]))
            .collect::<Vec<_>>()
    };
    let pairs = |a: usize, b: usize, rows: &[Vec<f64>]| {
        rows.iter().map(|y| (y[a], y[b])).collect::<Vec<_>>()
    };
    for i in 0..n {
        figure.line(3 * i, &series(i, &result.exact), palette(0));
        figure.line(3 * i + 1, &pairs(i, n + i, &result.exact), palette(0));
        if result.averaged.is_some() {
            figure.line(3 * i, &series(i, &averaged), BLACK);
            figure.line(3 * i + 1, &pairs(i, n + i, &averaged), BLACK);
            figure.legend(
                3 * i,
                &[("exact".into(), palette(0)), ("averaged".into(), BLACK)],
            );
        }
        match &result.period_map {
            Some(map) => figure.points(3 * i + 2, pairs(i, n + i, map), RED, 3),
            None => figure.line(3 * i + 2, &series(n + i, &result.exact), palette(1)),
        }
    }
    let energy: Vec<(f64, f64)> = result
        .times
        .iter()
        .copied()
        .zip(result.energy_change.iter().copied())
        .collect();
    figure.line(3 * n, &energy, GREY);
    for (i, d) in deviation.iter().enumerate() {
        if result.averaged.is_some() {
            figure.line(3 * n + 1, d, palette(i));
        }
    }
    figure
}
