//! The bodies of the generic scenes, shared by the scene of that name and
//! the study scenes that are its presets (the same knobs with other
//! defaults, the same files): knobs → one library call → figures.

use crate::scene::{knob, parameter_knobs, Knob, Scene, SceneError};
use mechlab_runtime::analysis::declared::{no_progress, Analysis};
use mechlab_runtime::registry::{Catalog, Model};
use mechlab_runtime::settings::Declared;
use mechlab_runtime::settings::Range;

mod averaging;
mod continuation;
mod maps;
mod orbits;
mod section;
mod separatrix;
mod stability;
mod trade;

pub use crate::study::{study_scene, write_outputs, Outputs, Study, Table};
pub use averaging::averaging_scene;
pub use continuation::continuation_scene;
pub use maps::{basins_scene, chaos_map_scene, frequency_map_scene};
pub use orbits::{attractor_scene, explore_scene, period_map_scene};
pub use section::section_scene;
pub use separatrix::separatrix_scene;
pub use stability::{linkage_scene, stability_scene, steady_motion_scene};
pub use trade::trade_scene;

/// The model of `catalog` named by `--set model=…` (or `default`), with a
/// clear error listing the known ones.
pub fn model_from_args(catalog: Catalog, default: &str) -> Result<&'static Model, SceneError> {
    let name = Scene::peek("model").unwrap_or_else(|| default.into());
    Ok(mechlab_runtime::registry::lookup(catalog, &name)?)
}

/// A preset's defaults: its value of a knob, or the generic scene's.
struct Defaults<'a>(&'a [(&'static str, &'static str)]);

impl Defaults<'_> {
    fn get(&self, name: &str, generic: &'static str) -> &'static str {
        self.0
            .iter()
            .find(|(n, _)| *n == name)
            .map_or(generic, |(_, v)| v)
    }
}

/// A scene of a declared analysis: the `model` knob, the declaration's
/// settings as knobs (with the preset's defaults where `overrides` gives
/// one, over `base`: the declaration's defaults or a preset of the
/// library's), the scene's `extra` knobs (tiles), then every parameter of the
/// chosen model; the parsed scene and the settings it asks for, validated
/// by the declaration.
fn declared_scene<T: Declared>(
    catalog: Catalog,
    scene_name: &'static str,
    (default_model, about): (&'static str, Option<&str>),
    (base, overrides): (T, &[(&'static str, &'static str)]),
    extra: &[Knob],
) -> Result<(&'static Model, Scene, T), SceneError> {
    let defaults = Defaults(overrides);
    let model_name = defaults.get("model", default_model);
    let handle = model_from_args(catalog, model_name)?;
    let names = T::names();
    let preset = base.with_texts(
        overrides
            .iter()
            .filter(|(n, _)| names.contains(n))
            .map(|&(n, v)| (n, v)),
    )?;
    let mut knobs = vec![knob(
        "model",
        model_name,
        "the model (a file models/<name>.toml)",
    )];
    knobs.extend(
        preset
            .declarations()
            .into_iter()
            .map(Knob::from_declaration),
    );
    knobs.extend(extra.iter().cloned());
    knobs.extend(parameter_knobs(handle.info, overrides));
    let about = about.map_or_else(T::about, str::to_string);
    let scene = Scene::from_args(scene_name, &about, &knobs)?;
    let options = T::default().with_texts(names.iter().map(|&n| (n, scene.text(n))))?;
    Ok((handle, scene, options))
}

/// The scene of a declared analysis whose result says what it writes:
/// [`declared_scene`], the one driver ([`Analysis::run`]), its files.
fn analysis_scene<T: Analysis>(
    catalog: Catalog,
    scene_name: &'static str,
    default_model: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError>
where
    T::Output: crate::study::Outputs,
{
    let (model, scene, options) = declared_scene::<T>(
        catalog,
        scene_name,
        (default_model, None),
        (T::default(), overrides),
        &[],
    )?;
    eprintln!("{} on {} …", T::ANALYSIS, model.info.name);
    let values = scene.parameter_values(model.info)?;
    let result = options
        .run(model, &values, &no_progress)
        .map_err(|e| e.located(model, &values))?;
    crate::study::write_outputs(&scene, &result)
}

/// Processes that share a tiled sweep (a chaos map, basins), such as the
/// ranks of `mpirun` (`mechlab-mpi`, a package of its own so that neither
/// the runtime nor the models are compiled again for it).
pub trait TileSharing {
    /// Runs `compute(share)` with this process's share of the `count`
    /// tiles; once every process has, one runs `merge()` (every tile on
    /// disk by then) while the others wait.
    fn run(
        &self,
        count: usize,
        compute: &dyn Fn(Vec<usize>) -> Result<(), SceneError>,
        merge: &dyn Fn() -> Result<(), SceneError>,
    ) -> Result<(), SceneError>;
}

/// A tiled sweep run by `sharing` or alone: `sweep` with the tiles `only`
/// (None: every missing tile, then the merge) returns whether it merged,
/// and writes the scene's files when it did.
fn share_tiles(
    scene: &Scene,
    sharing: Option<&dyn TileSharing>,
    tiles: Option<&mechlab_runtime::analysis::tiles::Tiles>,
    rows: usize,
    sweep: &dyn Fn(Option<Vec<usize>>) -> Result<bool, SceneError>,
) -> Result<(), SceneError> {
    let Some(sharing) = sharing else {
        let only = tiles.and_then(|t| t.only.clone());
        if !sweep(only)? {
            // A job of an array: its tiles are written, the last run merges.
            eprintln!("tiles {} written", scene.text("only_tiles"));
        }
        return Ok(());
    };
    let Some(tiles) = tiles else {
        return Err(SceneError::Inconsistent {
            knobs: "tile_rows",
            reason: "under mpirun the ranks share the map by tiles: set tile_rows > 0",
        });
    };
    let count = rows.div_ceil(tiles.rows.max(1));
    sharing.run(count, &|share| sweep(Some(share)).map(|_| ()), &|| {
        sweep(None).map(|_| ())
    })
}

/// The knobs `tile_rows` (default `rows`; 0: no tiles) and `only_tiles`
/// of a tiled sweep, read by [`tiles_from`].
fn tile_knobs(rows: &'static str) -> [Knob; 2] {
    [
        knob("tile_rows", rows, "rows per tile, each written to out/<scene>.tiles/ when done so a rerun resumes (0: no tiles)"),
        knob("only_tiles", "all", "compute only these tiles (comma-separated indices, a job of an array) and stop; all: every missing tile, then the result"),
    ]
}

/// The tiles of the knobs `size` (rows or columns per tile, 0 for none)
/// and `only` (`all`, or the indices of a job's tiles), in
/// `out/<scene>.tiles/` beside the scene's output folder.
pub fn tiles_from(
    scene: &Scene,
    [size, only]: [&str; 2],
) -> Result<Option<mechlab_runtime::analysis::tiles::Tiles>, SceneError> {
    let rows: usize = scene.get(
        size,
        Range::Count {
            min: 0,
            max: usize::MAX,
        },
    )?;
    if rows == 0 {
        return Ok(None);
    }
    let only = match scene.text(only) {
        "all" => None,
        _ => Some(scene.get::<Vec<usize>>(only, Range::Any)?),
    };
    Ok(Some(mechlab_runtime::analysis::tiles::Tiles {
        folder: scene.out.with_extension("tiles"),
        rows,
        only,
    }))
}

/// `first,last,count`: `count` values from `first` to `last` in geometric
/// progression, or why not.
fn geometric_progression(parts: &[f64]) -> Result<Vec<f64>, &'static str> {
    let [first, last, count] = parts[..] else {
        return Err("three numbers: first,last,count");
    };
    if !(first > 0.0 && last > 0.0 && count >= 2.0 && count.fract() == 0.0) {
        return Err("first and last positive, count a whole number ≥ 2");
    }
    let n = count as usize;
    Ok((0..n)
        .map(|k| first * (last / first).powf(k as f64 / (n - 1) as f64))
        .collect())
}
