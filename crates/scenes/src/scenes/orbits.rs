//! Orbits of the period map: the `period_map` and `attractor` scenes.

use super::declared_scene;
use crate::scene::SceneError;
use mechlab_runtime::registry::Catalog;

/// The `period_map` scene: orbits of the period map of any model with a
/// fast phase on the cylinder (q, p), or on a plane of two state
/// components. Seeds: `--set seeds=…` (states separated by `;`) or a line
/// of `count` seeds along the first axis.
pub fn period_map_scene(
    catalog: Catalog,
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::period_map::PeriodMapOptions;
    super::analysis_scene::<PeriodMapOptions>(catalog, scene_name, "kapitza", overrides)
}

/// Scene `attractor`: the attractor of the period map of a forced, damped
/// model of one degree of freedom (a constrained one: on its constraints)
/// by name, its Lyapunov spectrum and dimensions.
pub fn attractor_scene(catalog: Catalog) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::attractor::AttractorOptions;
    super::analysis_scene::<AttractorOptions>(catalog, "attractor", "ueda", &[])
}

/// The `explore` scene: any model by name, its runs, portraits, period
/// map, energy and equilibria.
pub fn explore_scene(catalog: Catalog) -> Result<(), SceneError> {
    use mechlab_runtime::explore::{explore, figure, ExploreOptions};
    let (model, scene, options) = declared_scene::<ExploreOptions>(
        catalog,
        "explore",
        ("kapitza", None),
        (ExploreOptions::default(), &[]),
        &[],
    )?;
    let info = model.info;
    let params = scene.parameter_values(info)?;
    let (settings, y0) = options.resolve(model)?;
    let result = explore(model, &params, &y0, &settings)?;
    scene.save_figure(
        &figure(&result, model.dynamic, settings.t_end),
        "explore.png",
    )?;
    let header = result.series_header();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    scene.write_csv("series.csv", &header, result.series_rows())?;
    for line in result.report(info.coordinates, 32) {
        println!("{line}");
    }
    scene.write_summary(&result.summary(info, &params, &y0))?;
    Ok(())
}
