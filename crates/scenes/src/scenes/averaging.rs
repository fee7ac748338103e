//! The `averaging` scene: exact against averaged.

use super::declared_scene;
use crate::scene::SceneError;
use mechlab_runtime::registry::Catalog;

/// The `averaging` scene: Theorem 2 on any model — the deviation between
/// the exact and averaged runs from the same state against the phase's
/// frequency, with the fitted slopes, and ν × deviation. `values` takes a
/// list, `auto`, or `geometric:first,last,count`.
pub fn averaging_scene(
    catalog: Catalog,
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::averaging::{convergence, AveragingOptions};
    let (model, scene, options) = declared_scene::<AveragingOptions>(
        catalog,
        scene_name,
        ("double_pendulum", None),
        (AveragingOptions::default(), overrides),
        &[],
    )?;
    let settings = options.resolve()?;
    let result = convergence(model, &scene.parameter_values(model.info)?, &settings)?;
    for (c, s) in result.coordinates.iter().zip(&result.slope) {
        eprintln!("{c}: max deviation ∝ ν^{s:.4}");
    }
    let rows: Vec<(f64, f64, String, f64, f64)> = result
        .coordinates
        .iter()
        .enumerate()
        .flat_map(|(c, name)| {
            let result = &result;
            (0..result.values.len()).map(move |k| {
                (
                    result.values[k],
                    result.frequencies[k],
                    name.clone(),
                    result.max_deviation[c][k],
                    result.frequency_times_deviation[c][k],
                )
            })
        })
        .collect();
    let header = [
        result.parameter.as_str(),
        "frequency",
        "coordinate",
        "max_deviation",
        "frequency_times_max_deviation",
    ];
    scene.write_csv("convergence.csv", &header, rows)?;
    scene.save_figure(&result.figure(), "convergence.png")?;
    scene.write_summary(&result)?;
    Ok(())
}
