//! The maps of a plane of starts: the FLI chaos map, the basins of
//! attraction, and the frequency map (of a period map, or of a section).

use super::declared_scene;
use super::{model_from_args, section_scene, share_tiles, tile_knobs, tiles_from, TileSharing};
use crate::scene::{Progress, SceneError};
use crate::study::write_outputs;
use mechlab_runtime::analysis::chaos_map::{
    chaos_map, ChaosMapError, ChaosMapOptions, ChaosMapSettings,
};
use mechlab_runtime::registry::Catalog;

/// The `chaos_map` scene: the FLI map of any model's period map on a plane
/// of two state components. `overrides` are the preset's defaults (model
/// and its parameters, settings); `sharing`, processes that share its
/// tiles (None: this process computes them all).
pub fn chaos_map_scene(
    catalog: Catalog,
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
    sharing: Option<&dyn TileSharing>,
) -> Result<(), SceneError> {
    let (model, scene, options) = declared_scene::<ChaosMapOptions>(
        catalog,
        scene_name,
        ("kapitza", None),
        (ChaosMapOptions::default(), overrides),
        &tile_knobs("10"),
    )?;
    let settings = ChaosMapSettings {
        tiles: tiles_from(&scene, ["tile_rows", "only_tiles"])?,
        ..options.resolve(model)?
    };
    let progress = Progress::new(&format!("{scene_name} rows"), settings.pixels);
    let params = scene.parameter_values(model.info)?;
    let sweep = |only: Option<Vec<usize>>| {
        let mut settings = settings.clone();
        if let Some(tiles) = &mut settings.tiles {
            tiles.only = only;
        }
        let row_done = || {
            progress.inc();
            true
        };
        match chaos_map(model, &params, &settings, &row_done) {
            Err(ChaosMapError::Partial) => Ok(false),
            map => write_outputs(&scene, &map?).map(|()| true),
        }
    };
    let rows = settings.pixels;
    share_tiles(&scene, sharing, settings.tiles.as_ref(), rows, &sweep)
}

/// The `basins` scene: the basins of attraction of a period map on a
/// plane of the state, the attractors found unaided.
pub fn basins_scene(catalog: Catalog, sharing: Option<&dyn TileSharing>) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::basins::{basins, BasinSettings, BasinsError, BasinsOptions};
    let (model, scene, options) = declared_scene::<BasinsOptions>(
        catalog,
        "basins",
        ("duffing", None),
        (BasinsOptions::default(), &[]),
        &tile_knobs("0"),
    )?;
    let settings = BasinSettings {
        tiles: tiles_from(&scene, ["tile_rows", "only_tiles"])?,
        ..options.resolve(model)?
    };
    let params = scene.parameter_values(model.info)?;
    let progress = Progress::new("basins starts", settings.pixels.pow(2));
    let sweep = |only: Option<Vec<usize>>| {
        let mut settings = settings.clone();
        if let Some(tiles) = &mut settings.tiles {
            tiles.only = only;
        }
        match basins(model, &params, &settings, &|k| progress.advance(k)) {
            Err(BasinsError::Partial) => Ok(false),
            result => write_outputs(&scene, &result?).map(|()| true),
        }
    };
    let rows = settings.pixels;
    share_tiles(&scene, sharing, settings.tiles.as_ref(), rows, &sweep)
}

/// The `frequency_map` scene: Laskar's frequency map of a section at a
/// fixed energy for an autonomous model (Hénon–Heiles by default; the
/// `section` scene's knobs), or of the period map on a plane for a model
/// with a fast phase (the chaos map's plane and knobs).
pub fn frequency_map_scene(catalog: Catalog) -> Result<(), SceneError> {
    let model = model_from_args(catalog, "henon_heiles")?;
    use mechlab_runtime::registry::Kind;
    let fast_phase = matches!(
        model.dynamic.kind(),
        Kind::Hamiltonian {
            fast_phase: true,
            ..
        } | Kind::Constrained {
            fast_phase: true,
            ..
        }
    );
    if !fast_phase {
        let overrides = [("frequencies", "100"), ("orbits", "0")];
        return section_scene(catalog, "frequency_map", &overrides);
    }
    let (model, scene, options) = declared_scene::<ChaosMapOptions>(
        catalog,
        "frequency_map",
        (
            "henon_heiles",
            Some(
                "Laskar's frequency map of the period map: each orbit's tunes and diffusion index",
            ),
        ),
        (
            mechlab_runtime::analysis::frequency_map::period_map_options(),
            &[],
        ),
        &[],
    )?;
    let settings = options.resolve(model)?;
    let params = scene.parameter_values(model.info)?;
    let progress = Progress::new("frequency map orbits", settings.pixels.pow(2));
    let map = mechlab_runtime::analysis::frequency_map::period_map_frequencies(
        model,
        &params,
        &settings,
        &|k| progress.advance(k),
    )?;
    write_outputs(&scene, &map)
}
