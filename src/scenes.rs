//! The bodies of the generic scenes, shared by the scene of that name and
//! the study scenes that are its presets (the same knobs with other
//! defaults, the same files): knobs → one library call → figures.

use crate::analysis::chaos_map::{chaos_map, ChaosMapSettings};
use crate::ode::Method;
use crate::registry::ModelInfo;
use crate::scene::{knob, parameter_knobs, Knob, Progress, Scene, SceneError};

/// The model named by `--set model=…` (or `default`), with a clear error
/// listing the known ones.
pub fn model_from_args(default: &str) -> Result<&'static ModelInfo, SceneError> {
    let name = Scene::peek("model").unwrap_or_else(|| default.into());
    crate::registry::find(&name).ok_or_else(|| SceneError::BadValue {
        name: "model".into(),
        value: name.clone(),
        reason: format!(
            "no such model (known: {})",
            crate::models::ALL
                .iter()
                .map(|m| m.name)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    })
}

/// `method` and `tol` knobs with these defaults.
pub fn method_knobs(method: &'static str, tol: &'static str) -> [Knob; 2] {
    [
        knob(
            "method",
            method,
            "integration method (taylor, dop853, rk4, gauss4, gauss6, radau5)",
        ),
        knob(
            "tol",
            tol,
            "its tolerance (taylor, dop853, radau5) or step size",
        ),
    ]
}

/// The method of the `method`/`tol` knobs.
pub fn method_from(scene: &Scene) -> Result<Method, SceneError> {
    Ok(Method::parse(scene.text("method"), scene.positive("tol")?)?)
}

/// The `chaos_map` scene: the FLI map of any model's period map on a plane
/// of two state components. `overrides` are the preset's defaults (model
/// and its parameters, knobs).
pub fn chaos_map_scene(
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError> {
    let default = |name: &str, value: &'static str| -> &'static str {
        overrides
            .iter()
            .find(|(n, _)| *n == name)
            .map_or(value, |(_, v)| v)
    };
    let info = model_from_args(default("model", "kapitza"))?;
    let [method, tol] = method_knobs(default("method", "taylor"), default("tol", "1e-6"));
    let mut knobs = vec![
        knob(
            "model",
            default("model", "kapitza"),
            "the model (a file models/<name>.toml) with a fast phase",
        ),
        knob(
            "axes",
            default("axes", "0,1"),
            "the state components [q; p] along the two axes (0 = first coordinate)",
        ),
        knob(
            "through",
            default("through", "0"),
            "the state the plane passes through, comma-separated (0: all zero)",
        ),
        knob(
            "pixels",
            default("pixels", "300"),
            "resolution (pixels per side)",
        ),
        knob(
            "periods",
            default("periods", "180"),
            "periods of the phase per pixel",
        ),
        knob(
            "p_max",
            default("p_max", "3"),
            "an axis that is not an angle covers [−p_max, p_max]",
        ),
        method,
        tol,
    ];
    knobs.extend(parameter_knobs(info, overrides));
    let scene = Scene::from_args(
        scene_name,
        "FLI chaos map of the period map of any model",
        &knobs,
    )?;
    let axes = scene.numbers("axes")?;
    let [x, y] = axes.as_slice() else {
        return Err(SceneError::BadValue {
            name: "axes".into(),
            value: scene.text("axes").into(),
            reason: "two indices".into(),
        });
    };
    let settings = ChaosMapSettings {
        axes: [*x as usize, *y as usize],
        ranges: [None, None],
        p_max: scene.positive("p_max")?,
        through: (scene.text("through") != "0")
            .then(|| scene.numbers("through"))
            .transpose()?,
        pixels: scene.count("pixels")?,
        periods: scene.count("periods")?,
        method: method_from(&scene)?,
    };
    let progress = Progress::new(&format!("{scene_name} rows"), settings.pixels);
    let map = chaos_map(
        info.name,
        &scene.parameter_values(info)?,
        &settings,
        &|| progress.inc(),
    )?;
    let [grey, viridis] = map.figures();
    scene.save_figure(&grey, "chaos_map.png")?;
    scene.save_figure(&viridis, "chaos_map_viridis.png")?;
    let rows = map.fli.iter().enumerate().map(|(k, fli)| {
        let (a, b) = map.pixel(k);
        (a, b, *fli)
    });
    scene.write_csv(
        "chaos_map.csv",
        &[map.axes[0].as_str(), map.axes[1].as_str(), "fli"],
        rows,
    )?;
    scene.write_summary(&map)?;
    Ok(())
}
