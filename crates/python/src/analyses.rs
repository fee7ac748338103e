//! The analyses by name for Python: each resolves its settings from
//! keyword arguments (the scenes' defaults), runs the library's function
//! off the GIL, and returns its summary as a dict with its per-point data
//! as NumPy arrays.

use mechlab::analysis::chaos_map::{chaos_map as fli_map, ChaosMapSettings};
use mechlab::analysis::on_constraints::vibration::{vibration_stability, VibrationSettings};
use mechlab::analysis::period_map::{portrait as portrait_of, PortraitSettings};
use mechlab::analysis::section::{
    parse_plane, section as section_of, seeds_across, SectionSettings,
};
use mechlab::analysis::stability::{stability as stability_of, Settings, MAX_WINDOWS};
use mechlab::ode::Method;
use mechlab::registry::Model;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::detached::{detached, progress};
use crate::errors::{py_err, Class, Classify};

/// A state component by index or by name (raw, "p_phi", or as the
/// figures write it, "p_φ").
#[derive(FromPyObject)]
pub enum Axis {
    Index(usize),
    Name(String),
}

/// The two state components of a plane; None: the first coordinate and
/// its momentum (or velocity), as the scenes' `axes=auto`.
pub fn axes(model: &Model, given: Option<(Axis, Axis)>) -> PyResult<[usize; 2]> {
    let info = model.info;
    let n = info.coordinates.len();
    let Some((a, b)) = given else {
        return Ok([0, n]);
    };
    let names = info.state_names();
    let index = |axis: Axis| match axis {
        Axis::Index(i) if i < 2 * n => Ok(i),
        Axis::Name(name) => (0..2 * n)
            .find(|&i| names[i] == name || info.label(i) == name)
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "model '{}' has no state component '{name}' (known: {})",
                    info.name,
                    names.join(", ")
                ))
            }),
        Axis::Index(i) => Err(PyValueError::new_err(format!(
            "model '{}' has {} state components: index {i} is past them",
            info.name,
            2 * n
        ))),
    };
    Ok([index(a)?, index(b)?])
}

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
#[allow(clippy::too_many_arguments)]
pub fn portrait<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    axes: [usize; 2],
    seeds: Option<Vec<Vec<f64>>>,
    count: usize,
    p_max: f64,
    periods: usize,
    method: Method,
) -> PyResult<Bound<'py, PyDict>> {
    let settings = PortraitSettings {
        axes,
        seeds,
        count,
        p_max,
        periods,
        method,
    };
    let result = detached(py, |_| portrait_of(model, &values, &settings))?.map_err(py_err)?;
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
#[allow(clippy::too_many_arguments)]
pub fn chaos_map<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    axes: [usize; 2],
    ranges: [Option<(f64, f64)>; 2],
    through: Option<Vec<f64>>,
    pixels: usize,
    periods: usize,
    p_max: f64,
    method: Method,
    show_progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let settings = ChaosMapSettings {
        axes,
        ranges,
        p_max,
        through,
        pixels,
        periods,
        method,
        tiles: None,
    };
    let bar = progress(pixels as u64, &format!("{} FLI map rows", model.info.name));
    if !show_progress {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let result = detached(py, |stop| {
        fli_map(model, &values, &settings, &|| {
            bar.inc(1);
            !stop.requested()
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

/// Why a constrained model's stabilisation cannot be computed.
impl Classify for mechlab::analysis::on_constraints::vibration::VibrationError {
    fn class(&self) -> Class {
        use mechlab::analysis::on_constraints::vibration::VibrationError;
        match self {
            VibrationError::Refused(r) => r.class(),
            _ => Class::Integration,
        }
    }
}

/// Stabilisation by vibration (the `stability` scene): thresholds a*
/// and exact windows of a model's equilibria, or for a constrained model
/// the `linkage` analysis of its equilibrium near the start.
#[allow(clippy::too_many_arguments)]
pub fn stability<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    amplitude: Option<String>,
    samples: usize,
    a_max: Option<f64>,
    edge_tolerance: f64,
    method: Method,
    max_windows: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(constrained) = model.constrained {
        let settings = VibrationSettings {
            amplitude,
            max_amplitude: a_max,
            start: None,
            scan: samples,
            method,
        };
        let result = detached(py, |_| vibration_stability(constrained, &values, &settings))?
            .map_err(py_err)?;
        return summary(py, &result);
    }
    let Some(amplitude) = amplitude.or(model.info.amplitude.map(String::from)) else {
        return Err(crate::errors::Refused::new_err(format!(
            "model '{}' names no amplitude ([fast_phase] amplitude in its file): pass amplitude='<parameter>'",
            model.info.name
        )));
    };
    let settings = Settings {
        amplitude,
        a_max,
        samples,
        edge_tolerance,
        method,
        max_windows: max_windows.unwrap_or(MAX_WINDOWS),
    };
    let result = detached(py, |_| stability_of(model, &values, &settings))?.map_err(py_err)?;
    let dict = summary(py, &result)?;
    dict.set_item("report", result.report(usize::MAX))?;
    Ok(dict)
}

/// What a section is asked for: the plane and the orbits.
pub struct SectionRequest {
    pub energy: f64,
    pub plane: Option<String>,
    pub value: f64,
    pub rising: bool,
    pub seeds: Option<Vec<[f64; 2]>>,
    pub orbits: usize,
    pub extent: f64,
    pub crossings: usize,
    pub t_max: f64,
    pub tol: f64,
}

/// A Poincaré section at a fixed energy (the `section` scene): each
/// orbit's points on the plane as an (n, 2) array.
pub fn section<'py>(
    py: Python<'py>,
    model: &'static Model,
    values: Vec<f64>,
    request: SectionRequest,
) -> PyResult<Bound<'py, PyDict>> {
    let info = model.info;
    let plane_text = request
        .plane
        .unwrap_or_else(|| info.coordinates[0].to_string());
    let settings = SectionSettings {
        plane: parse_plane(&plane_text, info.coordinates)
            .map_err(|e| PyValueError::new_err(e.to_string()))?,
        value: request.value,
        rising: request.rising,
        energy: request.energy,
        crossings: request.crossings,
        t_max: request.t_max,
        tol: request.tol,
        phase: 0.0,
        slab: 0.05,
    };
    let result = detached(py, |_| {
        let seeds = request.seeds.clone().unwrap_or_else(|| {
            seeds_across(model, &values, &settings, request.extent, request.orbits)
        });
        section_of(model, &values, &seeds, &settings)
    })?
    .map_err(py_err)?;
    let dict = summary(py, &result)?;
    let orbits: Vec<_> = result
        .orbits
        .iter()
        .map(|o| points(py, o.points.iter().copied()))
        .collect();
    dict.set_item("points", orbits)?;
    Ok(dict)
}
