//! The `separatrix_splitting` scene.

use super::declared_scene;
use super::geometric_progression;
use crate::scene::{knob, Scene, SceneError, ValueProblem};
use mechlab_runtime::registry::{Catalog, Model};
use mechlab_runtime::settings::Range;

/// The `separatrix_splitting` scene: the hyperbolic fixed point of the
/// period map of a 1-degree-of-freedom model with a fast phase, its
/// manifolds, two primary homoclinic points and the lobe between them.
pub fn separatrix_scene(
    catalog: Catalog,
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::separatrix::{separatrix_splitting, SplittingOptions};
    let sweep = [
        knob(
            "sweep",
            "none",
            "also sweep `sweep_parameter` geometrically: first,last,count (none: no sweep)",
        ),
        knob("sweep_parameter", "eps", "the parameter the sweep sets"),
    ];
    let (model, scene, options) = declared_scene::<SplittingOptions>(
        catalog,
        scene_name,
        ("kapitza", None),
        (SplittingOptions::default(), overrides),
        &sweep,
    )?;
    let settings = options.resolve()?;
    let params = scene.parameter_values(model.info)?;
    eprintln!("growing the manifolds of the hyperbolic fixed point …");
    let splitting = separatrix_splitting(model, &params, &settings)?;
    crate::study::write_files(&scene, &splitting)?;
    let sweep = splitting_sweep_of(&scene, model, &params, &settings)?;
    #[derive(serde::Serialize)]
    struct Summary<'a> {
        splitting: &'a mechlab_runtime::analysis::separatrix::Splitting,
        sweep: Option<&'a mechlab_runtime::analysis::separatrix::SplittingSweep>,
    }
    scene.write_summary(&Summary {
        splitting: &splitting,
        sweep: sweep.as_ref(),
    })?;
    Ok(())
}

/// The separatrix scene's sweep of `sweep_parameter` when `sweep` asks for
/// one, with its figure and table.
fn splitting_sweep_of(
    scene: &Scene,
    model: &Model,
    params: &[f64],
    settings: &mechlab_runtime::analysis::separatrix::SplittingSettings,
) -> Result<Option<mechlab_runtime::analysis::separatrix::SplittingSweep>, SceneError> {
    use mechlab_runtime::analysis::separatrix::splitting_sweep;
    Ok(match scene.text("sweep") {
        "none" => None,
        _ => {
            let values = geometric_progression(&scene.get::<Vec<f64>>("sweep", Range::Any)?)
                .map_err(|reason| SceneError::BadValue {
                    name: "sweep".into(),
                    value: scene.text("sweep").into(),
                    reason: ValueProblem::Requirement(reason),
                })?;
            eprintln!(
                "sweeping {} over {} values …",
                scene.text("sweep_parameter"),
                values.len()
            );
            let sweep = splitting_sweep(
                model,
                params,
                scene.text("sweep_parameter"),
                &values,
                settings,
            )?;
            scene.save_figure(&sweep.figure(), "lobe_area_sweep.png")?;
            let rows = sweep.rows.iter().map(|r| {
                (
                    r.value,
                    r.eps,
                    r.lobe_area_action,
                    r.lobe_area_polygon,
                    r.lobe_area_melnikov,
                    r.angle,
                    r.resolved,
                )
            });
            scene.write_csv(
                "lobe_area_sweep.csv",
                &[
                    "value",
                    "eps",
                    "lobe_area_action",
                    "lobe_area_polygon",
                    "lobe_area_melnikov",
                    "angle",
                    "resolved",
                ],
                rows,
            )?;
            Some(sweep)
        }
    })
}
