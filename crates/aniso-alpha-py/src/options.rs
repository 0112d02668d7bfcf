//! A detection's keyword arguments (a dict from `aniso_alpha.detect`) as
//! the library's [`DetectOptions`], the builder the CLI uses too; errors
//! name the arguments as Python spells them (`min_size`).

use aniso_alpha::detect::{Detector, StructureKind};
use aniso_alpha::options::{DetectOptions, SamplerChoice, Style};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::value_error;

/// The keys `options` may hold.
const KEYS: [&str; 10] = [
    "alpha", "lambda2", "lambda3", "min_size", "sampler", "m1", "m2", "step", "epsilon", "tile",
];

/// `structure` ("lines" or "planes") and the options in `options` (a key
/// absent or None: the default; `epsilon` None: no significance test).
pub fn detect_options(
    structure: &str,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<DetectOptions> {
    let kind = match structure {
        "lines" => StructureKind::Lines,
        "planes" => StructureKind::Planes,
        other => {
            return Err(PyValueError::new_err(format!(
                "structure must be \"lines\" or \"planes\", got {other:?}"
            )))
        }
    };
    let mut o = DetectOptions::new(kind);
    let Some(options) = options else {
        return Ok(o);
    };
    for key in options.keys() {
        let key: String = key.extract()?;
        if !KEYS.contains(&key.as_str()) {
            return Err(PyTypeError::new_err(format!(
                "unexpected option {key:?} (options: {})",
                KEYS.join(", ")
            )));
        }
    }
    let float = |name: &str| -> PyResult<Option<f64>> {
        match options.get_item(name)? {
            Some(v) if !v.is_none() => v.extract::<f64>().map(Some).map_err(|_| {
                PyTypeError::new_err(format!("{name} must be a number, got {}", type_name(&v)))
            }),
            _ => Ok(None),
        }
    };
    let count = |name: &str| -> PyResult<Option<u64>> {
        match options.get_item(name)? {
            Some(v) if !v.is_none() => {
                if v.is_instance_of::<pyo3::types::PyBool>() {
                    return Err(PyTypeError::new_err(format!(
                        "{name} must be an integer, got bool"
                    )));
                }
                let i: i128 = v.extract().map_err(|_| {
                    PyTypeError::new_err(format!(
                        "{name} must be an integer, got {}",
                        type_name(&v)
                    ))
                })?;
                u64::try_from(i).map(Some).map_err(|_| {
                    PyValueError::new_err(format!(
                        "bad parameter: {name} must be between 1 and {}, got {i}",
                        u32::MAX
                    ))
                })
            }
            _ => Ok(None),
        }
    };
    o.alpha = float("alpha")?;
    o.lambda2 = float("lambda2")?;
    o.lambda3 = float("lambda3")?;
    o.min_size = count("min_size")?;
    if let Some(m1) = float("m1")? {
        o.m1 = m1;
    }
    if let Some(m2) = count("m2")? {
        o.m2 = m2;
    }
    if let Some(step) = float("step")? {
        o.step = step;
    }
    if options.contains("epsilon")? {
        o.epsilon = float("epsilon")?;
    }
    o.tile = float("tile")?;
    o.sampler = match options.get_item("sampler")? {
        Some(v) if !v.is_none() => {
            let s: String = v.extract().map_err(|_| {
                PyTypeError::new_err(format!("sampler must be a string, got {}", type_name(&v)))
            })?;
            Some(SamplerChoice::parse(&s).ok_or_else(|| {
                PyValueError::new_err(format!(
                    "sampler must be \"data\", \"box\" or \"fibonacci\", got {s:?}"
                ))
            })?)
        }
        _ => None,
    };
    o.check(Style::Python).map_err(value_error)?;
    Ok(o)
}

/// The detector of a call: [`DetectOptions::build`], errors as
/// `ValueError` naming Python's arguments.
pub fn build(
    options: &DetectOptions,
    points: &[[f64; 3]],
    normals: Option<&[[f64; 3]]>,
) -> PyResult<Detector> {
    options
        .build(points, normals, Style::Python)
        .map_err(value_error)
}

fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}
