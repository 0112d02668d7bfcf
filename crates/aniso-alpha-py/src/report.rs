//! The JSON of a detection: `{"structures": [...], "parameters": {...}}`,
//! as in the report `aniso-alpha detect --report` writes.
//!
//! Interim: the structures are a copy of the CLI's current `structure_json`
//! (so that the bindings' structures equal the CLI's report), until the
//! library has `aniso_alpha::report::detection_json` (feature `json`), which
//! the CLI and these bindings will then share.

use aniso_alpha::detect::detector::{Detection, Detector, Param, Primitive, Structure};
use aniso_alpha::detect::StructureKind;
use serde_json::{json, Map, Value};

/// The report's `structures` and `parameters`. With explicit parameters the
/// `parameters` are the CLI's (structure, k, alpha, lambda2, lambda3,
/// min_size, sampler, elongation); when [`Detector::auto`] estimated some,
/// `"sampler"` is `"data"` (the data orientation set: `"modes"` counts its
/// modes, `"orientations"` its rotations) and `"estimated"` and `"reasons"`
/// say, for each of alpha, lambda2, lambda3 and min_size, whether it was
/// estimated and why it has its value.
pub fn detection_json(det: &Detection, detector: &Detector) -> Value {
    let planes = det.kind == StructureKind::Planes;
    let (lambda2, lambda3) = detector.lambdas();
    let mut params = Map::new();
    params.insert(
        "structure".into(),
        json!(if planes { "planes" } else { "lines" }),
    );
    params.insert("k".into(), json!(det.kind.k()));
    params.insert("alpha".into(), json!(detector.alpha()));
    params.insert("lambda2".into(), json!(planes.then_some(lambda2)));
    params.insert("lambda3".into(), json!(lambda3));
    params.insert("min_size".into(), json!(detector.min_size()));
    match detector.estimate() {
        None => {
            params.insert(
                "sampler".into(),
                json!({"kind": "box", "m1": 0.3, "m2": 12}),
            );
        }
        Some(e) => {
            params.insert(
                "sampler".into(),
                json!({
                    "kind": "data",
                    "modes": e.modes.len(),
                    "orientations": e.modes.iter().map(|m| m.rotations.len()).sum::<usize>(),
                }),
            );
            let named: [(&str, &Param); 4] = [
                ("alpha", &e.alpha),
                ("lambda2", &e.lambda2),
                ("lambda3", &e.lambda3),
                ("min_size", &e.min_size),
            ];
            let named = named.into_iter().filter(|(n, _)| planes || *n != "lambda2");
            let (estimated, reasons): (Map<_, _>, Map<_, _>) = named
                .map(|(n, p)| {
                    (
                        (n.to_string(), json!(p.estimated)),
                        (n.to_string(), json!(p.reason)),
                    )
                })
                .unzip();
            params.insert("estimated".into(), Value::Object(estimated));
            params.insert("reasons".into(), Value::Object(reasons));
        }
    }
    params.insert("elongation".into(), json!(detector.elongation()));
    json!({
        "structures": det.structures.iter().map(structure_json).collect::<Vec<_>>(),
        "parameters": params,
    })
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

fn structure_json(s: &Structure) -> Value {
    json!({
        "id": s.id,
        "kind": s.kind_name(),
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
