//! The `section` scene: orbits, the MEGNO map and the frequency map of
//! a Poincaré section.

use super::declared_scene;
use super::maps::write_frequency_map;
use crate::scene::{Scene, SceneError};
use mechlab_runtime::registry::Catalog;

/// Scene `section`: the Poincaré section of an autonomous model of two
/// degrees of freedom at a fixed energy.
pub fn section_scene(
    catalog: Catalog,
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::section::{section_study, SectionOptions};
    let (model, scene, options) = declared_scene::<SectionOptions>(
        catalog,
        scene_name,
        ("henon_heiles", None),
        (SectionOptions::default(), overrides),
        &[],
    )?;
    let params = scene.parameter_values(model.info)?;
    let study = section_study(model, &params, &options, &|line| eprintln!("{line}"))?;
    if let Some(section) = &study.section {
        write_section(&scene, section, options.crossings)?;
    }
    if let Some(map) = &study.frequency_map {
        write_frequency_map(&scene, map)?;
    }
    if let Some(map) = &study.megno_map {
        write_megno_map(&scene, map)?;
    }
    scene.write_summary(&study)?;
    Ok(())
}

/// The section's figure, table and report.
fn write_section(
    scene: &Scene,
    result: &mechlab_runtime::analysis::section::Section,
    crossings: usize,
) -> Result<(), SceneError> {
    scene.save_figure(&result.figure(), "section.png")?;
    let rows = result
        .orbits
        .iter()
        .enumerate()
        .flat_map(|(k, o)| o.points.iter().map(move |p| (k, p[0], p[1])));
    scene.write_csv(
        "section.csv",
        &["orbit", result.axes[0].as_str(), result.axes[1].as_str()],
        rows,
    )?;
    eprintln!(
        "largest |{} − E| on the section {:.1e}, largest distance from the plane {:.1e}",
        result.energy_of, result.largest_energy_drift, result.largest_plane_distance
    );
    for (k, end) in result.ended_early() {
        let o = &result.orbits[k];
        eprintln!(
            "orbit {k} (seed {:?}) ended after {} of {} points: {end}",
            o.points[0], o.crossings, crossings
        );
    }
    Ok(())
}

/// The MEGNO map's figure and table.
fn write_megno_map(
    scene: &Scene,
    map: &mechlab_runtime::analysis::section_map::SectionMap,
) -> Result<(), SceneError> {
    scene.save_figure(&map.figure(), "section_megno.png")?;
    let (window, pixels) = (map.window, map.pixels);
    let at = move |k: usize, range: [f64; 2]| {
        range[0] + (range[1] - range[0]) * (k as f64 + 0.5) / pixels as f64
    };
    let rows = map
        .megno
        .iter()
        .enumerate()
        .map(move |(k, v)| (at(k % pixels, window[0]), at(k / pixels, window[1]), *v));
    scene.write_csv(
        "section_megno.csv",
        &[map.axes[0].as_str(), map.axes[1].as_str(), "megno"],
        rows,
    )?;
    Ok(())
}
