//! vibrobed's errors as Python exceptions: bad input is a `ScenarioError` (a `ValueError`) with
//! the command line's message and the field it names; a file that cannot be read or written is an
//! `OSError` naming it with the system's reason; a failure of the simulation a `RuntimeError`.

use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use vibrobed::Error;

pyo3::create_exception!(
    vibrobed,
    ScenarioError,
    PyValueError,
    "Bad input (exit code 2 on the command line): the message is the command line's, and \
     `field` names the culprit (a dotted scenario path such as `particles.radius`, or an option)."
);

/// The Python exception for `e`.
pub fn to_py(e: Error) -> PyErr {
    match e {
        Error::Input { field, message } => Python::attach(|py| {
            let text = Error::Input {
                field: field.clone(),
                message,
            }
            .to_string();
            let err = ScenarioError::new_err(text);
            // An attribute on the instance: `except ScenarioError as e: e.field`.
            let _ = err.value(py).setattr("field", field);
            err
        }),
        Error::Io(message) => PyOSError::new_err(message),
        Error::Runtime(message) => PyRuntimeError::new_err(format!("runtime failure: {message}")),
    }
}

/// `Result` into `PyResult`.
pub trait IntoPy<T> {
    /// The error as its Python exception.
    fn py(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for vibrobed::Result<T> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}
