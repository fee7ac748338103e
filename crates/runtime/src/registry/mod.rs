//! What every generated model exposes about itself: its file, names,
//! parameters and derived expressions (for reports and snapshot tests).

use std::fmt;

mod constrained;
mod recording;
pub use constrained::{Constrained, ConstrainedSystems, Output, PlaneCrossing};
use recording::Recorder;
pub use recording::{distance, within, Cells, KnownAttractors, Recording};

use crate::ode::any_size::fixed_state;
use crate::ode::{AnySystem, DynSystem, ErasedSystem, Method, OdeError, SizedSystem, Stats};
use crate::tangent::lyapunov::fli_of_starts;
use crate::tangent::monodromy::{monodromies, monodromy};
pub use mechlab_range::Range;
use nalgebra::DMatrix;

/// One derived expression in its readable form (checked at build time
/// against Symbolica's result), as text and LaTeX.
#[derive(Clone, Copy, Debug)]
pub struct DerivedExpression {
    /// Stable key, e.g. `hamiltonian` or `mass_matrix[0][1]`.
    pub key: &'static str,
    pub description: &'static str,
    pub text: &'static str,
    pub latex: &'static str,
}

/// A generated model, described.
#[derive(Clone, Copy, Debug)]
pub struct ModelInfo {
    pub name: &'static str,
    /// The model file's text.
    pub source: &'static str,
    pub source_file: &'static str,
    pub coordinates: &'static [&'static str],
    pub momenta: &'static [&'static str],
    /// Whether the state's second half are the coordinates' velocities
    /// (a constrained model: `momenta` then names the velocities).
    pub velocities: bool,
    pub parameter_names: &'static [&'static str],
    /// Defaults of the model file, as text.
    pub parameter_defaults: &'static [&'static str],
    pub parameter_descriptions: &'static [&'static str],
    /// The values each parameter may take.
    pub parameter_ranges: &'static [Range],
    /// The parameter that scales the vibration, if the model file names one
    /// (`[fast_phase] amplitude`).
    pub amplitude: Option<&'static str>,
    /// The parameter the fast phase's rate depends on, if exactly one (ν
    /// for the rate `nu`, ε for `1/eps`).
    pub rate_parameter: Option<&'static str>,
    pub derivations: &'static [DerivedExpression],
    /// Cost of the right-hand sides after CSE (arithmetic operations,
    /// transcendental calls weighted 20, divisions 4): (function, as derived
    /// by Symbolica, in the readable form, emitted).
    pub operation_counts: &'static [(&'static str, usize, usize, usize)],
    /// The mechanism's drawing, if the model file names its points.
    pub drawing: Option<&'static Drawing>,
    /// The generated Rust module.
    pub generated_code: &'static str,
}

/// A model's mechanism as its file draws it (`[[points]]`): named points,
/// functions of the time and the coordinates, and bars between them.
#[derive(Debug)]
pub struct Drawing {
    pub points: &'static [&'static str],
    /// Bars between points, by index.
    pub bars: &'static [[usize; 2]],
    /// Each body's frame: the indices of its centre and of its x, y and z
    /// axes' tips.
    pub body_frames: &'static [[usize; 4]],
    /// Whether the drawing is in space (a point given as (x, y, z), or a
    /// body): else every z is 0 and the figure's plane is (x, y).
    pub in_space: bool,
    /// The points (x, y, z) at (t, q) with the parameters' values in
    /// declaration order; empty if q is not of the coordinates' length
    /// (the caller checks; see [`crate::analysis::mechanism`]).
    pub at: fn(f64, &[f64], &[f64]) -> Vec<[f64; 3]>,
    /// Gravity's acceleration at the parameters' values, where the model
    /// file gives it: the drawing's way down.
    pub gravity: Option<fn(&[f64]) -> [f64; 3]>,
}

impl ModelInfo {
    /// The names of the Hamiltonian state [q; p].
    pub fn state_names(&self) -> Vec<&'static str> {
        self.coordinates
            .iter()
            .chain(self.momenta)
            .copied()
            .collect()
    }

    /// State component `index` in the figures' notation: φ₁, p_φ₁, or a
    /// velocity φ₁′.
    pub fn label(&self, index: usize) -> String {
        let n = self.coordinates.len();
        match (index.checked_sub(n), self.velocities) {
            (None, _) => display_name(self.coordinates[index]),
            (Some(i), true) => format!("{}′", display_name(self.coordinates[i])),
            (Some(i), false) => display_name(self.momenta[i]),
        }
    }

    /// The names of two different state components chosen as a plane's
    /// axes, or why they cannot be.
    pub fn plane(&self, axes: [usize; 2]) -> Result<[String; 2], PlaneError> {
        let names = self.state_names();
        if axes.iter().any(|&a| a >= names.len()) || axes[0] == axes[1] {
            return Err(PlaneError { names });
        }
        Ok(axes.map(|a| names[a].to_string()))
    }

    /// `value` for the parameter `name`, or why it cannot be: an unknown
    /// name, a value that is not finite or outside the parameter's range.
    pub fn check_parameter(&self, name: &str, value: f64) -> Result<(), ParameterError> {
        let Some(i) = self.parameter_names.iter().position(|n| *n == name) else {
            return Err(ParameterError::Unknown {
                model: self.name,
                name: name.to_string(),
                known: self.parameter_names,
            });
        };
        if !value.is_finite() {
            return Err(ParameterError::NotFinite {
                model: self.name,
                name: name.to_string(),
                value,
            });
        }
        let range = self.parameter_ranges[i];
        if !range.contains(value) {
            return Err(ParameterError::OutOfRange {
                model: self.name,
                name: name.to_string(),
                value,
                range,
            });
        }
        Ok(())
    }

    /// Parameter values in declaration order as name → value; None if there
    /// are not exactly as many values as parameters.
    pub fn named_values(&self, values: &[f64]) -> Option<std::collections::BTreeMap<String, f64>> {
        (values.len() == self.parameter_names.len()).then(|| {
            self.parameter_names
                .iter()
                .map(|n| n.to_string())
                .zip(values.iter().copied())
                .collect()
        })
    }
}

/// How a model moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Hamilton's equations in [q; p], with or without a fast phase.
    Hamiltonian { dof: usize, fast_phase: bool },
    /// Points on rough guides, state [s; s'], integrated with stick–slip switching.
    Contacts { count: usize },
    /// Coordinates under ideal constraints, state [q; q'], integrated on
    /// the constraints ([`crate::constrained`]).
    Constrained {
        coordinates: usize,
        constraints: usize,
        fast_phase: bool,
    },
}

/// Any generated model with dynamically sized states and parameters in
/// declaration order, so that one scene can run a model chosen by name.
/// Methods that do not apply to a model's kind return `None`. The provided
/// methods are `#[inline]` for the reason [`crate::ode::System`] gives.
pub trait DynamicModel: Sync {
    fn info(&self) -> &'static ModelInfo;
    fn kind(&self) -> Kind;
    fn defaults(&self) -> Vec<f64>;
    /// Which coordinates are angles.
    fn periodic(&self) -> Vec<bool>;
    /// Which components of the state are angles; its length is the
    /// state's dimension (a Hamiltonian model's [q; p], a contact model's
    /// [s; s']: the coordinates, then as many rates).
    #[inline]
    fn periodic_state(&self) -> Vec<bool> {
        let mut periodic = self.periodic();
        periodic.resize(2 * periodic.len(), false);
        periodic
    }
    /// The model file's start at rest: a constrained model's (whose
    /// coordinates must satisfy its constraints), or the coordinates'
    /// starts of a model without constraints whose file gives any (0 for
    /// the others, the momenta 0).
    #[inline]
    fn start(&self, _params: &[f64]) -> Option<Vec<f64>> {
        None
    }
    /// The exact system with its action S = ∫ (p·q' − H) dt and the fast
    /// phase θ as third and fourth state components (models of one degree
    /// of freedom with a fast phase).
    #[inline]
    fn action_system(&self) -> Option<&'static dyn crate::ode::DynSystem<4>> {
        None
    }
    /// The exact right-hand side (Hamiltonian models).
    #[inline]
    fn exact_rhs(&self, _params: &[f64], _t: f64, _y: &[f64]) -> Vec<f64> {
        unimplemented!("a contact model has no smooth right-hand side")
    }
    #[inline]
    fn averaged_rhs(&self, _params: &[f64], _y: &[f64]) -> Option<Vec<f64>> {
        None
    }
    /// H (Hamiltonian models) or the energy function (contact models).
    fn energy(&self, params: &[f64], t: f64, y: &[f64]) -> f64;
    #[inline]
    fn averaged_energy(&self, _params: &[f64], _y: &[f64]) -> Option<f64> {
        None
    }
    /// The Hamiltonian averaged to second order in ε = 1/rate, where derived.
    #[inline]
    fn averaged2_energy(&self, _params: &[f64], _y: &[f64]) -> Option<f64> {
        None
    }
    /// V + V_vibr (V without a fast phase).
    #[inline]
    fn effective_potential(&self, _params: &[f64], _q: &[f64]) -> Option<f64> {
        None
    }
    /// Its Hessian, row-major.
    #[inline]
    fn effective_potential_hessian(&self, _params: &[f64], _q: &[f64]) -> Option<Vec<f64>> {
        None
    }
    /// The period of the fast phase.
    #[inline]
    fn phase_period(&self, _params: &[f64]) -> Option<f64> {
        None
    }
    /// Free forces and normal reactions (contact models).
    #[inline]
    fn contact_forces(&self, _params: &[f64], _y: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        None
    }
    /// Masses and friction coefficients (contact models).
    #[inline]
    fn contact_constants(&self, _params: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        None
    }
}

/// A parameter that cannot be set.
#[derive(Clone, Debug, PartialEq)]
pub enum ParameterError {
    Unknown {
        model: &'static str,
        name: String,
        known: &'static [&'static str],
    },
    NotFinite {
        model: &'static str,
        name: String,
        value: f64,
    },
    OutOfRange {
        model: &'static str,
        name: String,
        value: f64,
        range: Range,
    },
}

impl fmt::Display for ParameterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParameterError::Unknown { model, name, known } => {
                write!(
                    f,
                    "model '{model}' has no parameter '{name}' (known: {})",
                    known.join(", ")
                )
            }
            ParameterError::OutOfRange {
                model,
                name,
                value,
                range,
            } => {
                write!(
                    f,
                    "parameter '{name}' of model '{model}' must lie in {range} (its model file's range), got {value}"
                )
            }
            ParameterError::NotFinite { model, name, value } => {
                write!(
                    f,
                    "parameter '{name}' of model '{model}' must be finite, got {value}"
                )
            }
        }
    }
}

impl std::error::Error for ParameterError {}

/// A generated Hamiltonian model at its own sizes: D degrees of freedom, a
/// state of S = 2D, T = 2S for the state with one tangent vector and
/// V = S + S² with a full set (stable Rust cannot compute them from D, so
/// the generated code states all four). Its one implementation, [`Erased`],
/// reaches the model's compiled code through a trait object; it is what
/// [`Systems`] runs the integrations of a model on at the model's size, and
/// what the analyses defined for one size only (sections of two degrees of
/// freedom, separatrices of one) take.
pub trait Fixed<const D: usize, const S: usize, const T: usize, const V: usize>:
    Sync + 'static
{
    type Exact: crate::ode::System<S> + Sync;
    /// The averaged system (the exact one again for a model without a fast
    /// phase, where [`Fixed::averaged`] gives None).
    type Averaged: crate::ode::System<S> + Sync;
    /// The system averaged to second order in ε = 1/rate (the exact one
    /// again where [`Fixed::averaged2`] gives None).
    type Averaged2: crate::ode::System<S> + Sync;
    fn info(&self) -> &'static ModelInfo;
    fn has_fast_phase(&self) -> bool;
    /// Which coordinates are angles.
    fn periodic(&self) -> [bool; D];
    /// Which components of the state are angles (wrapped into [−π, π)):
    /// the state's layout as the model states it, which the analyses that
    /// work on any state (period maps, chaos maps, continuation, the
    /// studio's orbits) read instead of assuming [q; p]. A Hamiltonian
    /// model's state is its coordinates, then their momenta.
    #[inline]
    fn periodic_state(&self) -> [bool; S] {
        let periodic = self.periodic();
        std::array::from_fn(|i| i < D && periodic[i])
    }
    fn exact(&self, params: &[f64]) -> Self::Exact;
    fn averaged(&self, params: &[f64]) -> Option<Self::Averaged>;
    /// The period of the fast phase.
    fn phase_period(&self, params: &[f64]) -> Option<f64>;
    /// The second-order averaged system: None where it is not derived (no
    /// fast phase, or the numeric-solve form).
    fn averaged2(&self, params: &[f64]) -> Option<Self::Averaged2>;
    fn mass_matrix(&self, params: &[f64], q: &[f64; D]) -> [[f64; D]; D];
}

/// What a generated Hamiltonian model gives at its own sizes, as a trait
/// object (the model's module implements it; [`Erased`] adapts it to
/// [`Fixed`]). Parameters are values in declaration order.
pub trait SizedModel<const D: usize, const S: usize>: Sync {
    fn info(&self) -> &'static ModelInfo;
    /// Which coordinates are angles.
    fn periodic(&self) -> [bool; D];
    fn exact(&self) -> &'static dyn DynSystem<S>;
    /// None without a fast phase.
    fn averaged(&self) -> Option<&'static dyn DynSystem<S>>;
    /// None where the second order is not derived.
    fn averaged2(&self) -> Option<&'static dyn DynSystem<S>>;
    fn phase_period(&self, params: &[f64]) -> Option<f64>;
    fn averaged2_hessian(&self, params: &[f64], y: &[f64; S]) -> Option<[[f64; S]; S]>;
    fn averaged2_shift(&self, params: &[f64], t: f64, y: &[f64; S]) -> Option<[f64; S]>;
    fn mass_matrix(&self, params: &[f64], q: &[f64; D]) -> [[f64; D]; D];
    fn potential_gradient(&self, params: &[f64], q: &[f64; D]) -> [f64; D];
    fn potential_hessian(&self, params: &[f64], q: &[f64; D]) -> [[f64; D]; D];
    fn effective_potential(&self, params: &[f64], q: &[f64; D]) -> f64;
    fn effective_potential_hessian(&self, params: &[f64], q: &[f64; D]) -> [[f64; D]; D];
}

/// A [`SizedModel`] as a [`Fixed`] model: the one type the analyses are
/// compiled for at each size.
pub struct Erased<const D: usize, const S: usize, const T: usize, const V: usize>(
    pub &'static dyn SizedModel<D, S>,
);

impl<const D: usize, const S: usize, const T: usize, const V: usize> Fixed<D, S, T, V>
    for Erased<D, S, T, V>
{
    type Exact = ErasedSystem<S>;
    type Averaged = ErasedSystem<S>;
    type Averaged2 = ErasedSystem<S>;
    fn info(&self) -> &'static ModelInfo {
        self.0.info()
    }
    fn has_fast_phase(&self) -> bool {
        self.0.averaged().is_some()
    }
    fn periodic(&self) -> [bool; D] {
        self.0.periodic()
    }
    fn exact(&self, params: &[f64]) -> ErasedSystem<S> {
        ErasedSystem {
            system: self.0.exact(),
            params: params.to_vec(),
        }
    }
    fn averaged(&self, params: &[f64]) -> Option<ErasedSystem<S>> {
        let system = self.0.averaged()?;
        Some(ErasedSystem {
            system,
            params: params.to_vec(),
        })
    }
    fn phase_period(&self, params: &[f64]) -> Option<f64> {
        self.0.phase_period(params)
    }
    fn averaged2(&self, params: &[f64]) -> Option<ErasedSystem<S>> {
        let system = self.0.averaged2()?;
        Some(ErasedSystem {
            system,
            params: params.to_vec(),
        })
    }
    fn mass_matrix(&self, params: &[f64], q: &[f64; D]) -> [[f64; D]; D] {
        self.0.mass_matrix(params, q)
    }
}

/// What every model with smooth equations of motion gives, whatever its
/// state (a Hamiltonian model's [q; p], a constrained model's [q; q'] on
/// its constraints): the flow the state-generic analyses (portraits,
/// period maps) run. Parameters are values in declaration order.
pub trait Flows: Sync {
    fn info(&self) -> &'static ModelInfo;
    fn has_fast_phase(&self) -> bool;
    /// Which components of the state are angles; its length is the state's.
    fn periodic_state(&self) -> Vec<bool>;
    /// The period of the fast phase.
    fn phase_period(&self, params: &[f64]) -> Option<f64>;
    fn exact(&self, params: &[f64]) -> Box<dyn AnySystem>;
    /// The state seeds are varied from: zero for a free model, the model
    /// file's start for a constrained one.
    fn base_state(&self, _params: &[f64]) -> Vec<f64> {
        vec![0.0; self.periodic_state().len()]
    }
    /// The fast Lyapunov indicator of the exact system's period map from
    /// each start (`starts` holds them one after the other) with the
    /// tangent vector `w0`, and the f-evaluations spent (see
    /// [`crate::tangent::lyapunov::fli_of_starts`]). A constrained model
    /// first puts each start on its constraints holding the components
    /// `held` (a plane's axes) and its tangent vector on their tangent
    /// space; a start it cannot put there gets NaN (no state of the model
    /// there).
    #[allow(clippy::too_many_arguments)]
    fn fli(
        &self,
        params: &[f64],
        method: Method,
        period: f64,
        starts: &[f64],
        w0: &[f64],
        periods: usize,
        held: &[usize],
    ) -> Result<FliValues, OdeError>;
    /// The iterates `transient + 1 ..= transient + record` of the exact
    /// system's period map from each start (`starts` one after the other),
    /// as `recording` says, None for a start whose orbit stopped. Each
    /// orbit alone here; the Hamiltonian models' fixed sizes run the
    /// Taylor method's in the batch lanes.
    fn iterates(
        &self,
        params: &[f64],
        method: Method,
        period: f64,
        starts: &[f64],
        recording: &Recording,
    ) -> Result<Vec<Option<Vec<Vec<f64>>>>, OdeError> {
        let wrap = self.periodic_state();
        iterates_one_by_one(
            &*self.exact(params),
            method,
            period,
            starts,
            recording,
            &wrap,
        )
    }
    /// The states at `times` of each start (`starts` one after the other)
    /// from times[0], an orbit that stops keeping its error: each orbit
    /// alone here (in parallel); the Hamiltonian models' fixed sizes run
    /// the Taylor method's in the batch lanes.
    fn states_of_starts(
        &self,
        params: &[f64],
        method: Method,
        starts: &[f64],
        times: &[f64],
    ) -> Result<Vec<Result<Vec<Vec<f64>>, OdeError>>, OdeError> {
        states_one_by_one(&*self.exact(params), method, starts, times)
    }
    /// Whether the model has Taylor recurrences (every Hamiltonian model;
    /// a constrained one up to 6 coordinates and 300 kB of recurrences).
    fn has_taylor_recurrences(&self) -> bool {
        true
    }
    /// Makes `y` a state of the model at t = 0 holding its components
    /// `held` (a chart's coordinates): a free model's states all are; a
    /// constrained model's other components move onto the constraints.
    fn consistent(
        &self,
        _params: &[f64],
        _y: &mut [f64],
        _held: &[usize],
    ) -> Result<(), crate::ode::holonomic::ConstraintError> {
        Ok(())
    }
}

/// [`Flows::iterates`] of `system`, each orbit alone (in parallel).
fn iterates_one_by_one(
    system: &dyn AnySystem,
    method: Method,
    period: f64,
    starts: &[f64],
    recording: &Recording,
    wrap: &[bool],
) -> Result<Vec<Option<Vec<Vec<f64>>>>, OdeError> {
    use rayon::prelude::*;
    crate::ode::Integrator::new(method)?;
    let periods = recording.transient + recording.record;
    Ok(starts
        .par_chunks(system.dim() * 16)
        .flat_map_iter(|block| {
            let records: Vec<_> = block
                .chunks(system.dim())
                .map(|y0| {
                    let mut integrator = crate::ode::Integrator::new(method).ok()?;
                    let mut recorder = Recorder::new(recording, wrap);
                    let run = system.stream(&mut integrator, y0, period, periods, &mut |y| {
                        recorder.push(y)
                    });
                    recorder.finish(run.is_ok())
                })
                .collect();
            (recording.done)(records.len());
            records
        })
        .collect())
}

/// [`Flows::iterates`] of `system` by the Taylor method in the batch lanes,
/// blocks of orbits each through one batch integrator. `settle(t, y)`
/// takes each state at a period's end (a constrained model puts it on its
/// constraints); false stops the orbit, with no record.
fn iterates_in_lanes<S: crate::ode::System<N> + Sync, const N: usize>(
    system: &S,
    method: Method,
    period: f64,
    starts: &[f64],
    recording: &Recording,
    wrap: &[bool],
    settle: &(dyn Fn(f64, &mut [f64; N]) -> bool + Sync),
) -> Result<Vec<Option<Vec<Vec<f64>>>>, OdeError> {
    use crate::ode::{LaneIntegrator, Orbit};
    use rayon::prelude::*;
    let starts: Vec<[f64; N]> = starts
        .chunks(N)
        .map(fixed_state::<N>)
        .collect::<Result<_, _>>()?;
    LaneIntegrator::new(method)?;
    let blocks: Vec<Vec<Option<Vec<Vec<f64>>>>> = starts
        .par_chunks(256)
        .map(|block| {
            let Ok(mut integrator) = LaneIntegrator::new(method) else {
                return vec![None; block.len()];
            };
            let orbits = Orbit::of_one_system(system, period, block);
            let mut recorders: Vec<Recorder> = block
                .iter()
                .map(|_| Recorder::new(recording, wrap))
                .collect();
            let mut periods_done = vec![0usize; block.len()];
            let mut unsettled = vec![false; block.len()];
            let errors = integrator.stream(&orbits, |k, y| {
                periods_done[k] += 1;
                if !settle(periods_done[k] as f64 * period, y) {
                    unsettled[k] = true;
                    return false;
                }
                recorders[k].push(y)
            });
            (recording.done)(block.len());
            recorders
                .into_iter()
                .zip(errors)
                .zip(unsettled)
                .map(|((recorder, error), unsettled)| {
                    recorder.finish(error.is_none() && !unsettled)
                })
                .collect()
        })
        .collect();
    Ok(blocks.into_iter().flatten().collect())
}

/// [`Flows::states_of_starts`] of `system`, each orbit alone (in parallel).
fn states_one_by_one(
    system: &dyn AnySystem,
    method: Method,
    starts: &[f64],
    times: &[f64],
) -> Result<Vec<Result<Vec<Vec<f64>>, OdeError>>, OdeError> {
    use rayon::prelude::*;
    crate::ode::Integrator::new(method)?;
    Ok(starts
        .par_chunks(system.dim())
        .map(|y0| system.states_from(method, y0, times))
        .collect())
}

/// [`Flows::states_of_starts`] of `system` by the Taylor method in the
/// batch lanes: [`crate::ode::LANES`] orbits at a time, advanced together
/// from each output time to the next (each lane's run is that lane's
/// alone: the steps adapt per lane).
fn states_in_lanes<S: crate::ode::System<N> + Sync, const N: usize>(
    system: &S,
    method: Method,
    starts: &[f64],
    times: &[f64],
) -> Result<Vec<Result<Vec<Vec<f64>>, OdeError>>, OdeError> {
    use crate::ode::{LaneIntegrator, LANES};
    use rayon::prelude::*;
    let starts: Vec<[f64; N]> = starts
        .chunks(N)
        .map(fixed_state::<N>)
        .collect::<Result<_, _>>()?;
    LaneIntegrator::new(method)?;
    let blocks: Vec<Vec<Result<Vec<Vec<f64>>, OdeError>>> = starts
        .par_chunks(LANES)
        .map(|block| {
            let mut integrator = match LaneIntegrator::new(method) {
                Ok(integrator) => integrator,
                Err(e) => return vec![Err(e); block.len()],
            };
            let mut y: [[f64; N]; LANES] = std::array::from_fn(|l| block[l.min(block.len() - 1)]);
            let mut active: [bool; LANES] = std::array::from_fn(|l| l < block.len());
            let mut runs: Vec<Result<Vec<Vec<f64>>, OdeError>> =
                block.iter().map(|start| Ok(vec![start.to_vec()])).collect();
            for w in times.windows(2) {
                let results = integrator.advance(system, w[0], &y, active, w[1]);
                for (l, result) in results.into_iter().enumerate().take(block.len()) {
                    if !active[l] {
                        continue;
                    }
                    match result {
                        Ok(state) => {
                            y[l] = state;
                            if let Ok(states) = &mut runs[l] {
                                states.push(state.to_vec());
                            }
                        }
                        Err(e) => {
                            runs[l] = Err(e);
                            active[l] = false;
                        }
                    }
                }
            }
            runs
        })
        .collect();
    Ok(blocks.into_iter().flatten().collect())
}

/// A Hamiltonian model's systems and functions with states as slices: what
/// the analyses compiled once for every size use (see
/// [`crate::ode::any_size`]). Parameters are values in declaration order.
pub trait Systems: Flows {
    /// The state at rest at the coordinates `q` (for [q; p], p = 0).
    fn at_rest(&self, q: &[f64]) -> Vec<f64> {
        let mut y = q.to_vec();
        y.resize(self.periodic_state().len(), 0.0);
        y
    }
    /// None without a fast phase.
    fn averaged(&self, params: &[f64]) -> Option<Box<dyn AnySystem>>;
    /// The system averaged to second order in ε = 1/rate, where derived.
    fn averaged2(&self, params: &[f64]) -> Option<Box<dyn AnySystem>>;
    /// The first-order map's shift y − y′ at time t (where the second
    /// order is derived).
    fn averaged2_shift(&self, params: &[f64], t: f64, y: &[f64]) -> Option<Vec<f64>>;
    /// The mass matrix A(q).
    fn mass_matrix(&self, params: &[f64], q: &[f64]) -> DMatrix<f64>;
    /// ∂V/∂q and C = ∂²V/∂q² of the potential averaged over the phase.
    fn potential_gradient(&self, params: &[f64], q: &[f64]) -> Vec<f64>;
    fn potential_hessian(&self, params: &[f64], q: &[f64]) -> DMatrix<f64>;
    /// V + V_vibr (V without a fast phase) and its Hessian.
    fn effective_potential(&self, params: &[f64], q: &[f64]) -> f64;
    fn effective_potential_hessian(&self, params: &[f64], q: &[f64]) -> DMatrix<f64>;
    /// ∂²K̄/∂y² of the second-order averaged Hamiltonian, where derived.
    fn averaged2_hessian(&self, params: &[f64], y: &[f64]) -> Option<DMatrix<f64>>;
    /// The exact system's end state and monodromy matrix over one period
    /// from `y0`, at each (parameter values, period) of a sweep, and the
    /// sweep's statistics (see [`crate::tangent::monodromy::monodromies`]:
    /// the Taylor method runs them in its lanes).
    fn monodromies(&self, method: Method, problems: &[(Vec<f64>, f64)], y0: &[f64]) -> Monodromies;
    /// The exact system's state after `period` from `y0` and the monodromy
    /// matrix ∂y(T)/∂y(0) (see [`crate::tangent::monodromy::monodromy`]).
    fn monodromy(
        &self,
        params: &[f64],
        integrator: &mut crate::ode::Integrator,
        period: f64,
        y0: &[f64],
    ) -> Result<(Vec<f64>, nalgebra::DMatrix<f64>), OdeError>;
}

/// Each orbit's FLI (or why it stopped) and the f-evaluations spent.
pub type FliValues = (Vec<Result<f64, OdeError>>, u64);

/// Each problem's end state and monodromy matrix (or why it stopped), and
/// the statistics of their runs.
pub type Monodromies = (Vec<Result<(Vec<f64>, DMatrix<f64>), OdeError>>, Stats);

/// The coordinates `q` at the model's number D (the analyses check a
/// user's equilibrium's length before they ask).
fn coordinates<const D: usize>(q: &[f64]) -> [f64; D] {
    fixed_state::<D>(q).expect("coordinates of the model's length")
}

/// A fixed-size matrix as a dynamic one.
fn matrix<const N: usize>(m: &[[f64; N]; N]) -> DMatrix<f64> {
    DMatrix::from_fn(N, N, |i, k| m[i][k])
}

impl<const D: usize, const S: usize, const T: usize, const V: usize> Flows for Erased<D, S, T, V> {
    fn info(&self) -> &'static ModelInfo {
        self.0.info()
    }
    fn has_fast_phase(&self) -> bool {
        Fixed::has_fast_phase(self)
    }
    fn periodic_state(&self) -> Vec<bool> {
        Fixed::periodic_state(self).to_vec()
    }
    fn phase_period(&self, params: &[f64]) -> Option<f64> {
        self.0.phase_period(params)
    }
    fn exact(&self, params: &[f64]) -> Box<dyn AnySystem> {
        Box::new(SizedSystem(Fixed::exact(self, params)))
    }
    fn fli(
        &self,
        params: &[f64],
        method: Method,
        period: f64,
        starts: &[f64],
        w0: &[f64],
        periods: usize,
        _held: &[usize],
    ) -> Result<FliValues, OdeError> {
        let starts: Vec<[f64; S]> = starts
            .chunks(S)
            .map(fixed_state::<S>)
            .collect::<Result<_, _>>()?;
        let w0 = fixed_state::<S>(w0)?;
        let system = Fixed::exact(self, params);
        fli_of_starts::<_, S, T>(&system, method, period, &starts, &[w0], periods)
    }
    fn iterates(
        &self,
        params: &[f64],
        method: Method,
        period: f64,
        starts: &[f64],
        recording: &Recording,
    ) -> Result<Vec<Option<Vec<Vec<f64>>>>, OdeError> {
        let wrap = Fixed::periodic_state(self);
        if !matches!(method, Method::Taylor { .. }) {
            let system = Flows::exact(self, params);
            return iterates_one_by_one(&*system, method, period, starts, recording, &wrap);
        }
        let system = Fixed::exact(self, params);
        iterates_in_lanes(
            &system,
            method,
            period,
            starts,
            recording,
            &wrap,
            &|_, _| true,
        )
    }
    fn states_of_starts(
        &self,
        params: &[f64],
        method: Method,
        starts: &[f64],
        times: &[f64],
    ) -> Result<Vec<Result<Vec<Vec<f64>>, OdeError>>, OdeError> {
        if !matches!(method, Method::Taylor { .. }) {
            // (The provided method, each orbit alone.)
            let system = Flows::exact(self, params);
            return states_one_by_one(&*system, method, starts, times);
        }
        states_in_lanes(&Fixed::exact(self, params), method, starts, times)
    }
}

impl<const D: usize, const S: usize, const T: usize, const V: usize> Systems
    for Erased<D, S, T, V>
{
    fn averaged(&self, params: &[f64]) -> Option<Box<dyn AnySystem>> {
        let averaged = Fixed::averaged(self, params)?;
        Some(Box::new(SizedSystem(averaged)))
    }
    fn averaged2(&self, params: &[f64]) -> Option<Box<dyn AnySystem>> {
        let averaged = Fixed::averaged2(self, params)?;
        Some(Box::new(SizedSystem(averaged)))
    }
    fn averaged2_shift(&self, params: &[f64], t: f64, y: &[f64]) -> Option<Vec<f64>> {
        let y = fixed_state::<S>(y).ok()?;
        Some(self.0.averaged2_shift(params, t, &y)?.to_vec())
    }
    fn mass_matrix(&self, params: &[f64], q: &[f64]) -> DMatrix<f64> {
        matrix(&self.0.mass_matrix(params, &coordinates::<D>(q)))
    }
    fn potential_gradient(&self, params: &[f64], q: &[f64]) -> Vec<f64> {
        self.0
            .potential_gradient(params, &coordinates::<D>(q))
            .to_vec()
    }
    fn potential_hessian(&self, params: &[f64], q: &[f64]) -> DMatrix<f64> {
        matrix(&self.0.potential_hessian(params, &coordinates::<D>(q)))
    }
    fn effective_potential(&self, params: &[f64], q: &[f64]) -> f64 {
        self.0.effective_potential(params, &coordinates::<D>(q))
    }
    fn effective_potential_hessian(&self, params: &[f64], q: &[f64]) -> DMatrix<f64> {
        matrix(
            &self
                .0
                .effective_potential_hessian(params, &coordinates::<D>(q)),
        )
    }
    fn averaged2_hessian(&self, params: &[f64], y: &[f64]) -> Option<DMatrix<f64>> {
        let y = fixed_state::<S>(y).ok()?;
        Some(matrix(&self.0.averaged2_hessian(params, &y)?))
    }
    fn monodromies(&self, method: Method, problems: &[(Vec<f64>, f64)], y0: &[f64]) -> Monodromies {
        let y0 = match fixed_state::<S>(y0) {
            Ok(y0) => y0,
            Err(e) => return (vec![Err(e); problems.len()], Stats::default()),
        };
        let problems: Vec<_> = problems
            .iter()
            .map(|(params, period)| (Fixed::exact(self, params), *period, y0))
            .collect();
        let (results, stats) = monodromies::<_, S, V>(method, &problems);
        let results = results
            .into_iter()
            .map(|r| r.map(|(end, m)| (end.to_vec(), matrix(&m))))
            .collect();
        (results, stats)
    }
    fn monodromy(
        &self,
        params: &[f64],
        integrator: &mut crate::ode::Integrator,
        period: f64,
        y0: &[f64],
    ) -> Result<(Vec<f64>, nalgebra::DMatrix<f64>), OdeError> {
        let y0 = fixed_state::<S>(y0)?;
        let system = Fixed::exact(self, params);
        let (image, m) = monodromy::<_, S, V>(integrator, &system, period, &y0)?;
        Ok((image.to_vec(), matrix(&m)))
    }
}

/// A Hamiltonian model at its own size: for 1 to 3 degrees of freedom the
/// runtime's instances (the analyses of one size, sections and separatrices,
/// read them), for more the model's [`Systems`], compiled in the models
/// package at the model's size.
#[derive(Clone, Copy)]
pub enum FixedSize {
    Dof1(&'static Erased<1, 2, 4, 6>),
    Dof2(&'static Erased<2, 4, 8, 20>),
    Dof3(&'static Erased<3, 6, 12, 42>),
    Large(&'static dyn Systems),
}

/// One generated model: what it is, its dynamically sized interface, and
/// for Hamiltonian models the model at its own sizes, whose [`Systems`]
/// ([`Model::systems`]) the analyses run.
#[derive(Clone, Copy)]
pub struct Model {
    pub info: &'static ModelInfo,
    pub dynamic: &'static dyn DynamicModel,
    /// None for a contact or a constrained model.
    pub sized: Option<FixedSize>,
    /// A constrained model's equations and projections.
    pub constrained: Option<&'static dyn ConstrainedSystems>,
}

impl Model {
    /// The model file's parameter values with `given` (name → value) set,
    /// each checked, in declaration order: how every front end reads the
    /// parameters a user names.
    pub fn values_with<'a>(
        &self,
        given: impl IntoIterator<Item = (&'a String, &'a f64)>,
    ) -> Result<Vec<f64>, ParameterError> {
        let mut values = self.dynamic.defaults();
        for (name, &value) in given {
            self.info.check_parameter(name, value)?;
            let k = self.info.parameter_names.iter().position(|n| n == name);
            values[k.expect("check_parameter knows every name")] = value;
        }
        Ok(values)
    }

    /// The model's [`Flows`]: its [`Systems`] or its constrained form
    /// (None for a contact model).
    pub fn flows(&self) -> Option<&'static dyn Flows> {
        match (self.systems(), self.constrained) {
            (Some(systems), _) => Some(systems),
            (None, Some(constrained)) => Some(constrained),
            (None, None) => None,
        }
    }

    /// The model's [`Systems`] (None for a contact model).
    pub fn systems(&self) -> Option<&'static dyn Systems> {
        Some(match self.sized? {
            FixedSize::Dof1(m) => m,
            FixedSize::Dof2(m) => m,
            FixedSize::Dof3(m) => m,
            FixedSize::Large(m) => m,
        })
    }
}

impl fmt::Debug for Model {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Model")
            .field("name", &self.info.name)
            .field("kind", &self.dynamic.kind())
            .finish()
    }
}

/// Axes that are not two different state components of the model.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("the axes must be two different state components among {}", names.join(", "))]
pub struct PlaneError {
    pub names: Vec<&'static str>,
}

/// A model name that no model file has.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("no model named '{name}' (known: {})", known.join(", "))]
pub struct UnknownModel {
    pub name: String,
    pub known: Vec<&'static str>,
}

/// The models a program knows by name: the `mechlab` package's
/// `models::MODELS` (generated from `models/`), handed to the parts of the
/// runtime that list or look up models (scenes, the studio, reports).
pub type Catalog = &'static [&'static Model];

/// The model named `name` in `catalog`.
pub fn lookup(catalog: Catalog, name: &str) -> Result<&'static Model, UnknownModel> {
    catalog
        .iter()
        .copied()
        .find(|m| m.info.name == name)
        .ok_or_else(|| UnknownModel {
            name: name.to_string(),
            known: catalog.iter().map(|m| m.info.name).collect(),
        })
}

/// A name of a model file in the notation of the figures: Greek names as
/// letters, trailing digits as subscripts, momenta as p_φ₁ (`phi1` → φ₁,
/// `p_phi1` → p_φ₁, `eps` → ε, `A` → A).
pub fn display_name(name: &str) -> String {
    const GREEK: [(&str, &str); 24] = [
        ("alpha", "α"),
        ("beta", "β"),
        ("gamma", "γ"),
        ("delta", "δ"),
        ("epsilon", "ε"),
        ("eps", "ε"),
        ("zeta", "ζ"),
        ("eta", "η"),
        ("theta", "θ"),
        ("kappa", "κ"),
        ("lambda", "λ"),
        ("mu", "μ"),
        ("nu", "ν"),
        ("xi", "ξ"),
        ("pi", "π"),
        ("rho", "ρ"),
        ("sigma", "σ"),
        ("tau", "τ"),
        ("phi", "φ"),
        ("chi", "χ"),
        ("psi", "ψ"),
        ("omega", "ω"),
        ("Omega", "Ω"),
        ("Phi", "Φ"),
    ];
    if let Some(coordinate) = name.strip_prefix("p_") {
        return format!("p_{}", display_name(coordinate));
    }
    let stem = name.trim_end_matches(|c: char| c.is_ascii_digit());
    let digits = &name[stem.len()..];
    let stem = GREEK
        .iter()
        .find(|(latin, _)| *latin == stem)
        .map_or(stem, |(_, greek)| greek);
    let subscripts: String = digits
        .chars()
        .map(|d| char::from_u32(0x2080 + d.to_digit(10).unwrap_or(0)).unwrap_or(d))
        .collect();
    format!("{stem}{subscripts}")
}
