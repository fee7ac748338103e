//! Scene `stability`: stabilisation by vibration for any model with a fast
//! phase, by name. For every equilibrium of the system without vibration
//! that stays one of the averaged system: the roots λ of det(C − λA) = 0,
//! the threshold a* of the amplitude from V + V_vibr = C + a²K (or why there
//! is none), and the exact system's stability window from its Floquet
//! multipliers, drawn as the spectral radius against the amplitude. With
//! `--set chart=x,y`, the stability chart of one equilibrium in two
//! parameters, its boundaries located by bisection. A constrained model
//! is stabilised on its constraints, as the scene `linkage` does (its
//! knobs then).
//!
//! `cargo run --release --example stability -- --set model=triple_pendulum`
//! `cargo run --release --example stability -- --set chart=eps,A --set chart_y_max=12`

use mechlab::analysis::stability::{
    stability, stability_chart, ChartSettings, Settings, StabilityError,
};
use mechlab::scene::{knob, parameter_knobs, run, Scene, SceneError, ValueProblem};
use mechlab::scenes::{method_from, method_knobs, model_from_args, tiles_from};

fn main() {
    run(|| {
        let model = model_from_args(mechlab::models::MODELS, "kapitza")?;
        if model.constrained.is_some() {
            // Stabilised on its constraints: the `linkage` analysis, its knobs.
            let overrides = [("model", model.info.name)];
            return mechlab::scenes::linkage_scene(
                mechlab::models::MODELS,
                "stability",
                &overrides,
            );
        }
        let info = model.info;
        let [method, tol] = method_knobs("dop853", "1e-10");
        let mut knobs = vec![
            knob("model", "kapitza", "the model (a file models/<name>.toml) with a fast phase"),
            knob("amplitude", info.amplitude.unwrap_or("none"), "the parameter that scales the vibration (default: the model file's [fast_phase] amplitude)"),
            method,
            tol,
            knob("samples", "40", "amplitudes sampled on (0, a_max] to bracket the exact window's edges"),
            knob("a_max", "auto", "largest amplitude of the exact window (auto: 3 a*)"),
            knob("max_windows", "64", "at most this many equilibria get an exact window (a Floquet sweep each): those with the lowest thresholds a*, then those the vibration moves"),
            knob("edge_tolerance", "1e-9", "the window's edges and the chart's boundaries are bisected to this"),
            knob("chart", "none", "two parameters x,y for a stability chart of the equilibrium chart_q (none: no chart)"),
            knob("chart_q", "0", "the equilibrium of the chart, comma-separated (0: all coordinates zero)"),
            knob("chart_x", "0.02,0.5,40", "first, last value and count of x"),
            knob("chart_y_max", "12", "y is sampled on (0, chart_y_max]"),
            knob("chart_y_samples", "120", "samples of y that bracket the boundaries"),
            knob("chart_tile_columns", "4", "chart columns per tile, each written to out/stability.tiles/ when done so a rerun resumes (0: no tiles)"),
            knob("chart_only_tiles", "all", "compute only these chart tiles (comma-separated indices, a job of an array) and stop; all: every missing tile, then the chart"),
        ];
        knobs.extend(parameter_knobs(info, &[]));
        let scene = Scene::from_args(
            "stability",
            "stabilisation by vibration of any model's equilibria",
            &knobs,
        )?;
        let params = scene.parameter_values(info)?;
        let settings = Settings {
            amplitude: scene.text("amplitude").to_string(),
            a_max: (scene.text("a_max") != "auto")
                .then(|| scene.positive("a_max"))
                .transpose()?,
            samples: scene.count("samples")?,
            edge_tolerance: scene.positive("edge_tolerance")?,
            method: method_from(&scene)?,
            max_windows: scene.count("max_windows")?,
        };
        let result = stability(model, &params, &settings)?;
        for line in result.report(32) {
            eprintln!("{line}");
        }
        scene.write_csv(
            "spectral_radius.csv",
            &["equilibrium", "amplitude", "spectral_radius"],
            result.spectral_radius_rows(),
        )?;
        if let Some(figure) = result.figure() {
            scene.save_figure(&figure, "spectral_radius.png")?;
        }
        if scene.text("chart") != "none" {
            let chart_settings = chart_settings(&scene, &settings, info.coordinates.len())?;
            let chart = match stability_chart(model, &params, &chart_settings) {
                // A job of an array: its tiles are written, the last run draws.
                Err(StabilityError::Partial) => {
                    eprintln!("chart tiles {} written", scene.text("chart_only_tiles"));
                    return Ok(());
                }
                chart => chart?,
            };
            scene.write_csv(
                "chart_boundaries.csv",
                &[chart.x.as_str(), chart.y.as_str()],
                chart.boundary_rows(),
            )?;
            scene.save_figure(&chart.figure(), "chart.png")?;
            let json =
                serde_json::to_string_pretty(&chart).map_err(|source| SceneError::Summary {
                    scene: "stability",
                    source,
                })?;
            scene.write_text("chart.json", &json)?;
        }
        scene.write_summary(&result)?;
        Ok(())
    });
}

/// The chart's settings from its knobs.
fn chart_settings(
    scene: &Scene,
    settings: &Settings,
    dof: usize,
) -> Result<ChartSettings, SceneError> {
    let bad = |name: &str, reason: &'static str| SceneError::BadValue {
        name: name.into(),
        value: scene.text(name).into(),
        reason: ValueProblem::Requirement(reason),
    };
    let Some((x, y)) = scene.text("chart").split_once(',') else {
        return Err(bad("chart", "two parameter names x,y"));
    };
    let [first, last, count] = scene.numbers("chart_x")?[..] else {
        return Err(bad("chart_x", "first,last,count"));
    };
    if !(count >= 2.0 && count.fract() == 0.0) {
        return Err(bad("chart_x", "a whole count of at least 2"));
    }
    let n = count as usize;
    Ok(ChartSettings {
        q: if scene.text("chart_q") == "0" {
            vec![0.0; dof]
        } else {
            scene.numbers("chart_q")?
        },
        x: x.trim().into(),
        x_values: (0..n)
            .map(|k| first + (last - first) * k as f64 / (n - 1) as f64)
            .collect(),
        y: y.trim().into(),
        y_max: scene.positive("chart_y_max")?,
        y_samples: scene.count("chart_y_samples")?,
        edge_tolerance: settings.edge_tolerance,
        method: settings.method,
        tiles: tiles_from(scene, ["chart_tile_columns", "chart_only_tiles"])?,
    })
}
