//! Scene `averaging`: Theorem 2 on any model with a fast phase, by name. The
//! exact and the averaged system run from the same state [q; p] for each
//! value of the parameter that sets the phase's frequency ν; the figure
//! shows each coordinate's largest deviation over [0, t_obs] against ν on
//! log axes with the fitted line (slope −1 where the theorem holds).
//!
//! `cargo run --release --example averaging -- --set model=triple_pendulum`

use mechlab::analysis::averaging::{convergence, AveragingConvergence, ConvergenceSettings};
use mechlab::models;
use mechlab::ode::Method;
use mechlab::plot::{palette, Figure, PanelSpec};
use mechlab::registry::display_name;
use mechlab::scene::{knob, parameter_knobs, run, Scene, SceneError};

fn main() {
    run(|| {
        let name = Scene::peek("model").unwrap_or_else(|| "double_pendulum".into());
        let info = mechlab::registry::find(&name).ok_or_else(|| SceneError::BadValue {
            name: "model".into(),
            value: name.clone(),
            reason: format!(
                "no such model (known: {})",
                models::ALL
                    .iter()
                    .map(|m| m.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })?;
        let mut knobs = vec![
            knob(
                "model",
                "double_pendulum",
                "the model (a file models/<name>.toml) with a fast phase",
            ),
            knob(
                "parameter",
                "auto",
                "the parameter swept to change ν (auto: the one the phase rate depends on)",
            ),
            knob(
                "values",
                "auto",
                "its values, comma-separated (auto: ν at 4…64 times the model's frequency)",
            ),
            knob(
                "y0",
                "auto",
                "the common initial state [q; p], comma-separated (auto: q = 0.2, −0.1, …, p = 0)",
            ),
            knob("t_obs", "2", "the deviation is the maximum over [0, t_obs]"),
            knob("method", "dop853", "integration method"),
            knob("tol", "1e-11", "its tolerance"),
        ];
        knobs.extend(parameter_knobs(info, &[]));
        let scene = Scene::from_args(
            "averaging",
            "exact against averaged: the deviation against the frequency",
            &knobs,
        )?;
        let settings = ConvergenceSettings {
            parameter: (scene.text("parameter") != "auto")
                .then(|| scene.text("parameter").to_string()),
            values: (scene.text("values") != "auto")
                .then(|| scene.numbers("values"))
                .transpose()?,
            y0: (scene.text("y0") != "auto")
                .then(|| scene.numbers("y0"))
                .transpose()?,
            t_obs: scene.positive("t_obs")?,
            method: Method::parse(scene.text("method"), scene.positive("tol")?)?,
        };
        let result = convergence(&name, &scene.parameter_values(info)?, &settings)?;
        for (c, s) in result.coordinates.iter().zip(&result.slope) {
            eprintln!("{c}: deviation ∝ ν^{s:.3}");
        }
        let rows: Vec<(f64, f64, String, f64)> = result
            .coordinates
            .iter()
            .zip(&result.max_deviation)
            .flat_map(|(c, devs)| {
                result
                    .values
                    .iter()
                    .zip(&result.frequencies)
                    .zip(devs)
                    .map(move |((v, f), d)| (*v, *f, c.clone(), *d))
            })
            .collect();
        scene.write_csv(
            "deviation.csv",
            &[
                result.parameter.as_str(),
                "frequency",
                "coordinate",
                "max_deviation",
            ],
            &rows,
        )?;
        scene.save_figure(&figure(&result), "deviation.png")?;
        scene.write_summary(&result)?;
        Ok(())
    });
}

/// The deviation of every coordinate against ν (log–log), with the fits.
fn figure(result: &AveragingConvergence) -> Figure {
    let range = |values: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = values
            .filter(|v| *v > 0.0)
            .fold((f64::MAX, 0.0f64), |(l, h), v| (l.min(v), h.max(v)));
        (lo / 1.5, hi * 1.5)
    };
    let x = range(&mut result.frequencies.iter().copied());
    let y = range(&mut result.max_deviation.iter().flatten().copied());
    let title = format!(
        "{}: exact against averaged from the same state",
        result.model
    );
    let spec = PanelSpec::new(
        &title,
        "frequency ν of the phase",
        "max |exact − averaged|",
        x,
        y,
    )
    .log_log();
    let mut figure = Figure::single(760, 520, spec);
    let mut legend = Vec::new();
    for (k, (coordinate, deviations)) in result
        .coordinates
        .iter()
        .zip(&result.max_deviation)
        .enumerate()
    {
        let points: Vec<(f64, f64)> = result
            .frequencies
            .iter()
            .copied()
            .zip(deviations.iter().copied())
            .collect();
        figure.points(0, points.iter().copied(), palette(k), 4);
        let fit: Vec<(f64, f64)> = [x.0 * 1.5, x.1 / 1.5]
            .iter()
            .map(|nu| (*nu, result.level[k] * nu.powf(result.slope[k])))
            .collect();
        figure.line(0, &fit, palette(k));
        legend.push((
            format!("{}: slope {:.3}", display_name(coordinate), result.slope[k]),
            palette(k),
        ));
    }
    figure.legend_at(0, &legend, true);
    figure
}
