//! Scene `explore`: any model of `models/`, by name. It integrates the exact
//! system (and the averaged one if the model has a fast phase; the
//! stick–slip integrator for a contact model) with the chosen method and
//! tolerance, and draws the time series and phase portraits per degree of
//! freedom, the period map, exact against averaged, and the energy change;
//! the equilibria of the effective potential with their stability go to the
//! summary. Every parameter of the chosen model is a knob.
//!
//! `cargo run --release --example explore -- --set model=elastic_pendulum --set k=20`

use mechlab::explore::{default_start, explore, Settings};
use mechlab::scene::{knob, parameter_knobs, run, Scene};
use mechlab::scenes::{method_from, method_knobs};

fn main() {
    run(|| {
        let name = Scene::peek("model").unwrap_or_else(|| "kapitza".into());
        let handle = mechlab::models::by_name(&name)?;
        let model = handle.dynamic;
        let info = model.info();
        let [method, tol] = method_knobs("dop853", "1e-10");
        let mut knobs = vec![
            knob("model", "kapitza", "the model (a file models/<name>.toml)"),
            knob("y0", "auto", "initial state, comma-separated: [q; p] or [s; s'] (auto: q = 0.3, 0.5, …, p = 0; contacts: s = 0, −0.3, …, s' = 1)"),
            knob("t_end", "20", "length of the run"),
            method,
            tol,
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
        let y0: Vec<f64> = match scene.text("y0") {
            "auto" => default_start(model),
            _ => scene.numbers("y0")?,
        };
        let settings = Settings {
            method: method_from(&scene)?,
            t_end: scene.positive("t_end")?,
            samples: scene.count("samples")?,
            periods: scene.count("periods")?,
        };
        let result = explore(handle, &params, &y0, &settings)?;

        let figure = mechlab::explore::figure(&result, model, settings.t_end);
        scene.save_figure(&figure, "explore.png")?;
        let header = result.series_header();
        let header: Vec<&str> = header.iter().map(String::as_str).collect();
        scene.write_csv("series.csv", &header, result.series_rows())?;
        for line in result.report(info.coordinates, 32) {
            println!("{line}");
        }
        scene.write_summary(&result.summary(info, &params, &y0))?;
        Ok(())
    });
}
