//! `mechlab._native`: the generated models of `models/` and their analyses
//! for Python, NumPy arrays in and out. Each call resolves the model's
//! parameters by name (checked against their ranges), runs one library
//! function off the GIL (`detached`), and returns arrays or the analysis's
//! summary as a dict (the same fields a scene writes to summary.json), its
//! per-point data as arrays. The package `mechlab` (python/mechlab) wraps
//! the dicts as attribute-access results.

mod analyses;
mod detached;
mod errors;

use std::collections::BTreeMap;

use mechlab::analysis::attractor::AttractorOptions;
use mechlab::analysis::averaging::AveragingOptions;
use mechlab::analysis::basins::BasinsOptions;
use mechlab::analysis::chaos_map::ChaosMapOptions;
use mechlab::analysis::continuation::ContinuationOptions;
use mechlab::analysis::declared::Analysis;
use mechlab::analysis::on_constraints::steady::study::SteadyMotionOptions;
use mechlab::analysis::on_constraints::vibration::LinkageOptions;
use mechlab::analysis::period_map::PeriodMapOptions;
use mechlab::analysis::section::SectionOptions;
use mechlab::analysis::separatrix::SplittingOptions;
use mechlab::analysis::stability::StabilityOptions;
use mechlab::analysis::states::{states_at, states_of_starts, IntegrateOptions, IteratesOptions};
use mechlab::explore::ExploreOptions;
use mechlab::registry::{Kind, Model};
use numpy::ndarray::{Array2, Array3};
use numpy::{AllowTypeChange, IntoPyArray, PyArray2, PyArrayLike1, PyArrayLike2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use detached::detached;
use errors::py_err;

/// The names of the models (the files models/<name>.toml).
#[pyfunction]
fn models() -> Vec<&'static str> {
    mechlab::models::MODELS
        .iter()
        .map(|m| m.info.name)
        .collect()
}

/// The model `name`; a ValueError lists the known ones.
#[pyfunction]
fn model(name: &str) -> PyResult<PyModel> {
    mechlab::models::by_name(name)
        .map(|model| PyModel { model })
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// One derived expression: its key, what it is, its text and LaTeX.
#[pyclass(frozen, name = "Derivation", module = "mechlab")]
struct PyDerivation {
    #[pyo3(get)]
    key: &'static str,
    #[pyo3(get)]
    description: &'static str,
    #[pyo3(get)]
    text: &'static str,
    #[pyo3(get)]
    latex: &'static str,
}

#[pymethods]
impl PyDerivation {
    fn __repr__(&self) -> String {
        format!("{} = {}", self.key, self.text)
    }
    fn _repr_latex_(&self) -> String {
        format!("$${}$$", self.latex)
    }
}

/// A model's derivations, shown in Jupyter as one aligned block.
#[pyclass(frozen, name = "Derivations", module = "mechlab", sequence)]
struct PyDerivations {
    model: &'static Model,
}

#[pymethods]
impl PyDerivations {
    fn __len__(&self) -> usize {
        self.model.info.derivations.len()
    }
    fn __getitem__(&self, index: isize) -> PyResult<PyDerivation> {
        let all = self.model.info.derivations;
        let i = if index < 0 {
            all.len() as isize + index
        } else {
            index
        };
        let d = usize::try_from(i)
            .ok()
            .and_then(|i| all.get(i))
            .ok_or_else(|| {
                pyo3::exceptions::PyIndexError::new_err("derivation index out of range")
            })?;
        Ok(PyDerivation {
            key: d.key,
            description: d.description,
            text: d.text,
            latex: d.latex,
        })
    }
    fn __repr__(&self) -> String {
        let lines: Vec<String> = self
            .model
            .info
            .derivations
            .iter()
            .map(|d| format!("{} = {}", d.key, d.text))
            .collect();
        lines.join("\n")
    }
    fn _repr_latex_(&self) -> String {
        let rows: Vec<String> = self
            .model
            .info
            .derivations
            .iter()
            .map(|d| {
                format!(
                    "&\\text{{{}}}: && {} \\\\",
                    d.description.replace('_', "\\_"),
                    d.latex
                )
            })
            .collect();
        format!(
            "$$\\begin{{aligned}}\n{}\n\\end{{aligned}}$$",
            rows.join("\n")
        )
    }
}

/// A generated model: what it is, its parameters, its derivations, and
/// the analyses by name.
#[pyclass(frozen, name = "Model", module = "mechlab")]
struct PyModel {
    model: &'static Model,
}

#[pymethods]
impl PyModel {
    #[getter]
    fn name(&self) -> &'static str {
        self.model.info.name
    }
    /// "hamiltonian", "constrained" or "contact".
    #[getter]
    fn kind(&self) -> &'static str {
        match (self.model.constrained, self.model.dynamic.kind()) {
            (Some(_), _) => "constrained",
            (None, Kind::Hamiltonian { .. }) => "hamiltonian",
            (None, _) => "contact",
        }
    }
    #[getter]
    fn fast_phase(&self) -> bool {
        self.model.info.rate_parameter.is_some()
            || self.model.flows().is_some_and(|f| f.has_fast_phase())
    }
    #[getter]
    fn coordinates(&self) -> Vec<&'static str> {
        self.model.info.coordinates.to_vec()
    }
    /// The state's components in the figures' notation (φ, p_φ, φ′).
    #[getter]
    fn state_names(&self) -> Vec<String> {
        let info = self.model.info;
        (0..2 * info.coordinates.len())
            .map(|i| info.label(i))
            .collect()
    }
    /// The constraints' names (empty for a model without constraints).
    #[getter]
    fn constraints(&self) -> Vec<&'static str> {
        self.model
            .constrained
            .map_or_else(Vec::new, |c| c.constraint_names().to_vec())
    }
    /// Each parameter's default value, in declaration order.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        let info = self.model.info;
        for (name, value) in info
            .parameter_names
            .iter()
            .zip(self.model.dynamic.defaults())
        {
            dict.set_item(name, value)?;
        }
        Ok(dict)
    }
    /// Each parameter's range, as the model file gives it ("(0, inf)").
    #[getter]
    fn ranges(&self) -> BTreeMap<&'static str, String> {
        let info = self.model.info;
        info.parameter_names
            .iter()
            .zip(info.parameter_ranges)
            .map(|(n, r)| (*n, r.to_string()))
            .collect()
    }
    #[getter]
    fn descriptions(&self) -> BTreeMap<&'static str, &'static str> {
        let info = self.model.info;
        info.parameter_names
            .iter()
            .copied()
            .zip(info.parameter_descriptions.iter().copied())
            .collect()
    }
    /// The parameter that scales the vibration, if the file names one.
    #[getter]
    fn amplitude(&self) -> Option<&'static str> {
        self.model.info.amplitude
    }
    /// The model file's text and path.
    #[getter]
    fn source(&self) -> &'static str {
        self.model.info.source
    }
    #[getter]
    fn source_file(&self) -> &'static str {
        self.model.info.source_file
    }
    #[getter]
    fn derivations(&self) -> PyDerivations {
        PyDerivations { model: self.model }
    }
    fn __repr__(&self) -> String {
        format!("mechlab.model({:?})", self.model.info.name)
    }

    /// The parameter values in declaration order, the defaults overridden
    /// by `params` (name → value); an unknown name or a value outside its
    /// range is a ValueError naming it.
    #[pyo3(signature = (params=None))]
    fn values(&self, params: Option<BTreeMap<String, f64>>) -> PyResult<Vec<f64>> {
        parameter_values(self.model, params)
    }

    /// The start the scenes take when none is given (the model file's
    /// start where it gives one, with the momenta of its starting rates;
    /// else q = 0.3, 0.5, …, p = 0; a constrained model's file start, on
    /// its constraints).
    #[pyo3(signature = (params=None))]
    fn start<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
    ) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
        let values = parameter_values(self.model, params)?;
        let Some(constrained) = self.model.constrained else {
            return Ok(mechlab::explore::default_start(self.model.dynamic).into_pyarray(py));
        };
        let mut y = constrained.start(&values);
        constrained
            .project(&values, 0.0, &mut y)
            .map_err(|source| {
                py_err(mechlab::analysis::states::StatesError::Start {
                    model: self.model.info.name,
                    source,
                })
            })?;
        Ok(y.into_pyarray(py))
    }

    /// The energy function at (t, y): H, a constrained model's E on its
    /// constraints, a contact model's E (what `explore` follows).
    #[pyo3(signature = (y, t=0.0, *, params=None))]
    fn energy(
        &self,
        y: PyArrayLike1<'_, f64, AllowTypeChange>,
        t: f64,
        params: Option<BTreeMap<String, f64>>,
    ) -> PyResult<f64> {
        let values = parameter_values(self.model, params)?;
        let y = y.as_slice()?;
        let expected = self.model.dynamic.periodic_state().len();
        if y.len() != expected {
            let refusal = mechlab::analysis::Refusal::state_length(
                self.model.info.name,
                "state",
                y.len(),
                expected,
            );
            return Err(py_err(refusal));
        }
        Ok(self.model.dynamic.energy(&values, t, y))
    }

    /// The states at the times `t` from `y0` at t[0] (dense output; a
    /// constrained model's start and states put on its constraints), one
    /// row per time.
    #[pyo3(signature = (y0, t, *, params=None, **settings))]
    fn integrate<'py>(
        &self,
        py: Python<'py>,
        y0: PyArrayLike1<'py, f64, AllowTypeChange>,
        t: PyArrayLike1<'py, f64, AllowTypeChange>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let values = parameter_values(self.model, params)?;
        let options: IntegrateOptions =
            analyses::declared_from(IntegrateOptions::default(), settings)?;
        let method = options.resolve().map_err(py_err)?;
        let (y0, times) = (y0.as_slice()?.to_vec(), t.as_slice()?.to_vec());
        let model = self.model;
        let states =
            detached(py, || states_at(model, &values, method, &y0, &times))?.map_err(py_err)?;
        let dim = y0.len();
        let flat: Vec<f64> = states.into_iter().flatten().collect();
        let array = Array2::from_shape_vec((flat.len() / dim.max(1), dim), flat)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(array.into_pyarray(py))
    }

    /// The states at the times `t` from each row of `y0` (in parallel):
    /// `states[k, i]` is orbit k at t[i]; an orbit that stopped is NaN
    /// and listed in `failed` as (k, why).
    #[pyo3(signature = (y0, t, *, params=None, **settings))]
    fn integrate_many<'py>(
        &self,
        py: Python<'py>,
        y0: PyArrayLike2<'py, f64, AllowTypeChange>,
        t: PyArrayLike1<'py, f64, AllowTypeChange>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let values = parameter_values(self.model, params)?;
        let options: IntegrateOptions =
            analyses::declared_from(IntegrateOptions::default(), settings)?;
        let method = options.resolve().map_err(py_err)?;
        let starts: Vec<Vec<f64>> = y0
            .as_array()
            .rows()
            .into_iter()
            .map(|r| r.to_vec())
            .collect();
        let times = t.as_slice()?.to_vec();
        let model = self.model;
        let runs = detached(py, || {
            states_of_starts(model, &values, method, &starts, &times)
        })?
        .map_err(py_err)?;
        let dim = y0.as_array().ncols();
        let mut states = Array3::from_elem((starts.len(), times.len(), dim), f64::NAN);
        let mut failed = Vec::new();
        for (k, run) in runs.into_iter().enumerate() {
            match run {
                Ok(orbit) => {
                    for (i, y) in orbit.iter().enumerate() {
                        for (j, x) in y.iter().enumerate() {
                            states[(k, i, j)] = *x;
                        }
                    }
                }
                Err(e) => failed.push((k, e.to_string())),
            }
        }
        let result = PyDict::new(py);
        result.set_item("states", states.into_pyarray(py))?;
        result.set_item("failed", failed)?;
        Ok(result)
    }

    /// Orbits of the period map from `seeds` (full states) or from
    /// `count` seeds on a line along the first axis, each drawn in the
    /// plane of `axes`. Settings: the period map's declaration
    /// (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn period_map<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<PeriodMapOptions>(py, params, settings, false)?;
        analyses::portrait(py, &result)
    }

    /// The fast Lyapunov indicator of the period map on a plane of
    /// `pixels`² starts (`fli[j, i]`, row 0 at the bottom), with a
    /// progress bar; Ctrl-C stops it between blocks of rows. Settings: the
    /// chaos map's declaration (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, progress=true, **settings))]
    fn chaos_map<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        progress: bool,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<ChaosMapOptions>(py, params, settings, progress)?;
        analyses::chaos_map(py, &result)
    }

    /// Stabilisation by vibration on the constraints of a constrained
    /// model (the `linkage` scene): its equilibrium near the start, the
    /// averaged thresholds, the exact multipliers against the amplitude.
    /// Settings: the `linkage` declaration (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn linkage<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<LinkageOptions>(py, params, settings, false)?;
        analyses::linkage(py, &result)
    }

    /// The linearisation of a steady motion (the `steady_motion` scene; a
    /// model with constraints or without, not with a fast phase): eigenvalues with their errors and verdict,
    /// and against the speed with the stability boundaries. Settings: the
    /// `steady_motion` declaration (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn steady_motion<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<SteadyMotionOptions>(py, params, settings, false)?;
        analyses::steady_motion(py, &result)
    }

    /// Stabilisation by vibration: for each equilibrium the averaged
    /// threshold a* and the exact window of Floquet stability (settings:
    /// the `stability` declaration). A constrained model's stability is on
    /// its constraints, as the `stability` scene runs it: with a fast
    /// phase, its equilibrium held by vibration (settings: the `linkage`
    /// declaration); without, its steady motion (the `steady_motion`
    /// declaration).
    #[pyo3(signature = (*, params=None, **settings))]
    fn stability<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        if self.model.constrained.is_some() {
            return match self.model.info.amplitude {
                Some(_) => self.linkage(py, params, settings),
                None => self.steady_motion(py, params, settings),
            };
        }
        let result = self.run::<StabilityOptions>(py, params, settings, false)?;
        analyses::stability(py, &result)
    }

    /// The attractor of a forced, damped period map: its points, Lyapunov
    /// spectrum (two runs, their difference the error) and box-counting
    /// and Kaplan–Yorke dimensions. Settings: the attractor's declaration
    /// (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn attractor<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<AttractorOptions>(py, params, settings, false)?;
        analyses::attractor(py, &result)
    }

    /// Periodic orbits of the period map followed in a parameter, their
    /// Floquet multipliers and bifurcations, with the orbit diagram.
    /// Settings: the continuation's declaration (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn continuation<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<ContinuationOptions>(py, params, settings, false)?;
        analyses::continuation(py, &result)
    }

    /// The splitting of the separatrices of the period map's hyperbolic
    /// fixed point (a model of one degree of freedom with a fast phase):
    /// the lobe area by the action and by the polygon. Settings: the
    /// separatrix splitting's declaration (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn separatrix_splitting<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<SplittingOptions>(py, params, settings, false)?;
        analyses::summary(py, &result)
    }

    /// The exact system against the averaged one (of order 1 or 2) as the
    /// fast phase's rate grows: the largest deviation at each value of the
    /// swept parameter, and its slope against the frequency (−1 at first
    /// order). Settings: the averaging's declaration (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn averaging<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<AveragingOptions>(py, params, settings, false)?;
        analyses::summary(py, &result)
    }

    /// What the `explore` scene shows, for any model (the contact models
    /// of Study 3 too): the run, with the averaged run and the period map
    /// where there is a fast phase, the energy's change, the equilibria, a
    /// constrained model's reactions. Settings: the explore declaration
    /// (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn explore<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<ExploreOptions>(py, params, settings, false)?;
        analyses::explore(py, &result)
    }

    /// The period map's iterates from many starts (rows of `starts`,
    /// full states; the Taylor method runs them in the batch lanes):
    /// `iterates[k, i]` is start k after transient + 1 + i periods, NaN
    /// where its orbit stopped. A constrained model's starts are put on
    /// its constraints first.
    #[pyo3(signature = (starts, periods, *, params=None, **settings))]
    fn iterates<'py>(
        &self,
        py: Python<'py>,
        starts: PyArrayLike2<'py, f64, AllowTypeChange>,
        periods: usize,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, numpy::PyArray3<f64>>> {
        let values = parameter_values(self.model, params)?;
        let options: IteratesOptions =
            analyses::declared_from(IteratesOptions::default(), settings)?;
        let (transient, method) = (options.transient, options.resolve().map_err(py_err)?);
        let starts: Vec<Vec<f64>> = starts
            .as_array()
            .rows()
            .into_iter()
            .map(|r| r.to_vec())
            .collect();
        analyses::iterates(py, self.model, values, starts, transient, periods, method)
    }

    /// The basins of attraction of the period map's attractors on a plane
    /// of `pixels`² starts over `ranges` (`labels[j, i]`, row 0 at the
    /// bottom, −1 where the orbit diverged), with a progress bar.
    /// Settings: the basins' declaration (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, progress=true, **settings))]
    fn basins<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        progress: bool,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<BasinsOptions>(py, params, settings, progress)?;
        analyses::basins(py, &result)
    }

    /// The frequency map of the period map (a model with a fast phase) on
    /// a plane of `pixels`² starts: each orbit's tunes over `periods` and
    /// its diffusion index, with a progress bar. Settings: the chaos map's
    /// declaration, from the `frequency_map` scene's values.
    #[pyo3(signature = (*, params=None, progress=true, **settings))]
    fn period_map_frequencies<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        progress: bool,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let values = parameter_values(self.model, params)?;
        let base = mechlab::analysis::frequency_map::period_map_options();
        let options = analyses::declared_from(base, settings)?;
        let settings = options.resolve(self.model).map_err(py_err)?;
        analyses::period_map_frequencies(py, self.model, values, settings, progress)
    }

    /// A Poincaré section at a fixed energy: the `section` scene's
    /// summary — its orbits (each one's points an (n, 2) array), its MEGNO
    /// map and its frequency map where their pixels are asked for.
    /// Settings: the section's declaration (`mechlab.schema()`).
    #[pyo3(signature = (*, params=None, **settings))]
    fn section<'py>(
        &self,
        py: Python<'py>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let result = self.run::<SectionOptions>(py, params, settings, false)?;
        analyses::section(py, &result)
    }
}

impl PyModel {
    /// Declared analysis `T` on this model (`analyses::run`).
    fn run<T: Analysis>(
        &self,
        py: Python<'_>,
        params: Option<BTreeMap<String, f64>>,
        settings: Option<&Bound<'_, PyDict>>,
        show: bool,
    ) -> PyResult<T::Output> {
        analyses::run::<T>(py, self.model, params, settings, show)
    }
}

/// The defaults of `model` with `params` (name → value) set, each checked.
fn parameter_values(model: &Model, params: Option<BTreeMap<String, f64>>) -> PyResult<Vec<f64>> {
    model
        .values_with(&params.unwrap_or_default())
        .map_err(py_err)
}

/// Every declared analysis's settings: name, type, default, range and
/// help (the studio's `GET /api/schema`).
#[pyfunction]
fn schema(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    Ok(pythonize::pythonize(py, &mechlab::settings::schemas())?)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(models, m)?)?;
    m.add_function(wrap_pyfunction!(model, m)?)?;
    m.add_function(wrap_pyfunction!(schema, m)?)?;
    m.add_class::<PyModel>()?;
    m.add_class::<PyDerivation>()?;
    m.add_class::<PyDerivations>()?;
    m.add("Refused", m.py().get_type::<errors::Refused>())?;
    m.add(
        "IntegrationError",
        m.py().get_type::<errors::IntegrationError>(),
    )?;
    Ok(())
}
