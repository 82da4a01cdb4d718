//! Errors of the bindings and how they reach Python: bad input (what `merge_sim` rejects with
//! exit code 2) raises `mergesim.ScenarioError` (a `ValueError`), a failure while simulating
//! (exit code 1) `mergesim.SimulationError` (a `RuntimeError`). The message is the CLI's, without
//! its `error: ` prefix: the error and its causes joined by `: `, none repeated (`chain`).

use pyo3::PyErr;
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use thiserror::Error;

create_exception!(
    _native,
    ScenarioError,
    PyValueError,
    "Bad input: a scenario, planner, parameter or argument that merge_sim rejects with exit code 2 \
     (the message is the CLI's)."
);
create_exception!(
    _native,
    SimulationError,
    PyRuntimeError,
    "The simulation failed while running (merge_sim's exit code 1)."
);

/// Why a call of the bindings failed.
#[derive(Debug, Error)]
pub(crate) enum BindingError {
    /// Bad input (exit code 2 in the CLI).
    #[error("{0}")]
    Input(String),
    /// A failure while running (exit code 1 in the CLI).
    #[error("{0}")]
    Run(String),
}

impl BindingError {
    /// Bad input, with `error`'s causes (as the CLI prints it).
    pub(crate) fn input(error: &(dyn std::error::Error + 'static)) -> Self {
        Self::Input(chain(error))
    }

    /// A failure while running, with `error`'s causes.
    pub(crate) fn run(error: &(dyn std::error::Error + 'static)) -> Self {
        Self::Run(chain(error))
    }
}

impl From<BindingError> for PyErr {
    fn from(error: BindingError) -> Self {
        match error {
            BindingError::Input(message) => ScenarioError::new_err(message),
            BindingError::Run(message) => SimulationError::new_err(message),
        }
    }
}

/// `error` and its sources joined by `: `, a source its message already ends with left out:
/// what `merge_sim` prints after `error: ` (`mergesim::error_text`).
pub(crate) fn chain(error: &(dyn std::error::Error + 'static)) -> String {
    mergesim::error_text::error_chain(error)
}
