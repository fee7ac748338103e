//! The analyses by name for Python: each resolves its settings from
//! keyword arguments (the scenes' defaults), runs the library's function
//! off the GIL, and returns its summary as a dict with its per-point data
//! as NumPy arrays.

use std::collections::BTreeMap;

use mechlab::analysis::attractor::Attractor;
use mechlab::analysis::basins::Basins;
use mechlab::analysis::chaos_map::{ChaosMap, ChaosMapSettings};
use mechlab::analysis::continuation::Continuation;
use mechlab::analysis::declared::Analysis;
use mechlab::analysis::on_constraints::steady::study::SteadyStudy;
use mechlab::analysis::on_constraints::vibration::Linkage;
use mechlab::analysis::period_map::Portrait;
use mechlab::analysis::section::SectionStudy;
use mechlab::analysis::stability::Stability;
use mechlab::explore::Exploration;
use mechlab::ode::Method;
use mechlab::registry::Model;
use mechlab::settings::Declared;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::detached::{detached, progress};
use crate::errors::py_err;

/// `summary` (serde) as a dict.
pub fn summary<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyDict>> {
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

/// A declared analysis's settings from keyword arguments (by the names of
/// its declaration; `base`'s values where not given), checked by the
/// declaration.
pub fn declared_from<T: Declared>(base: T, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<T> {
    let given: serde_json::Map<String, serde_json::Value> = match kwargs {
        Some(kwargs) => pythonize::depythonize(kwargs)?,
        None => serde_json::Map::new(),
    };
    base.with_json(&given).map_err(py_err)
}

/// Declared analysis `T` run with the keyword `settings`, off the GIL,
/// with a progress bar where it counts its work and `show` asks for one;
/// Ctrl-C stops it.
pub fn run<T: Analysis>(
    py: Python<'_>,
    model: &'static Model,
    params: Option<BTreeMap<String, f64>>,
    settings: Option<&Bound<'_, PyDict>>,
    show: bool,
) -> PyResult<T::Output> {
    let values = model
        .values_with(&params.unwrap_or_default())
        .map_err(py_err)?;
    let options: T = declared_from(T::default(), settings)?;
    let label = format!("{} {}", model.info.name, T::ANALYSIS);
    let bar = progress(options.work() as u64, &label);
    if !show || options.work() == 0 {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let result = detached(py, || {
        options
            .run(model, &values, &|k| {
                bar.inc(k as u64);
                !mechlab::ode::stop::stop_requested()
            })
            .map_err(|e| e.located(model, &values))
    })?
    .map_err(py_err)?;
    bar.finish_and_clear();
    Ok(result)
}

/// A period map's portrait: each orbit as an (n, 2) array.
pub fn portrait<'py>(py: Python<'py>, result: &Portrait) -> PyResult<Bound<'py, PyDict>> {
    let dict = summary(py, result)?;
    let orbits: Vec<_> = result
        .orbits
        .iter()
        .map(|o| points(py, o.iter().map(|&(x, y)| [x, y])))
        .collect();
    dict.set_item("orbits", orbits)?;
    dict.set_item("labels", result.labels.to_vec())?;
    Ok(dict)
}

/// The FLI map as an image `fli`.
pub fn chaos_map<'py>(py: Python<'py>, result: &ChaosMap) -> PyResult<Bound<'py, PyDict>> {
    let pixels = result.pixels;
    let dict = summary(py, result)?;
    let image = Array2::from_shape_vec((pixels, pixels), result.fli.clone())
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    dict.set_item("fli", image.into_pyarray(py))?;
    dict.set_item("labels", result.labels.to_vec())?;
    Ok(dict)
}

/// Stabilisation on the constraints, with the orbits about the
/// equilibrium (`orbits` and `averaged_orbits`, each an (n, 2) array).
pub fn linkage<'py>(py: Python<'py>, result: &Linkage) -> PyResult<Bound<'py, PyDict>> {
    let dict = summary(py, result)?;
    if let Some(orbits) = &result.orbits {
        let arrays = |runs: &[Vec<(f64, f64)>]| -> Vec<_> {
            let pairs =
                |run: &Vec<(f64, f64)>| run.iter().map(|&(x, y)| [x, y]).collect::<Vec<_>>();
            runs.iter()
                .map(|run| points(py, pairs(run).into_iter()))
                .collect()
        };
        dict.set_item("orbits", arrays(&orbits.exact))?;
        dict.set_item("averaged_orbits", arrays(&orbits.averaged))?;
    }
    Ok(dict)
}

/// A steady motion's linearisation: its summary, with `matrix` the
/// linearisation as an array and, with a sweep, `sweep_eigenvalues` as a
/// (speeds, eigenvalues) complex array.
pub fn steady_motion<'py>(py: Python<'py>, result: &SteadyStudy) -> PyResult<Bound<'py, PyDict>> {
    let dict = summary(py, result)?;
    let m = &result.motion.matrix;
    let matrix = Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]);
    dict.set_item("matrix", matrix.into_pyarray(py))?;
    if let Some(sweep) = &result.sweep {
        let width = sweep.eigenvalues.iter().map(Vec::len).max().unwrap_or(0);
        let values = Array2::from_shape_fn((sweep.speeds.len(), width), |(k, j)| {
            sweep.eigenvalues[k]
                .get(j)
                .map_or(numpy::Complex64::new(f64::NAN, f64::NAN), |&(re, im)| {
                    numpy::Complex64::new(re, im)
                })
        });
        dict.set_item("sweep_eigenvalues", values.into_pyarray(py))?;
    }
    Ok(dict)
}

/// Stabilisation by vibration with its text report.
pub fn stability<'py>(py: Python<'py>, result: &Stability) -> PyResult<Bound<'py, PyDict>> {
    let dict = summary(py, result)?;
    dict.set_item("report", result.report(usize::MAX))?;
    Ok(dict)
}

/// A section study: each orbit's points as an (n, 2) array, the MEGNO
/// map as an image `megno`, the frequency map's tunes and diffusion
/// index as images.
pub fn section<'py>(py: Python<'py>, study: &SectionStudy) -> PyResult<Bound<'py, PyDict>> {
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

/// An attractor: its points as an (n, 2) array, the Lyapunov spectrum's
/// convergence.
pub fn attractor<'py>(py: Python<'py>, result: &Attractor) -> PyResult<Bound<'py, PyDict>> {
    let dict = summary(py, result)?;
    dict.set_item("orbit", points(py, result.orbit.iter().copied()))?;
    dict.set_item("convergence", result.convergence.clone())?;
    Ok(dict)
}

/// A continuation with the names of the state's components.
pub fn continuation<'py>(py: Python<'py>, result: &Continuation) -> PyResult<Bound<'py, PyDict>> {
    let dict = summary(py, result)?;
    dict.set_item("state_names", result.state_names.clone())?;
    Ok(dict)
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
pub fn explore<'py>(py: Python<'py>, result: &Exploration) -> PyResult<Bound<'py, PyDict>> {
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

/// Basins: `labels[j, i]` the attractor of each pixel (row 0 at the
/// bottom; −1 diverged), each attractor's points.
pub fn basins<'py>(py: Python<'py>, result: &Basins) -> PyResult<Bound<'py, PyDict>> {
    let pixels = result.pixels;
    let dict = summary(py, result)?;
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
