//! The analyses by name for Python: each resolves its settings from
//! keyword arguments (the scenes' defaults), runs the library's function
//! off the GIL, and returns its summary as a dict with its per-point data
//! as NumPy arrays.

use mechlab::analysis::chaos_map::{chaos_map as fli_map, ChaosMapSettings};
use mechlab::analysis::on_constraints::vibration::{vibration_stability, VibrationSettings};
use mechlab::analysis::period_map::{portrait as portrait_of, PortraitSettings};
use mechlab::analysis::section::{section_study, SectionOptions};
use mechlab::analysis::stability::{stability as stability_of, Settings};
use mechlab::ode::Method;
use mechlab::registry::Model;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::detached::{detached, progress};
use crate::errors::py_err;

/// `summary` (serde) as a dict.
fn summary<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyDict>> {
    Ok(pythonize::pythonize(py, value)?.cast_into::<PyDict>()?)
}

/// Points as an (n, 2) array.
fn points<'py>(
    py: Python<'py>,
    points: impl Iterator<Item = [f64; 2]>,
) -> Bound<'py, numpy::PyArray2<f64>> {
    let flat: Vec<f64> = points.flatten().collect();
    let rows = flat.len() / 2;
    Array2::from_shape_vec((rows, 2), flat)
        .expect("two numbers per point")
        .into_pyarray(py)
}

/// Orbits of the period map (the `period_map` scene).
pub fn portrait<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: PortraitSettings,
) -> PyResult<Bound<'py, PyDict>> {
    let result = detached(py, || portrait_of(model, &values, &settings))?.map_err(py_err)?;
    let dict = summary(py, &result)?;
    let orbits: Vec<_> = result
        .orbits
        .iter()
        .map(|o| points(py, o.iter().map(|&(x, y)| [x, y])))
        .collect();
    dict.set_item("orbits", orbits)?;
    dict.set_item("labels", result.labels.to_vec())?;
    Ok(dict)
}

/// The FLI map of the period map (the `chaos_map` scene), with a
/// progress bar by rows; Ctrl-C stops it between blocks of rows.
pub fn chaos_map<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: ChaosMapSettings,
    show_progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let pixels = settings.pixels;
    let bar = progress(pixels as u64, &format!("{} FLI map rows", model.info.name));
    if !show_progress {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let result = detached(py, || {
        fli_map(model, &values, &settings, &|| {
            bar.inc(1);
            !mechlab::ode::stop::stop_requested()
        })
    })?
    .map_err(py_err)?;
    bar.finish_and_clear();
    let dict = summary(py, &result)?;
    let image = Array2::from_shape_vec((pixels, pixels), result.fli.clone())
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    dict.set_item("fli", image.into_pyarray(py))?;
    dict.set_item("labels", result.labels.to_vec())?;
    Ok(dict)
}

/// A constrained model's stabilisation on its constraints (the `linkage`
/// scene).
pub fn linkage<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: VibrationSettings,
) -> PyResult<Bound<'py, PyDict>> {
    let Some(constrained) = model.constrained else {
        return Err(py_err(mechlab::analysis::Refusal::Setting {
            model: model.info.name.into(),
            requirement: "linkage runs on a model with [[constraints]] in its file (`stability` on the others)",
        }));
    };
    let result =
        detached(py, || vibration_stability(constrained, &values, &settings))?.map_err(py_err)?;
    summary(py, &result)
}

/// Stabilisation by vibration (the `stability` scene): thresholds a*
/// and exact windows of a model's equilibria.
pub fn stability<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: Settings,
) -> PyResult<Bound<'py, PyDict>> {
    let result = detached(py, || stability_of(model, &values, &settings))?.map_err(py_err)?;
    let dict = summary(py, &result)?;
    dict.set_item("report", result.report(usize::MAX))?;
    Ok(dict)
}

/// A Poincaré section at a fixed energy (the `section` scene): the
/// scene's summary, each orbit's points as an (n, 2) array, the MEGNO map
/// as an image `megno`, the frequency map's tunes and diffusion index as
/// images.
pub fn section<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    options: SectionOptions,
) -> PyResult<Bound<'py, PyDict>> {
    let study =
        detached(py, || section_study(model, &values, &options, &|_| ()))?.map_err(py_err)?;
    let dict = PyDict::new(py);
    let section = match &study.section {
        None => None,
        Some(section) => {
            let orbits = summary(py, section)?;
            let points: Vec<_> = section
                .orbits
                .iter()
                .map(|o| points(py, o.points.iter().copied()))
                .collect();
            orbits.set_item("points", points)?;
            Some(orbits)
        }
    };
    dict.set_item("section", section)?;
    let megno = match &study.megno_map {
        None => None,
        Some(map) => {
            let pixels = map.pixels;
            let summary = summary(py, map)?;
            let image = Array2::from_shape_vec((pixels, pixels), map.megno.clone())
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            summary.set_item("megno", image.into_pyarray(py))?;
            Some(summary)
        }
    };
    dict.set_item("megno_map", megno)?;
    let frequency_map = match &study.frequency_map {
        None => None,
        Some(map) => Some(frequencies(py, map)?),
    };
    dict.set_item("frequency_map", frequency_map)?;
    Ok(dict)
}

/// The attractor of a forced, damped period map (the `attractor`
/// scene): its points as an (n, 2) array, the Lyapunov spectrum and the
/// dimensions.
pub fn attractor<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: mechlab::analysis::attractor::AttractorSettings,
) -> PyResult<Bound<'py, PyDict>> {
    use mechlab::analysis::attractor::attractor as attractor_of;
    let result = detached(py, || attractor_of(model, &values, &settings))?.map_err(py_err)?;
    let dict = summary(py, &result)?;
    dict.set_item("orbit", points(py, result.orbit.iter().copied()))?;
    let convergence: Vec<(usize, Vec<f64>)> = result.convergence.clone();
    dict.set_item("convergence", convergence)?;
    Ok(dict)
}

/// Periodic orbits continued in a parameter with their bifurcations (the
/// `continuation` scene).
pub fn continuation<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: mechlab::analysis::continuation::ContinuationSettings,
) -> PyResult<Bound<'py, PyDict>> {
    use mechlab::analysis::continuation::continuation as continuation_of;
    let result = detached(py, || continuation_of(model, &values, &settings))?.map_err(py_err)?;
    let dict = summary(py, &result)?;
    dict.set_item("state_names", result.state_names.clone())?;
    Ok(dict)
}

/// The splitting of the separatrices of the period map's saddle (the
/// `separatrix_splitting` scene): lobe areas by two routes.
pub fn separatrix_splitting<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: mechlab::analysis::separatrix::SplittingSettings,
) -> PyResult<Bound<'py, PyDict>> {
    use mechlab::analysis::separatrix::separatrix_splitting as splitting_of;
    let result = detached(py, || splitting_of(model, &values, &settings))?.map_err(py_err)?;
    summary(py, &result)
}

/// The exact system against the averaged one as the phase's rate grows
/// (the `averaging` scene): the deviation's slope against the frequency.
pub fn averaging<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: mechlab::analysis::averaging::ConvergenceSettings,
) -> PyResult<Bound<'py, PyDict>> {
    use mechlab::analysis::averaging::convergence;
    let result = detached(py, || convergence(model, &values, &settings))?.map_err(py_err)?;
    summary(py, &result)
}

/// Rows of numbers as a 2-D array (NaN-padded if ragged).
fn table<'py>(py: Python<'py>, rows: &[Vec<f64>]) -> Bound<'py, numpy::PyArray2<f64>> {
    let width = rows.iter().map(Vec::len).max().unwrap_or(0);
    let mut array = Array2::from_elem((rows.len(), width), f64::NAN);
    for (i, row) in rows.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            array[(i, j)] = *x;
        }
    }
    array.into_pyarray(py)
}

/// What the `explore` scene shows, for any model (a contact model with its
/// stick–slip switching too): the run, the averaged run and the period
/// map where there is a fast phase, the energy's change, the equilibria,
/// a constrained model's reactions.
pub fn explore<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    y0: Vec<f64>,
    settings: mechlab::explore::Settings,
) -> PyResult<Bound<'py, PyDict>> {
    let result = detached(py, || {
        mechlab::explore::explore(model, &values, &y0, &settings)
    })?
    .map_err(py_err)?;
    let dict = PyDict::new(py);
    dict.set_item("times", result.times.clone().into_pyarray(py))?;
    dict.set_item("states", table(py, &result.exact))?;
    if let Some(averaged) = &result.averaged {
        dict.set_item("averaged", table(py, averaged))?;
    }
    if let Some(map) = &result.period_map {
        dict.set_item("period_map", table(py, map))?;
    }
    dict.set_item(
        "energy_change",
        result.energy_change.clone().into_pyarray(py),
    )?;
    dict.set_item("energy_label", result.energy_label)?;
    dict.set_item("equilibria", pythonize::pythonize(py, &result.equilibria)?)?;
    dict.set_item("switches", result.switches.clone())?;
    if let Some(reactions) = &result.reactions {
        dict.set_item("reaction_names", reactions.names.clone())?;
        dict.set_item("reactions", table(py, &reactions.values))?;
    }
    Ok(dict)
}

/// The iterates of the period map from many starts (the Taylor method in
/// the batch lanes): `iterates[k, i]` is start k's state after
/// transient + 1 + i periods, NaN for an orbit that stopped.
pub fn iterates<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    starts: Vec<Vec<f64>>,
    transient: usize,
    record: usize,
    method: Method,
) -> PyResult<Bound<'py, numpy::PyArray3<f64>>> {
    use mechlab::analysis::period_map::iterates_of_starts;
    let bar = progress(starts.len() as u64, &format!("{} orbits", model.info.name));
    let runs = detached(py, || {
        iterates_of_starts(model, &values, method, &starts, transient, record, &|k| {
            bar.inc(k as u64)
        })
    })?
    .map_err(py_err)?;
    bar.finish_and_clear();
    let dim = starts.first().map_or(0, Vec::len);
    let mut array = numpy::ndarray::Array3::from_elem((starts.len(), record, dim), f64::NAN);
    for (k, run) in runs.iter().enumerate() {
        for (i, y) in run.iter().flatten().enumerate().take(record) {
            for (j, x) in y.iter().enumerate().take(dim) {
                array[(k, i, j)] = *x;
            }
        }
    }
    Ok(array.into_pyarray(py))
}

/// The basins of attraction of a period map's attractors on a plane of
/// starts (the `basins` scene): `labels[j, i]` the attractor of each
/// pixel (row 0 at the bottom; −1 diverged), each attractor's points.
pub fn basins<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: mechlab::analysis::basins::BasinSettings,
    show_progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use mechlab::analysis::basins::basins as basins_of;
    let pixels = settings.pixels;
    let bar = progress(
        (pixels * pixels) as u64,
        &format!("{} basins starts", model.info.name),
    );
    if !show_progress {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let result = detached(py, || {
        basins_of(model, &values, &settings, &|k| bar.inc(k as u64))
    })?
    .map_err(py_err)?;
    bar.finish_and_clear();
    let dict = summary(py, &result)?;
    let labels = Array2::from_shape_vec((pixels, pixels), result.labels.clone())
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    dict.set_item("labels", labels.into_pyarray(py))?;
    let attractor_points: Vec<_> = result
        .points
        .iter()
        .map(|p| points(py, p.iter().copied()))
        .collect();
    dict.set_item("points", attractor_points)?;
    Ok(dict)
}

/// A frequency map's summary with its tunes (ν₁, ν₂ as two images) and
/// diffusion index per pixel.
fn frequencies<'py>(
    py: Python<'py>,
    map: &mechlab::analysis::frequency_map::FrequencyMap,
) -> PyResult<Bound<'py, PyDict>> {
    let pixels = map.pixels;
    let dict = summary(py, map)?;
    let image = |f: &dyn Fn(usize) -> f64| {
        Array2::from_shape_fn((pixels, pixels), |(j, i)| f(j * pixels + i)).into_pyarray(py)
    };
    dict.set_item("nu1", image(&|k| map.frequencies[k][0]))?;
    dict.set_item("nu2", image(&|k| map.frequencies[k][1]))?;
    dict.set_item("diffusion", image(&|k| map.diffusion[k]))?;
    Ok(dict)
}

/// The frequency map of a period map on a plane of starts (the
/// `frequency_map` scene on a model with a fast phase), with a progress bar.
pub fn period_map_frequencies<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    settings: ChaosMapSettings,
    show_progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use mechlab::analysis::frequency_map::period_map_frequencies as frequencies_of;
    let pixels = settings.pixels;
    let bar = progress(
        (pixels * pixels) as u64,
        &format!("{} frequency map orbits", model.info.name),
    );
    if !show_progress {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let result = detached(py, || {
        frequencies_of(model, &values, &settings, &|k| bar.inc(k as u64))
    })?
    .map_err(py_err)?;
    bar.finish_and_clear();
    frequencies(py, &result)
}
