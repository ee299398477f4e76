//! The extension module of the `cpsplan` Python package: the command line,
//! run in the interpreter's process. The package's Python layer
//! (`cpsplan/__init__.py`) builds the arguments and reads the results.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    _cpsplan,
    CpsplanError,
    PyException,
    "A cpsplan run failed: the message says why, on one line."
);

/// Runs `cpsplan ARGS...` (without the program's name); raises `CpsplanError`
/// with the one-line message the command line prints.
#[pyfunction]
fn run(py: Python<'_>, args: Vec<String>) -> PyResult<()> {
    let argv: Vec<String> = std::iter::once("cpsplan".to_string()).chain(args).collect();
    py.detach(|| cpsplan_cli::cli::run_args(argv))
        .map_err(|e| CpsplanError::new_err(cpsplan_cli::cli::one_line(&e)))
}

/// The extension module.
#[pymodule]
fn _cpsplan(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add("CpsplanError", m.py().get_type::<CpsplanError>())?;
    Ok(())
}
