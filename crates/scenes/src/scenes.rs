//! The bodies of the generic scenes, shared by the scene of that name and
//! the study scenes that are its presets (the same knobs with other
//! defaults, the same files): knobs → one library call → figures.

use crate::scene::{knob, parameter_knobs, Knob, Progress, Scene, SceneError, ValueProblem};
use mechlab_runtime::analysis::chaos_map::{
    chaos_map, ChaosMap, ChaosMapError, ChaosMapOptions, ChaosMapSettings,
};
use mechlab_runtime::ode::Method;
use mechlab_runtime::registry::{Catalog, Model};
use mechlab_runtime::settings::Declared;

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
            map => write_chaos_map(&scene, &map?).map(|()| true),
        }
    };
    let rows = settings.pixels;
    share_tiles(&scene, sharing, settings.tiles.as_ref(), rows, &sweep)
}

/// The chaos map's figures, CSV and summary.
fn write_chaos_map(scene: &Scene, map: &ChaosMap) -> Result<(), SceneError> {
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
    scene.write_summary(map)?;
    Ok(())
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
    if scene.number(size)? == 0.0 {
        return Ok(None);
    }
    let only_name = only;
    let only = match scene.text(only_name) {
        "all" => None,
        _ => Some(
            scene
                .numbers(only_name)?
                .iter()
                .map(|k| {
                    (*k >= 0.0 && k.fract() == 0.0)
                        .then_some(*k as usize)
                        .ok_or_else(|| SceneError::BadValue {
                            name: only_name.into(),
                            value: scene.text(only_name).into(),
                            reason: ValueProblem::Requirement(
                                "tile indices are whole numbers from 0",
                            ),
                        })
                })
                .collect::<Result<_, _>>()?,
        ),
    };
    Ok(Some(mechlab_runtime::analysis::tiles::Tiles {
        folder: scene.out.with_extension("tiles"),
        rows: scene.count(size)?,
        only,
    }))
}

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
    scene.save_figure(&averaging_figure(&result), "convergence.png")?;
    scene.write_summary(&result)?;
    Ok(())
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

/// Max deviation against ν (log–log, with the fits) and ν × max deviation.
fn averaging_figure(
    result: &mechlab_runtime::analysis::averaging::AveragingConvergence,
) -> mechlab_runtime::plot::Figure {
    use mechlab_runtime::plot::{palette, Figure, PanelSpec};
    use mechlab_runtime::registry::display_name;
    let range = |values: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = values
            .filter(|v| *v > 0.0)
            .fold((f64::MAX, 0.0f64), |(l, h), v| (l.min(v), h.max(v)));
        (lo / 1.5, hi * 1.5)
    };
    let x = range(&mut result.frequencies.iter().copied());
    let y = range(&mut result.max_deviation.iter().flatten().copied());
    // ν^order × deviation levels off where the deviation is c/ν^order.
    let order = result.order as i32;
    let scaled_of = |k: usize| -> Vec<(f64, f64)> {
        result
            .frequencies
            .iter()
            .zip(&result.max_deviation[k])
            .map(|(nu, d)| (*nu, d * nu.powi(order)))
            .collect()
    };
    let scaled = range(
        &mut (0..result.coordinates.len())
            .flat_map(scaled_of)
            .map(|p| p.1),
    );
    let title = format!(
        "{}: exact against averaged (order {order}), t ≤ {}",
        result.model, result.t_obs
    );
    let (power, scaled_title) = if order == 1 {
        (
            "ν × max deviation".to_string(),
            "ν × max deviation: levels off where the deviation is c/ν".to_string(),
        )
    } else {
        (
            format!("ν^{order} × max deviation"),
            format!("ν^{order} × max deviation: levels off where the deviation is c/ν^{order}"),
        )
    };
    let specs = [
        PanelSpec::new(
            &title,
            "frequency ν of the phase",
            "max |exact − averaged|",
            x,
            y,
        )
        .log_log(),
        PanelSpec::new(
            &scaled_title,
            "frequency ν of the phase",
            &power,
            x,
            (0.0, scaled.1),
        )
        .log_x(),
    ];
    let mut figure = Figure::grid(2, 1, 620, 460, &specs);
    let mut legend = Vec::new();
    for (k, coordinate) in result.coordinates.iter().enumerate() {
        let points: Vec<(f64, f64)> = result
            .frequencies
            .iter()
            .copied()
            .zip(result.max_deviation[k].iter().copied())
            .collect();
        figure.points(0, points.iter().copied(), palette(k), 4);
        let fit: Vec<(f64, f64)> = [x.0 * 1.5, x.1 / 1.5]
            .iter()
            .map(|nu| (*nu, result.level[k] * nu.powf(result.slope[k])))
            .collect();
        figure.line(0, &fit, palette(k));
        let scaled = scaled_of(k);
        figure.line(1, &scaled, palette(k));
        figure.points(1, scaled, palette(k), 4);
        legend.push((
            format!("{}: slope {:.3}", display_name(coordinate), result.slope[k]),
            palette(k),
        ));
    }
    figure.legend_at(0, &legend, true);
    figure.legend_at(1, &legend, true);
    figure
}

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
            result => write_basins(&scene, &result?).map(|()| true),
        }
    };
    let rows = settings.pixels;
    share_tiles(&scene, sharing, settings.tiles.as_ref(), rows, &sweep)
}

/// The basins' summary lines, figure, CSV and summary.
fn write_basins(
    scene: &Scene,
    result: &mechlab_runtime::analysis::basins::Basins,
) -> Result<(), SceneError> {
    for a in &result.attractors {
        let seen = if a.confirmed { "" } else { " (one start only)" };
        eprintln!(
            "{}: {:.4} ± {:.4} of the starts, at {:?}{seen}",
            a.kind, a.fraction, a.fraction_error, a.representative
        );
    }
    eprintln!("diverged: {}; {:.1} s", result.diverged, result.seconds);
    let boundary = &result.boundary;
    match (
        boundary.exponent,
        boundary.exponent_error,
        boundary.dimension,
    ) {
        (Some(alpha), Some(error), Some(dimension)) => eprintln!(
            "boundary: uncertainty exponent {alpha:.3} ± {error:.3}, box dimension {dimension:.3}"
        ),
        _ => eprintln!("boundary: {}", boundary.why_not.unwrap_or("not measured")),
    }
    scene.save_figure(&result.figure(), "basins.png")?;
    let n = result.pixels;
    let rows = result
        .labels
        .iter()
        .enumerate()
        .map(|(k, l)| (k % n, k / n, *l));
    scene.write_csv("basins.csv", &["column", "row", "attractor"], rows)?;
    scene.write_summary(result)?;
    Ok(())
}

/// The `linkage` scene: stabilisation by vibration of a constrained model
/// (the four-bar linkage held upside down by default): the averaged
/// equilibrium on the constraints, its thresholds, and the exact window.
pub fn linkage_scene(
    catalog: Catalog,
    scene_name: &'static str,
    overrides: &[(&'static str, &'static str)],
) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::on_constraints::vibration::{
        orbits_about, vibration_stability, LinkageOptions,
    };
    let orbit_knobs = [
        knob("orbits", "6", "orbits about the equilibrium (0: none)"),
        knob(
            "kick",
            "0.6",
            "the largest kick in the first coordinate's velocity",
        ),
        knob("periods", "300", "periods of the fast phase per orbit"),
    ];
    let (model, scene, options) = declared_scene::<LinkageOptions>(
        catalog,
        scene_name,
        ("four_bar", None),
        (LinkageOptions::default(), overrides),
        &orbit_knobs,
    )?;
    let info = model.info;
    let constrained = model.constrained.ok_or(SceneError::BadValue {
        name: "model".into(),
        value: info.name.into(),
        reason: ValueProblem::Requirement("a model with [[constraints]] in its file"),
    })?;
    let settings = options.resolve()?;
    let result = vibration_stability(constrained, &scene.parameter_values(info)?, &settings)?;
    println!(
        "{}: equilibrium q* = {:?}, averaged ω² = {:?} ({}); thresholds in {}: {:?}",
        info.name,
        result.equilibrium,
        result.squared_frequencies,
        if result.averaged_stable {
            "stable"
        } else {
            "unstable"
        },
        result.amplitude,
        result.averaged_thresholds
    );
    println!("exact: {:?}", result.exact);
    scene.save_figure(&result.figure(), "linkage.png")?;
    let count = scene.whole("orbits")?;
    if count > 0 {
        let params = scene.parameter_values(info)?;
        let shape = (count, scene.positive("kick")?, scene.count("periods")?);
        let orbits = orbits_about(
            constrained,
            &params,
            &result.equilibrium,
            shape,
            settings.method,
        )?;
        scene.save_figure(&orbits.figure(), "orbits.png")?;
    }
    let rows = result.scan.iter().map(|p| {
        (
            p.amplitude,
            p.lowest_squared_frequency,
            p.largest_modulus.unwrap_or(f64::NAN),
        )
    });
    scene.write_csv(
        "scan.csv",
        &[
            result.amplitude.as_str(),
            "lowest_omega2",
            "largest_modulus",
        ],
        rows,
    )?;
    scene.write_summary(&result)?;
    Ok(())
}

/// The `stability` scene: stabilisation by vibration of any model's
/// equilibria (a constrained model's on its constraints: the `linkage`
/// scene), with `chart=x,y` the stability chart of one equilibrium in two
/// parameters.
pub fn stability_scene(catalog: Catalog) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::stability::{stability, StabilityOptions};
    let model = model_from_args(catalog, "kapitza")?;
    if model.constrained.is_some() {
        let overrides = [("model", model.info.name)];
        return linkage_scene(catalog, "stability", &overrides);
    }
    let (model, scene, options) = declared_scene::<StabilityOptions>(
        catalog,
        "stability",
        ("kapitza", None),
        (StabilityOptions::default(), &[]),
        &chart_knobs(),
    )?;
    let params = scene.parameter_values(model.info)?;
    let settings = options.resolve(model)?;
    let result = stability(model, &params, &settings)?;
    for line in result.report(32) {
        eprintln!("{line}");
    }
    scene.write_csv(
        "spectral_radius.csv",
        &["equilibrium", "amplitude", "spectral_radius"],
        result.spectral_radius_rows(),
    )?;
    if let Some(figure) = result.figure() {
        scene.save_figure(&figure, "spectral_radius.png")?;
    }
    if scene.text("chart") != "none" && !write_chart(&scene, model, &params, &settings)? {
        return Ok(());
    }
    scene.write_summary(&result)?;
    Ok(())
}

/// The stability chart's knobs.
fn chart_knobs() -> Vec<Knob> {
    vec![
        knob("chart", "none", "two parameters x,y for a stability chart of the equilibrium chart_q (none: no chart)"),
        knob("chart_q", "0", "the equilibrium of the chart, comma-separated (0: all coordinates zero)"),
        knob("chart_x", "0.02,0.5,40", "first, last value and count of x"),
        knob("chart_y_max", "12", "y is sampled on (0, chart_y_max]"),
        knob("chart_y_samples", "120", "samples of y that bracket the boundaries"),
        knob("chart_tile_columns", "4", "chart columns per tile, each written to out/stability.tiles/ when done so a rerun resumes (0: no tiles)"),
        knob("chart_only_tiles", "all", "compute only these chart tiles (comma-separated indices, a job of an array) and stop; all: every missing tile, then the chart"),
    ]
}

/// The stability chart of the chart knobs, its figure, table and
/// `chart.json`; false for a job of an array whose tiles are written.
fn write_chart(
    scene: &Scene,
    model: &Model,
    params: &[f64],
    settings: &mechlab_runtime::analysis::stability::Settings,
) -> Result<bool, SceneError> {
    use mechlab_runtime::analysis::stability::{stability_chart, ChartSettings, StabilityError};
    let bad = |name: &str, reason: &'static str| SceneError::BadValue {
        name: name.into(),
        value: scene.text(name).into(),
        reason: ValueProblem::Requirement(reason),
    };
    let Some((x, y)) = scene.text("chart").split_once(',') else {
        return Err(bad("chart", "two parameter names x,y"));
    };
    let [first, last, count] = scene.numbers("chart_x")?[..] else {
        return Err(bad("chart_x", "first,last,count"));
    };
    if !(count >= 2.0 && count.fract() == 0.0) {
        return Err(bad("chart_x", "a whole count of at least 2"));
    }
    let n = count as usize;
    let chart_settings = ChartSettings {
        q: if scene.text("chart_q") == "0" {
            vec![0.0; model.info.coordinates.len()]
        } else {
            scene.numbers("chart_q")?
        },
        x: x.trim().into(),
        x_values: (0..n)
            .map(|k| first + (last - first) * k as f64 / (n - 1) as f64)
            .collect(),
        y: y.trim().into(),
        y_max: scene.positive("chart_y_max")?,
        y_samples: scene.count("chart_y_samples")?,
        edge_tolerance: settings.edge_tolerance,
        method: settings.method,
        tiles: tiles_from(scene, ["chart_tile_columns", "chart_only_tiles"])?,
    };
    let chart = match stability_chart(model, params, &chart_settings) {
        // A job of an array: its tiles are written, the last run draws.
        Err(StabilityError::Partial) => {
            eprintln!("chart tiles {} written", scene.text("chart_only_tiles"));
            return Ok(false);
        }
        chart => chart?,
    };
    scene.write_csv(
        "chart_boundaries.csv",
        &[chart.x.as_str(), chart.y.as_str()],
        chart.boundary_rows(),
    )?;
    scene.save_figure(&chart.figure(), "chart.png")?;
    let json = serde_json::to_string_pretty(&chart).map_err(|source| SceneError::Summary {
        scene: "stability",
        source,
    })?;
    scene.write_text("chart.json", &json)?;
    Ok(true)
}

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
    if !splitting.resolved {
        eprintln!(
            "the lobe area is not resolved to 1e-6: action {:?}, polygon {:?} (the manifolds split by little more than the precision tells)",
            splitting.lobe_area_action, splitting.lobe_area_polygon
        );
    }
    scene.save_figure(&splitting.figure(), "separatrix_splitting.png")?;
    let curves = [
        ("unstable", &splitting.unstable),
        ("stable", &splitting.stable),
        ("lobe", &splitting.lobe),
    ];
    let rows = curves
        .into_iter()
        .flat_map(|(curve, points)| points.iter().map(move |y| (curve, y[0], y[1])));
    scene.write_csv("manifolds.csv", &["curve", "q_lifted", "p"], rows)?;
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
            let values = geometric_progression(&scene.numbers("sweep")?).map_err(|reason| {
                SceneError::BadValue {
                    name: "sweep".into(),
                    value: scene.text("sweep").into(),
                    reason: ValueProblem::Requirement(reason),
                }
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

/// Scene `continuation`: the periodic orbits of a model's period map
/// followed in one parameter, their bifurcations, and the orbit diagram.
pub fn continuation_scene(catalog: Catalog) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::continuation::{continuation, ContinuationOptions};
    let drawn = knob(
        "coordinate",
        "0",
        "the state component drawn (0 = first coordinate; for a constrained model, of its chart)",
    );
    let (model, scene, options) = declared_scene::<ContinuationOptions>(
        catalog,
        "continuation",
        ("duffing", None),
        (ContinuationOptions::default(), &[]),
        &[drawn],
    )?;
    let params = scene.parameter_values(model.info)?;
    let settings = options.resolve(model, &params)?;
    let coordinate = scene.whole("coordinate")?;
    eprintln!("continuing in {} …", settings.parameter);
    let result = continuation(model, &params, &settings)?;
    // (A constrained model's states are its chart's coordinates.)
    let states = result.state_names.len();
    if coordinate >= states {
        return Err(SceneError::BadValue {
            name: "coordinate".into(),
            value: coordinate.to_string(),
            reason: ValueProblem::StateComponents(states),
        });
    }
    write_continuation(&scene, &result, coordinate)?;
    scene.write_summary(&result)?;
    Ok(())
}

/// The `continuation` scene's figure and tables (branches, bifurcations,
/// the orbit diagram), drawn in state component `coordinate`.
fn write_continuation(
    scene: &Scene,
    result: &mechlab_runtime::analysis::continuation::Continuation,
    coordinate: usize,
) -> Result<(), SceneError> {
    scene.save_figure(&result.figure(coordinate), "continuation.png")?;
    let rows = result.branches.iter().enumerate().flat_map(|(b, branch)| {
        branch.points.iter().map(move |p| {
            let radius = mechlab_runtime::analysis::floquet::spectral_radius(&p.multipliers);
            (
                b,
                branch.period,
                p.parameter,
                p.state[coordinate],
                radius,
                p.stable,
            )
        })
    });
    scene.write_csv(
        "branches.csv",
        &[
            "branch",
            "period",
            "parameter",
            "coordinate",
            "spectral_radius",
            "stable",
        ],
        rows,
    )?;
    scene.write_csv(
        "bifurcations.csv",
        &[
            "kind",
            "branch",
            "period",
            "parameter",
            "coordinate",
            "residual",
            "criticality",
        ],
        result.bifurcations.iter().map(|b| {
            (
                format!("{:?}", b.kind),
                b.branch,
                b.period,
                b.parameter,
                b.state[coordinate],
                b.residual,
                b.criticality.map_or(String::new(), |c| format!("{c:?}")),
            )
        }),
    )?;
    if let Some(d) = &result.diagram {
        scene.write_csv(
            "orbit_diagram.csv",
            &["parameter", "coordinate"],
            d.points.iter().map(|(p, y)| (*p, y[coordinate])),
        )?;
    }
    Ok(())
}

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
    write_frequency_map(&scene, &map)?;
    scene.write_summary(&map)?;
    Ok(())
}

/// A frequency map's summary line, figure and table.
fn write_frequency_map(
    scene: &Scene,
    map: &mechlab_runtime::analysis::frequency_map::FrequencyMap,
) -> Result<(), SceneError> {
    eprintln!(
        "{} orbits, {:.1} % regular, in {:.1} s",
        map.accessible,
        100.0 * map.regular_fraction,
        map.seconds
    );
    scene.save_figure(&map.figure(), "frequency_map.png")?;
    let pixels = map.pixels;
    let rows = (0..pixels * pixels).filter_map(|k| {
        let [nu1, nu2] = map.frequencies[k];
        nu1.is_finite()
            .then_some((k % pixels, k / pixels, nu1, nu2, map.diffusion[k]))
    });
    scene.write_csv(
        "frequency_map.csv",
        &["column", "row", "nu1", "nu2", "diffusion_index"],
        rows,
    )?;
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
