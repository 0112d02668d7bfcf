//! Running a long call: the GIL released, on a rayon pool of its own, a
//! panic turned into an exception.

use std::panic::{catch_unwind, AssertUnwindSafe};

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

/// The number of threads of a call: `threads` when given (at least 1), else
/// every core.
pub fn thread_count(threads: Option<i64>) -> PyResult<usize> {
    match threads {
        None => Ok(std::thread::available_parallelism().map_or(1, |n| n.get())),
        Some(n) if n >= 1 => usize::try_from(n)
            .map_err(|_| PyValueError::new_err(format!("threads = {n} is too large"))),
        Some(n) => Err(PyValueError::new_err(format!(
            "threads must be at least 1, got {n}"
        ))),
    }
}

/// Runs `work(threads)` with the GIL released, inside a rayon thread pool
/// of `threads` threads made for this call (so that every parallel loop of
/// the library runs on it, not on the global pool, and two calls from two
/// Python threads do not share or resize each other's pools).
///
/// A panic (a bug in the library) is caught here and raised as
/// `RuntimeError`, so it never unwinds into the interpreter.
pub fn detached<T, F>(py: Python<'_>, threads: usize, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(usize) -> PyResult<T> + Send,
{
    py.detach(move || {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("aniso-alpha-{i}"))
            .build()
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start {threads} threads: {e}")))?;
        catch_unwind(AssertUnwindSafe(|| pool.install(|| work(threads))))
            .unwrap_or_else(|payload| Err(panic_error(payload.as_ref())))
    })
}

/// The exception raised for a caught panic.
fn panic_error(payload: &(dyn std::any::Any + Send)) -> PyErr {
    let msg = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    PyRuntimeError::new_err(format!(
        "internal error in aniso-alpha (please report it): {msg}"
    ))
}
