//! What a study's run (in `mechlab::studies`) can fail with; here so that
//! scenes can carry it without depending on the generated models.

use crate::ode::OdeError;

/// Why a study's run failed.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error(transparent)]
    Ode(#[from] OdeError),
    /// One orbit of a set, with its start.
    #[error("orbit {index} from {start:?}: {source}")]
    Orbit {
        index: usize,
        start: Vec<f64>,
        source: OdeError,
    },
    #[error(transparent)]
    Stability(#[from] crate::analysis::stability::StabilityError),
    #[error(transparent)]
    Contact(#[from] crate::contact::ContactError),
    /// One case of a set, by its index and the value that sets it apart.
    #[error("case {index} ({value}): {source}")]
    Case {
        index: usize,
        value: f64,
        source: crate::contact::ContactError,
    },
    /// A setting outside what the study accepts; `requirement` says what
    /// it accepts.
    #[error("{setting}: {requirement}")]
    Settings {
        setting: &'static str,
        requirement: &'static str,
    },
    /// A parameter outside the model file's range.
    #[error(transparent)]
    Parameter(#[from] crate::registry::ParameterError),
    /// The averaged system's linearisation at an equilibrium has no finite
    /// eigenvalues (a singular mass matrix there, or a parameter out of
    /// its physical range).
    #[error("equilibrium {equilibrium:?}: the averaged linearisation has no finite eigenvalues")]
    NoFiniteEigenvalues { equilibrium: Vec<f64> },
}
