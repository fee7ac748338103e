//! The `section` scene: orbits, the MEGNO map and the frequency map of
//! a Poincaré section.

use super::declared_scene;
use crate::scene::SceneError;
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
    crate::study::write_outputs(&scene, &study)
}
