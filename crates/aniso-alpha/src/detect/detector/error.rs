//! The error of a detection run.

use super::super::filter::FilterError;
use super::super::orientations::OrientationError;
use super::super::scan::ScanError;
use crate::aniso::AnisotropyError;
use std::fmt;

/// Error of a detection run.
#[derive(Debug, Clone, PartialEq)]
pub enum DetectError {
    /// A parameter is out of range (the message says which).
    BadParameter(String),
    /// The input holds no point.
    Empty,
    /// Every point is at one position: no spacing to estimate α and λ
    /// from (give them).
    NoSpacing,
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// Index of the point.
        index: usize,
    },
    /// A coordinate's magnitude is above 1e50 or below 1e-30 (and not 0):
    /// outside the range where the exact arithmetic is guaranteed after
    /// the anisotropic transform. Rescale the data.
    OutOfRange {
        /// Index of the point.
        index: usize,
    },
    /// The orientation sampler's parameters are invalid.
    Orientations(OrientationError),
    /// The anisotropy is invalid.
    Anisotropy(AnisotropyError),
    /// The run was cancelled by the progress callback.
    Cancelled,
    /// A region run's scratch file (its part ids, kept on disk) could not
    /// be made, written or read (the operating system's message).
    Scratch(String),
    /// The input read in pieces changed during the run (a piece holds
    /// other points than when the run began).
    InputChanged(String),
    /// An internal invariant broke (a bug: please report it).
    Internal(String),
}

impl fmt::Display for DetectError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DetectError::BadParameter(m) => write!(f, "bad parameter: {m}"),
            DetectError::Empty => write!(f, "no points"),
            DetectError::NoSpacing => write!(
                f,
                "bad parameter: no spacing to estimate alpha and lambda from (every point is at \
                 one position): give alpha, lambda3 and min-size"
            ),
            DetectError::NonFinite { index } => {
                write!(f, "point {index} has a non-finite coordinate")
            }
            DetectError::OutOfRange { index } => write!(
                f,
                "point {index} has a coordinate outside 1e-30..1e50 in magnitude (or 0), \
                 the range of exact arithmetic for detection (narrower than the triangulation's \
                 1e-60..1e55, so that the points mapped by the ellipsoids stay inside it): rescale \
                 the data"
            ),
            DetectError::Orientations(e) => write!(f, "orientations: {e}"),
            DetectError::Anisotropy(e) => write!(f, "anisotropy: {e}"),
            DetectError::Cancelled => write!(f, "cancelled"),
            DetectError::Scratch(m) => write!(f, "the region run's scratch file failed: {m}"),
            DetectError::InputChanged(m) => write!(f, "the input changed during the run: {m}"),
            DetectError::Internal(m) => write!(f, "internal error (a bug, please report): {m}"),
        }
    }
}

impl std::error::Error for DetectError {}

impl From<OrientationError> for DetectError {
    fn from(e: OrientationError) -> Self {
        DetectError::Orientations(e)
    }
}
impl From<AnisotropyError> for DetectError {
    fn from(e: AnisotropyError) -> Self {
        DetectError::Anisotropy(e)
    }
}
impl From<FilterError> for DetectError {
    fn from(e: FilterError) -> Self {
        DetectError::Internal(format!("filter: {e}"))
    }
}
impl From<ScanError> for DetectError {
    fn from(e: ScanError) -> Self {
        match e {
            ScanError::Triangulation(t) => DetectError::Internal(format!(
                "triangulation of the transformed points failed: {t}"
            )),
            ScanError::Filter(f) => f.into(),
        }
    }
}
