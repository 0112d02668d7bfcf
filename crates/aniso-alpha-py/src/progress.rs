//! A Python progress callback for a detection: `progress(done, total)`
//! after each orientation, from the worker threads with the GIL taken.

use std::sync::{Arc, Mutex};

use aniso_alpha::detect::DetectError;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyBool;

/// The callback and the first exception it raised.
pub struct Callback {
    f: Arc<Py<PyAny>>,
    raised: Arc<Mutex<Option<PyErr>>>,
}

impl Callback {
    /// Wraps the Python callable `f`.
    pub fn new(f: Py<PyAny>) -> Self {
        Callback {
            f: Arc::new(f),
            raised: Arc::new(Mutex::new(None)),
        }
    }

    /// The detector's progress function: calls `f(done, total)`; `False`
    /// returned or an exception raised (kept for [`Callback::error`])
    /// cancels the run. Any other return value (tqdm's `update` returns
    /// `None` or `True`) goes on.
    pub fn tick(&self) -> impl Fn(usize, usize) -> bool + Send + Sync + 'static {
        let f = Arc::clone(&self.f);
        let raised = Arc::clone(&self.raised);
        move |done, total| {
            Python::attach(|py| match f.call1(py, (done, total)) {
                Ok(r) => {
                    let r = r.bind(py);
                    !r.is_instance_of::<PyBool>() || r.is_truthy().unwrap_or(true)
                }
                Err(e) => {
                    let mut slot = raised.lock().unwrap_or_else(|p| p.into_inner());
                    slot.get_or_insert(e);
                    false
                }
            })
        }
    }

    /// The exception for a run that ended in `err`: the callback's own
    /// exception, or `RuntimeError` when it returned `False`; `None` when
    /// the run was not cancelled.
    pub fn error(&self, err: &DetectError) -> Option<PyErr> {
        if !matches!(err, DetectError::Cancelled) {
            return None;
        }
        let mut slot = self.raised.lock().unwrap_or_else(|p| p.into_inner());
        Some(slot.take().unwrap_or_else(|| {
            PyRuntimeError::new_err(
                "detect: cancelled by the progress callback (it returned False)",
            )
        }))
    }
}
