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
    use mechlab_runtime::analysis::period_map::{portrait, PeriodMapOptions};
    let (model, scene, options) = declared_scene::<PeriodMapOptions>(
        catalog,
        scene_name,
        ("kapitza", None),
        (PeriodMapOptions::default(), overrides),
        &[],
    )?;
    let info = model.info;
    let settings = options.resolve(model)?;
    let result = portrait(model, &scene.parameter_values(info)?, &settings)?;
    for stopped in &result.failed {
        eprintln!("orbit {} stopped: {}", stopped.orbit, stopped.error);
    }
    scene.save_figure(&result.figure(), "period_map.png")?;
    let rows = result
        .orbits
        .iter()
        .enumerate()
        .flat_map(|(k, orbit)| orbit.iter().map(move |(a, b)| (k, *a, *b)));
    scene.write_csv(
        "orbits.csv",
        &["orbit", result.axes[0].as_str(), result.axes[1].as_str()],
        rows,
    )?;
    scene.write_summary(&result)?;
    Ok(())
}

/// Scene `attractor`: the attractor of the period map of a forced, damped
/// model of one degree of freedom (a constrained one: on its constraints)
/// by name, its Lyapunov spectrum and dimensions.
pub fn attractor_scene(catalog: Catalog) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::attractor::{attractor, AttractorOptions};
    let (model, scene, options) = declared_scene::<AttractorOptions>(
        catalog,
        "attractor",
        ("ueda", None),
        (AttractorOptions::default(), &[]),
        &[],
    )?;
    let settings = options.resolve()?;
    let params = scene.parameter_values(model.info)?;
    eprintln!(
        "{} periods of the map and two Lyapunov runs of {} …",
        settings.transient + settings.points,
        settings.lyapunov_periods
    );
    let result = attractor(model, &params, &settings)?;
    scene.save_figure(&result.figure(), "attractor.png")?;
    scene.write_csv(
        "attractor.csv",
        &["q", "p"],
        result.orbit.iter().map(|y| (y[0], y[1])),
    )?;
    scene.write_csv(
        "lyapunov_convergence.csv",
        &["periods", "lambda_1", "lambda_2"],
        result.convergence.iter().map(|(k, l)| (*k, l[0], l[1])),
    )?;
    scene.write_summary(&result)?;
    Ok(())
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
