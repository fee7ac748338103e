//! The library's errors as Python exceptions with the same messages: a
//! bad value (an unknown parameter, a state of the wrong length, a
//! tolerance of 0) is a `ValueError`; an analysis that does not apply to
//! the model is `mechlab.Refused` (a `ValueError`); an orbit the
//! integrator cannot follow is `mechlab.IntegrationError` (a
//! `RuntimeError`); a run stopped by Ctrl-C is `KeyboardInterrupt`.

use mechlab::classify::{Classify, ErrorClass};
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

/// `error` as the Python exception of its class (the library's one
/// classification, `mechlab::classify`), with its message.
pub fn py_err<E: Classify>(error: E) -> PyErr {
    let message = error.to_string();
    match error.class() {
        ErrorClass::BadValue => PyValueError::new_err(message),
        ErrorClass::Refused => Refused::new_err(message),
        ErrorClass::Integration => IntegrationError::new_err(message),
        ErrorClass::Stopped => PyKeyboardInterrupt::new_err(message),
    }
}
