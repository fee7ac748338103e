//! Analyses built on the integrators: the period map and its orbits,
//! variational equations (monodromy, Floquet multipliers, Lyapunov exponents,
//! the fast Lyapunov indicator), the Chirikov standard map, the comparison
//! of exact and averaged systems, stabilisation by vibration, and
//! Poincaré sections of autonomous models, and the continuation of
//! periodic orbits in a parameter with their bifurcations.

pub mod attractor;
pub mod averaging;
pub mod basins;
pub mod chaos_map;
pub mod check;
pub mod continuation;
pub mod declared;
pub mod dimension;
pub mod equilibria;
pub mod fit;
pub mod floquet;
pub mod frequency;
pub mod frequency_map;
pub mod mechanism;
pub mod on_constraints;
pub mod period_map;
pub mod section;
pub mod section_map;
pub mod separatrix;
pub mod stability;
pub mod standard_map;
pub mod states;
pub mod tiles;
pub mod trade;
pub mod vibrational_stability;

/// The tangent kernels, where the analyses have always found them.
pub use crate::tangent::{lyapunov, variational};

use std::ops::Range;

/// Why an analysis does not apply to a model or to a request, the same for
/// every analysis (each analysis's error wraps it as `Refused`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Refusal {
    /// A model of points on rough guides: it has no Hamiltonian form,
    /// period map or averaged system (`explore` runs it with stick–slip
    /// switching).
    #[error("'{model}' is a contact model: it has no Hamiltonian form, period map or averaged system (`explore` runs it with its stick–slip switching)")]
    ContactModel { model: String },
    /// A model with constraints: this analysis does not run on a
    /// constraint manifold yet.
    #[error("'{model}' is a constrained model: this analysis does not run on its constraints yet (the scenes `explore`, `period_map`, `chaos_map`, `basins`, `attractor`, `continuation`, `averaging`, `section`, `stability` and `linkage` run such models on them)")]
    Constrained { model: String },
    /// A model with a nonholonomic constraint, where the analysis needs
    /// holonomic ones; `reason` says why.
    #[error("'{model}' has a nonholonomic constraint: {reason}")]
    Nonholonomic { model: String, reason: &'static str },
    /// No `[fast_phase]` in its model file: no period map, nothing to average.
    #[error("model '{model}' has no fast phase ([fast_phase] in its model file): it has no period map and nothing to average")]
    NoFastPhase { model: String },
    /// A fast phase where the analysis is of autonomous models; `instead`
    /// names what answers the question for this model.
    #[error("model '{model}' has a fast phase: {instead}")]
    FastPhase {
        model: String,
        instead: &'static str,
    },
    /// Not a number of degrees of freedom the analysis is computed for.
    #[error(
        "model '{model}' has {dof} degrees of freedom: {analysis} is computed for {supported}"
    )]
    Dimension {
        model: String,
        dof: usize,
        analysis: &'static str,
        supported: &'static str,
    },
    /// Not one value per parameter of the model.
    #[error("model '{model}' has {expected} parameters, and {given} values were given")]
    ParameterCount {
        model: String,
        given: usize,
        expected: usize,
    },
    /// A state (a start, a seed, a point a plane passes through) of
    /// another length than the model's.
    #[error("model '{model}': the {what} has {given} components, the model's state {expected}")]
    StateLength {
        model: String,
        what: &'static str,
        given: usize,
        expected: usize,
    },
    /// A setting outside what the analysis accepts; `requirement` says
    /// what it accepts.
    #[error("model '{model}': {requirement}")]
    Setting {
        model: String,
        requirement: &'static str,
    },
    /// A parameter named that the model does not have, or a value it does
    /// not accept.
    #[error(transparent)]
    Parameter(#[from] crate::registry::ParameterError),
    /// An `accuracy` below what double precision resolves on numbers of
    /// this size: refused before any run.
    #[error("model '{model}': accuracy {accuracy:e} on {what} is below what double precision resolves on numbers of about {magnitude:.3}: about {floor:.1e} (64 units of rounding)")]
    BelowPrecision {
        model: String,
        what: &'static str,
        accuracy: f64,
        magnitude: f64,
        floor: f64,
    },
}

impl Refusal {
    /// The refusal of an `accuracy` on `what` (numbers of about
    /// `magnitude`) that double precision cannot reach: below 64 units of
    /// rounding of the magnitude.
    pub fn accuracy_within_reach(
        model: &str,
        what: &'static str,
        accuracy: Option<f64>,
        magnitude: f64,
    ) -> Result<(), Refusal> {
        let floor = 64.0 * f64::EPSILON * magnitude.abs();
        match accuracy {
            Some(accuracy) if accuracy < floor => Err(Refusal::BelowPrecision {
                model: model.into(),
                what,
                accuracy,
                magnitude,
                floor,
            }),
            _ => Ok(()),
        }
    }
}

/// The model's systems, or the refusal of a contact or a constrained
/// model (which have none).
pub(crate) fn hamiltonian(
    model: &crate::registry::Model,
) -> Result<&'static dyn crate::registry::Systems, Refusal> {
    model
        .systems()
        .ok_or_else(|| Refusal::without_hamiltonian_form(model))
}

/// The model's flows (Hamiltonian or constrained), or the refusal of a
/// contact model (which has none).
pub fn flows(
    model: &crate::registry::Model,
) -> Result<&'static dyn crate::registry::Flows, Refusal> {
    model
        .flows()
        .ok_or_else(|| Refusal::contact_model(model.info.name))
}

/// The model's flows with a fast phase (a period map), or the refusal:
/// what an analysis of the period map checks before it starts.
pub fn period_map_flows(
    model: &crate::registry::Model,
) -> Result<&'static dyn crate::registry::Flows, Refusal> {
    let flows = flows(model)?;
    if !flows.has_fast_phase() {
        return Err(Refusal::no_fast_phase(model.info.name));
    }
    Ok(flows)
}

/// Refuses the Taylor method for a model without Taylor recurrences (a
/// constrained model of more than 6 coordinates or long forms): one refusal instead of
/// every orbit stopping.
pub(crate) fn method_applies(
    model: &crate::registry::Model,
    method: crate::ode::Method,
) -> Result<(), Refusal> {
    let recurrences = model
        .flows()
        .is_none_or(|flows| flows.has_taylor_recurrences());
    match (recurrences, method) {
        (false, crate::ode::Method::Taylor { .. }) => Err(Refusal::Setting {
            model: model.info.name.into(),
            requirement: "a constrained model of more than 6 coordinates, or whose recurrences would pass 300 kB of source, has no Taylor recurrences (compiled in three number types, they would cost its build more than the method saves): set method to dop853, radau5, gauss4, gauss6 or rk4",
        }),
        _ => Ok(()),
    }
}

impl Refusal {
    /// The refusal of a model without a Hamiltonian form: a constrained
    /// model's (the analysis does not run on constraints yet) or a contact
    /// model's.
    pub fn without_hamiltonian_form(model: &crate::registry::Model) -> Refusal {
        match model.constrained {
            Some(_) => Refusal::Constrained {
                model: model.info.name.into(),
            },
            None => Refusal::contact_model(model.info.name),
        }
    }

    pub fn contact_model(model: impl Into<String>) -> Refusal {
        Refusal::ContactModel {
            model: model.into(),
        }
    }

    pub fn no_fast_phase(model: impl Into<String>) -> Refusal {
        Refusal::NoFastPhase {
            model: model.into(),
        }
    }

    /// [`Refusal::Setting`].
    pub fn setting(model: impl Into<String>, requirement: &'static str) -> Refusal {
        Refusal::Setting {
            model: model.into(),
            requirement,
        }
    }

    /// The model's parameters by name (the values in declaration order), or
    /// [`Refusal::ParameterCount`].
    pub fn named_values(
        info: &crate::registry::ModelInfo,
        values: &[f64],
    ) -> Result<std::collections::BTreeMap<String, f64>, Refusal> {
        info.named_values(values).ok_or(Refusal::ParameterCount {
            model: info.name.into(),
            given: values.len(),
            expected: info.parameter_names.len(),
        })
    }

    /// The index of the model's parameter `name`, or
    /// [`Refusal::Parameter`] naming the ones it has.
    pub fn parameter_index(
        info: &crate::registry::ModelInfo,
        name: &str,
    ) -> Result<usize, Refusal> {
        info.parameter_names
            .iter()
            .position(|p| *p == name)
            .ok_or_else(|| {
                Refusal::Parameter(crate::registry::ParameterError::Unknown {
                    model: info.name,
                    name: name.into(),
                    known: info.parameter_names,
                })
            })
    }

    /// [`Refusal::StateLength`].
    pub fn state_length(
        model: impl Into<String>,
        what: &'static str,
        given: usize,
        expected: usize,
    ) -> Refusal {
        Refusal::StateLength {
            model: model.into(),
            what,
            given,
            expected,
        }
    }
}

/// Orbits in one block of rows at most: a cancelled chaos map (the
/// studio's view moved) stops once the blocks running end.
pub const BLOCK_ORBITS: usize = 1024;

/// The blocks of rows in which a map (a chaos map, a section's MEGNO map)
/// of the rows `rows`, each of `pixels` orbits, runs on the current rayon
/// pool: about four blocks a thread, to keep the threads' loads even, and
/// at most [`BLOCK_ORBITS`] orbits a block. Each block is streamed through
/// one batch integrator, whose lanes idle only at the stream's end while
/// its last orbits finish: rows of 100 orbits one at a time wasted a few
/// per cent of them (Kapitza's 100² map at 1e-8, medians of five runs:
/// 2.23 s by rows against 2.15 s in blocks on one thread, 1.30 s against
/// 1.24 s on two).
pub fn row_blocks(rows: Range<usize>, pixels: usize) -> Vec<Range<usize>> {
    let size = rows
        .len()
        .div_ceil(4 * rayon::current_num_threads())
        .min(BLOCK_ORBITS / pixels.max(1))
        .max(1);
    let end = rows.end;
    rows.step_by(size).map(|j| j..(j + size).min(end)).collect()
}
