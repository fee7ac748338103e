//! The `averaging` scene: exact against averaged.

use crate::scene::SceneError;
use mechlab_runtime::analysis::averaging::AveragingOptions;
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
    super::analysis_scene::<AveragingOptions>(catalog, scene_name, "double_pendulum", overrides)
}
