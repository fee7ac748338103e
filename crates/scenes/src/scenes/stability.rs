//! Stabilisation by vibration: the `stability` scene (and its chart)
//! and the `linkage` scene on constraints.

use super::declared_scene;
use super::{model_from_args, tiles_from};
use crate::scene::{knob, Knob, Scene, SceneError, ValueProblem};
use mechlab_runtime::registry::{Catalog, Model};
use mechlab_runtime::settings::Range;

/// The `linkage` scene: stabilisation by vibration of a constrained model
/// (the four-bar linkage held upside down by default): the averaged
/// equilibrium on the constraints, its thresholds, and the exact window.
pub fn linkage_scene(
    catalog: Catalog,
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::on_constraints::vibration::LinkageOptions;
    super::analysis_scene::<LinkageOptions>(catalog, scene_name, "four_bar", overrides)
}

/// The `steady_motion` scene: the linearisation of a constrained model's
/// steady motion (Chaplygin's sleigh gliding straight by default): its
/// eigenvalues with their errors and verdict, and against the speed.
pub fn steady_motion_scene(
    catalog: Catalog,
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::on_constraints::steady::study::SteadyMotionOptions;
    super::analysis_scene::<SteadyMotionOptions>(catalog, scene_name, "chaplygin_sleigh", overrides)
}

/// The `stability` scene: stabilisation by vibration of any model's
/// equilibria, with `chart=x,y` the stability chart of one equilibrium in
/// two parameters. A constrained model's stability is on its constraints:
/// with a fast phase, its stabilisation by vibration (the `linkage`
/// scene); without, the linearisation of its steady motion (the
/// `steady_motion` scene).
pub fn stability_scene(catalog: Catalog) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::stability::{stability, StabilityOptions};
    let model = model_from_args(catalog, "kapitza")?;
    if model.constrained.is_some() {
        let overrides = [("model", model.info.name)];
        return match model.info.amplitude {
            Some(_) => linkage_scene(catalog, "stability", &overrides),
            None => steady_motion_scene(catalog, "stability", &overrides),
        };
    }
    let (model, scene, options) = declared_scene::<StabilityOptions>(
        catalog,
        "stability",
        ("kapitza", None),
        (StabilityOptions::default(), &[]),
        &chart_knobs(),
    )?;
    let params = scene.parameter_values(model.info)?;
    let settings = options.resolve(model)?;
    let result = stability(model, &params, &settings)?;
    crate::study::write_files(&scene, &result)?;
    if scene.text("chart") != "none" && !write_chart(&scene, model, &params, &settings)? {
        return Ok(());
    }
    scene.write_summary(&result)?;
    Ok(())
}

/// The stability chart's knobs.
fn chart_knobs() -> Vec<Knob> {
    vec![
        knob("chart", "none", "two parameters x,y for a stability chart of the equilibrium chart_q (none: no chart)"),
        knob("chart_q", "0", "the equilibrium of the chart, comma-separated (0: all coordinates zero)"),
        knob("chart_x", "0.02,0.5,40", "first, last value and count of x"),
        knob("chart_y_max", "12", "y is sampled on (0, chart_y_max]"),
        knob("chart_y_samples", "120", "samples of y that bracket the boundaries"),
        knob("chart_tile_columns", "4", "chart columns per tile, each written to out/stability.tiles/ when done so a rerun resumes (0: no tiles)"),
        knob("chart_only_tiles", "all", "compute only these chart tiles (comma-separated indices, a job of an array) and stop; all: every missing tile, then the chart"),
    ]
}

/// The stability chart of the chart knobs, its figure, table and
/// `chart.json`; false for a job of an array whose tiles are written.
fn write_chart(
    scene: &Scene,
    model: &Model,
    params: &[f64],
    settings: &mechlab_runtime::analysis::stability::Settings,
) -> Result<bool, SceneError> {
    use mechlab_runtime::analysis::stability::{stability_chart, ChartSettings, StabilityError};
    let bad = |name: &str, reason: &'static str| SceneError::BadValue {
        name: name.into(),
        value: scene.text(name).into(),
        reason: ValueProblem::Requirement(reason),
    };
    let Some((x, y)) = scene.text("chart").split_once(',') else {
        return Err(bad("chart", "two parameter names x,y"));
    };
    let [first, last, count] = scene.get::<Vec<f64>>("chart_x", Range::Any)?[..] else {
        return Err(bad("chart_x", "first,last,count"));
    };
    if !(count >= 2.0 && count.fract() == 0.0) {
        return Err(bad("chart_x", "a whole count of at least 2"));
    }
    let n = count as usize;
    let chart_settings = ChartSettings {
        q: if scene.text("chart_q") == "0" {
            vec![0.0; model.info.coordinates.len()]
        } else {
            scene.get("chart_q", Range::Any)?
        },
        x: x.trim().into(),
        x_values: (0..n)
            .map(|k| first + (last - first) * k as f64 / (n - 1) as f64)
            .collect(),
        y: y.trim().into(),
        y_max: scene.get("chart_y_max", Range::Positive)?,
        y_samples: scene.get(
            "chart_y_samples",
            Range::Count {
                min: 1,
                max: 1_000_000,
            },
        )?,
        edge_tolerance: settings.edge_tolerance,
        method: settings.method,
        tiles: tiles_from(scene, ["chart_tile_columns", "chart_only_tiles"])?,
    };
    let chart = match stability_chart(model, params, &chart_settings) {
        // A job of an array: its tiles are written, the last run draws.
        Err(StabilityError::Partial) => {
            eprintln!("chart tiles {} written", scene.text("chart_only_tiles"));
            return Ok(false);
        }
        chart => chart?,
    };
    scene.write_csv(
        "chart_boundaries.csv",
        &[chart.x.as_str(), chart.y.as_str()],
        chart.boundary_rows(),
    )?;
    scene.save_figure(&chart.figure(), "chart.png")?;
    let json = serde_json::to_string_pretty(&chart).map_err(|source| SceneError::Summary {
        scene: "stability",
        source,
    })?;
    scene.write_text("chart.json", &json)?;
    Ok(true)
}
