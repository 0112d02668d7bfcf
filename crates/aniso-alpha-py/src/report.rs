//! The JSON of a detection: `{"structures": [...], "parameters": {...}}`,
//! as in the report `aniso-alpha detect --report` writes.
//!
//! Interim: a copy of the CLI's current `structure_json` until the library
//! has `aniso_alpha::report::detection_json` (feature `json`), which the
//! CLI and these bindings will then share.

use aniso_alpha::detect::detector::{Detection, Detector, Primitive, Structure};
use aniso_alpha::detect::StructureKind;
use serde_json::{json, Value};

/// The report's `structures` and `parameters`.
pub fn detection_json(det: &Detection, detector: &Detector, params: &Given) -> Value {
    let planes = det.kind == StructureKind::Planes;
    json!({
        "structures": det.structures.iter().map(structure_json).collect::<Vec<_>>(),
        "parameters": {
            "structure": if planes { "planes" } else { "lines" },
            "k": det.kind.k(),
            "alpha": params.alpha,
            "lambda2": if planes { Some(params.lambda2) } else { None },
            "lambda3": params.lambda3,
            "min_size": params.min_size,
            "sampler": {"kind": "box", "m1": 0.3, "m2": 12},
            "elongation": detector.elongation(),
        },
    })
}

/// The parameters of an explicit run.
pub struct Given {
    pub alpha: f64,
    pub lambda2: f64,
    pub lambda3: f64,
    pub min_size: u32,
}

fn primitive_json(p: &Primitive) -> Value {
    match p {
        Primitive::Line(f) => json!({
            "type": "line", "centroid": f.centroid, "direction": f.direction,
            "rms_residual": f.rms_residual, "extent": f.extent,
        }),
        Primitive::Plane(f) => json!({
            "type": "plane", "centroid": f.centroid, "normal": f.normal, "axes": f.axes,
            "rms_residual": f.rms_residual, "extent": f.extent,
        }),
        Primitive::None => json!(null),
    }
}

fn kind_name(s: &Structure) -> &'static str {
    match (&s.primitive, s.parts.len()) {
        (Primitive::Line(_), 1) => "line",
        (Primitive::Line(_), _) => "polyline",
        (Primitive::Plane(_), 1) => "plane",
        (Primitive::Plane(_), _) => "surface",
        (Primitive::None, _) => "?",
    }
}

fn structure_json(s: &Structure) -> Value {
    json!({
        "id": s.id,
        "kind": kind_name(s),
        "points": s.vertices.len(),
        "simplices": s.simplices.len(),
        "primitive": primitive_json(&s.primitive),
        "parts": s.parts.iter().map(|p| json!({
            "points": p.vertices.len(),
            "simplices": p.simplices.len(),
            "primitive": primitive_json(&p.primitive),
        })).collect::<Vec<_>>(),
    })
}
