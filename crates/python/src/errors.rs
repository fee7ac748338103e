//! The library's errors as Python exceptions with the same messages: a
//! bad value (an unknown parameter, a state of the wrong length, a
//! tolerance of 0) is a `ValueError`; an analysis that does not apply to
//! the model is `mechlab.Refused` (a `ValueError`); an orbit the
//! integrator cannot follow is `mechlab.IntegrationError` (a
//! `RuntimeError`); a run stopped by Ctrl-C is `KeyboardInterrupt`.

use mechlab::analysis::period_map::PeriodMapError;
use mechlab::analysis::section::SectionError;
use mechlab::analysis::stability::StabilityError;
use mechlab::analysis::states::StatesError;
use mechlab::analysis::Refusal;
use mechlab::ode::OdeError;
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::PyErr;

pyo3::create_exception!(
    mechlab,
    Refused,
    PyValueError,
    "The analysis does not apply to this model (the message says why and what does)."
);
pyo3::create_exception!(
    mechlab,
    IntegrationError,
    pyo3::exceptions::PyRuntimeError,
    "The integrator could not follow an orbit (the message says where)."
);

/// Which Python exception an error becomes.
pub enum Class {
    Value,
    Refused,
    Integration,
    Interrupted,
}

/// An error of the library, classed for Python.
pub trait Classify: std::fmt::Display {
    fn class(&self) -> Class;
}

/// `error` as the Python exception of its class, with its message.
pub fn py_err<E: Classify>(error: E) -> PyErr {
    let message = error.to_string();
    match error.class() {
        Class::Value => PyValueError::new_err(message),
        Class::Refused => Refused::new_err(message),
        Class::Integration => IntegrationError::new_err(message),
        Class::Interrupted => PyKeyboardInterrupt::new_err(message),
    }
}

impl Classify for Refusal {
    fn class(&self) -> Class {
        match self {
            Refusal::Parameter(_)
            | Refusal::ParameterCount { .. }
            | Refusal::StateLength { .. }
            | Refusal::Setting { .. } => Class::Value,
            _ => Class::Refused,
        }
    }
}

impl Classify for OdeError {
    fn class(&self) -> Class {
        match self {
            OdeError::UnknownMethod(_)
            | OdeError::InvalidSetting { .. }
            | OdeError::NonFiniteInitialState { .. }
            | OdeError::StateLength { .. }
            | OdeError::TooLarge(_) => Class::Value,
            OdeError::Stopped { .. } => Class::Interrupted,
            _ => Class::Integration,
        }
    }
}

/// A declared setting's value refused (its name, value and range).
impl Classify for mechlab::settings::SettingError {
    fn class(&self) -> Class {
        Class::Value
    }
}

impl Classify for mechlab::registry::ParameterError {
    fn class(&self) -> Class {
        Class::Value
    }
}

impl Classify for StatesError {
    fn class(&self) -> Class {
        match self {
            StatesError::Refused(r) => r.class(),
            StatesError::Times | StatesError::Start { .. } => Class::Value,
            StatesError::Constrained(_) => Class::Integration,
            StatesError::Ode(e) => e.class(),
        }
    }
}

impl Classify for PeriodMapError {
    fn class(&self) -> Class {
        match self {
            PeriodMapError::Refused(r) => r.class(),
            PeriodMapError::Cancelled => Class::Interrupted,
            PeriodMapError::Ode(e) => e.class(),
            _ => Class::Value,
        }
    }
}

impl Classify for StabilityError {
    fn class(&self) -> Class {
        match self {
            StabilityError::Refused(r) => r.class(),
            StabilityError::Ode(e) => e.class(),
            _ => Class::Value,
        }
    }
}

impl Classify for SectionError {
    fn class(&self) -> Class {
        match self {
            SectionError::Refused(r) => r.class(),
            SectionError::Method(e) => e.class(),
            _ => Class::Value,
        }
    }
}
