//! The JSON of a detection: the library's report
//! ([`aniso_alpha::report::detection_json`], the one `aniso-alpha detect
//! --report` writes), of which the Python `Detection` keeps `structures`
//! and `parameters`.

use aniso_alpha::detect::quantized::Quantization;
use aniso_alpha::detect::{Detection, Detector};

/// The report as JSON text, with the quantized axes the run saw dithered
/// (`parameters.quantized`, as the CLI's report has them).
pub fn detection_json(det: &Detection, detector: &Detector, quantization: &Quantization) -> String {
    let mut r = aniso_alpha::report::detection_json(det, detector);
    r["parameters"]["quantized"] = aniso_alpha::report::quantized_json(quantization);
    r.to_string()
}
