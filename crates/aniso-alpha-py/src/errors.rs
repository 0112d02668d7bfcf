//! Library errors as Python exceptions: bad input is `ValueError` with the
//! library's message; a file that cannot be opened is `OSError` (its
//! `FileNotFoundError`, `PermissionError`... subclass, from the errno).

use aniso_alpha::io::IoError;
use pyo3::exceptions::{PyIsADirectoryError, PyOSError, PyValueError};
use pyo3::PyErr;

/// `ValueError(str(err))`.
pub fn value_error(err: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(err.to_string())
}

/// A reader's error: `OSError(errno, message, filename)` when the file
/// cannot be opened or read (Python picks the subclass from the errno),
/// `IsADirectoryError` for a folder, `ValueError` for what is in the file.
pub fn io_error(err: IoError) -> PyErr {
    let path = err.path().to_string_lossy().into_owned();
    match &err {
        IoError::Open { source, .. } => match source.raw_os_error() {
            Some(errno) => PyOSError::new_err((errno, source.to_string(), path)),
            None => PyOSError::new_err(err.to_string()),
        },
        IoError::IsDirectory { .. } => PyIsADirectoryError::new_err(err.to_string()),
        _ => PyValueError::new_err(err.to_string()),
    }
}
