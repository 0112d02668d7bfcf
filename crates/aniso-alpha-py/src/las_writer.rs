//! A labelled copy of a LAS/LAZ file written a range of points at a time
//! ([`LasLabelWriter`]), for clouds whose files are read by ranges.

use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard, TryLockError};

use aniso_alpha::io::LasLabelWriter;
use numpy::PyReadonlyArray1;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use crate::errors::io_error;
use crate::run::detached;
use crate::PyLas;

/// `LasLabelWriter(path, las, points, classify=None)`: the labelled copy
/// of the LAS/LAZ file `las` was read from (`read(..., start=, count=)`),
/// for its `points` records; `append(las, labels, part_labels)` adds the
/// records of the next range, `finish()` completes the file and moves it
/// onto `path` (a writer dropped before leaves no file).
#[pyclass(name = "LasLabelWriter", module = "aniso_alpha._native")]
pub struct PyLasLabelWriter {
    writer: Mutex<Option<LasLabelWriter>>,
}

impl PyLasLabelWriter {
    /// The writer (`None` once finished); an error while another thread
    /// uses it (waiting for it here, holding the GIL, could deadlock).
    fn lock(&self) -> PyResult<MutexGuard<'_, Option<LasLabelWriter>>> {
        match self.writer.try_lock() {
            Ok(w) => Ok(w),
            Err(TryLockError::Poisoned(e)) => Ok(e.into_inner()),
            Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(
                "the labelled LAS/LAZ file is being written by another thread",
            )),
        }
    }
}

/// The error of a writer used after `finish`.
fn finished() -> PyErr {
    PyValueError::new_err("the labelled LAS/LAZ file is already finished")
}

#[pymethods]
impl PyLasLabelWriter {
    #[new]
    #[pyo3(signature = (path, las, points, classify = None))]
    fn new(
        py: Python<'_>,
        path: PathBuf,
        las: &PyLas,
        points: u64,
        classify: Option<u8>,
    ) -> PyResult<Self> {
        let source = las.las.clone();
        let writer = detached(py, 1, move |_| {
            LasLabelWriter::create(&path, &source, points, classify).map_err(io_error)
        })?;
        Ok(PyLasLabelWriter {
            writer: Mutex::new(Some(writer)),
        })
    }

    /// Appends the records of `las` (the next range of the file) with one
    /// structure and part id each.
    fn append(
        &self,
        py: Python<'_>,
        las: &PyLas,
        labels: PyReadonlyArray1<'_, i64>,
        part_labels: PyReadonlyArray1<'_, i64>,
    ) -> PyResult<()> {
        let (labels, part_labels) = (labels.as_slice()?, part_labels.as_slice()?);
        let source = las.las.clone();
        let mut guard = self.lock()?;
        let w = guard.as_mut().ok_or_else(finished)?;
        detached(py, 1, |_| {
            w.append(&source.records, labels, part_labels)
                .map_err(io_error)
        })
    }

    /// Completes the file and moves it onto its path.
    fn finish(&self, py: Python<'_>) -> PyResult<()> {
        let w = self.lock()?.take().ok_or_else(finished)?;
        detached(py, 1, move |_| w.finish().map_err(io_error))
    }
}
