//! The JSON of a detection: the library's report
//! ([`aniso_alpha::report::detection_json`], the one `aniso-alpha detect
//! --report` writes), of which the Python `Detection` keeps `structures`
//! and `parameters`.

use aniso_alpha::detect::{Detection, Detector};

/// The report as JSON text.
pub fn detection_json(det: &Detection, detector: &Detector) -> String {
    aniso_alpha::report::detection_json(det, detector).to_string()
}
