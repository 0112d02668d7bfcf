//! The JSON report of a detection (method doc §7), shared by the CLI's
//! `--report` and the Python package (cargo feature `json`).
//!
//! ```
//! use aniso_alpha::detect::Detector;
//! use aniso_alpha::report::detection_json;
//! let scene = aniso_alpha::synth::lines(1);
//! let d = Detector::lines(1.0, 10.0, 4);
//! let det = d.run(&scene.points).unwrap();
//! let r = detection_json(&det, &d);
//! assert_eq!(r["parameters"]["alpha"]["value"], 1.0);
//! assert_eq!(r["parameters"]["alpha"]["estimated"], false);
//! let part = &r["structures"][0]["parts"][0];
//! assert_eq!(part["segment"].as_array().unwrap().len(), 2);
//! ```

use crate::detect::orientations::Sampler;
use crate::detect::quantized::Quantization;
use crate::detect::StructureKind;
use crate::detect::{Detection, Detector, OrientationSet, Part, Primitive, Structure};
use serde_json::{json, Value};

/// A finite number, or null (JSON has no infinities).
fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// The shares of the cloud that the orientation modes of the given and of
/// the estimated normals explain ([`crate::detect::GivenNormals`]).
fn explained((given, estimated): (f64, f64)) -> Value {
    json!({"given": num(given), "estimated": num(estimated)})
}

fn param(value: f64, estimated: bool, reason: &str) -> Value {
    json!({"value": num(value), "estimated": estimated, "reason": reason})
}

/// The `parameters.quantized` list: each axis whose coordinates lie on
/// levels coarser than a point's neighbourhood, with the levels' median
/// step and the neighbourhood's reach; the run saw its points dithered
/// within their level ([`crate::detect::quantized`]). Empty for almost
/// every cloud.
pub fn quantized_json(q: &Quantization) -> Value {
    q.axes
        .iter()
        .map(|a| json!({"axis": a.name(), "step": num(a.step), "reach": num(a.reach), "coarse": a.coarse, "terraced": num(a.terraced), "dithered": true}))
        .collect()
}

/// The `parameters` object: every value used, whether it was estimated,
/// and why.
pub fn parameters_json(d: &Detector) -> Value {
    let kind = d.kind();
    let (l2, l3) = d.lambdas();
    let e = d.estimate();
    let p = |name: &str, value: f64| -> Value {
        match e {
            Some(e) => {
                let q = match name {
                    "alpha" => &e.alpha,
                    "lambda2" => &e.lambda2,
                    "lambda3" => &e.lambda3,
                    _ => &e.min_size,
                };
                param(q.value, q.estimated, &q.reason)
            }
            None => param(value, false, "given"),
        }
    };
    let mut orientations = match d.orientations() {
        OrientationSet::Sampler(Sampler::Box { m1, m2 }) => {
            json!({"kind": "box", "m1": m1, "m2": m2, "count": d.orientation_count().unwrap_or(0)})
        }
        OrientationSet::Sampler(Sampler::Fibonacci { step_degrees }) => {
            json!({"kind": "fibonacci", "step_degrees": step_degrees, "count": d.orientation_count().unwrap_or(0)})
        }
        OrientationSet::Rotations(r) => json!({"kind": "rotations", "count": r.len()}),
        OrientationSet::Data(modes) => json!({
            "kind": "data",
            "count": d.orientation_count().unwrap_or(0),
            "modes": modes.iter().map(mode_json).collect::<Vec<_>>(),
        }),
    };
    if let Some(l) = d.ladder() {
        orientations["ladder"] = json!({
            "alphas": l.alphas.iter().copied().map(num).collect::<Vec<_>>(),
            "lambda": num(l.lambda),
            "points": l.points.len(),
        });
    }
    let mut v = json!({
        "structure": match kind { StructureKind::Lines => "lines", StructureKind::Planes => "planes" },
        "k": kind.k(),
        "alpha": p("alpha", d.alpha()),
        "lambda2": if kind == StructureKind::Planes { p("lambda2", l2) } else { Value::Null },
        "lambda3": p("lambda3", l3),
        "min_size": p("min_size", f64::from(d.min_size())),
        "epsilon": match d.epsilon() {
            Some(eps) => param(eps, false, "default: at most one false alarm expected"),
            None => Value::Null,
        },
        "elongation": d.elongation().map(num),
        "orientations": orientations,
        "normals": match (kind, d.normals_given(), d.given_normals()) {
            (StructureKind::Planes, Some(n), g) => json!({
                "source": "input",
                "usable": n,
                "agreement": g.map(|g| num(g.agreement)),
                "explained": g.and_then(|g| g.explained).map(explained),
                "modes_from": g.map(|g| g.modes_from()),
                "gate": true,
            }),
            (StructureKind::Planes, None, Some(g)) => json!({
                "source": "estimated",
                "input_ignored": true,
                "agreement": num(g.agreement),
                "explained": g.explained.map(explained),
                "modes_from": g.modes_from(),
                "gate": false,
                "reason": g.ignored_reason(),
            }),
            _ => json!({"source": "estimated"}),
        },
    });
    if let Some(e) = e {
        v["estimates"] = json!({
            "spacing_median": num(e.spacing_median),
            "spacing": num(e.spacing),
            "noise": num(e.noise),
            "structure_fraction": num(e.structure_fraction),
            "explained": num(e.explained),
            "structured": num(e.structured),
            "ladder_declined_points": e.ladder_declined,
        });
    }
    v
}

/// One mode of the data orientation set as the report writes it.
fn mode_json(m: &crate::detect::ModeScan) -> Value {
    json!({
        "axis": m.axis.map(num),
        "support": m.support,
        "points": m.points.len(),
        "spacing": num(m.spacing),
        "noise": num(m.noise),
        "alpha": num(m.alpha),
        "lambda2": num(m.lambda2),
        "lambda3": num(m.lambda3),
        "rotations": m.rotations.len(),
        "thinned_from": m.thinned_from,
        "cloud_scale": m.cloud_scale,
        "cover": m.cover,
    })
}

fn point(p: [f64; 3]) -> Value {
    json!(p.map(num))
}

/// One part: `plane`, `points`, `rms`, `polygon` for a planar part;
/// `segment`, `points`, `rms` for a straight one; its `log10_nfa`.
pub fn part_json(id: usize, p: &Part) -> Value {
    let mut v = json!({
        "id": id,
        "points": p.vertices.len(),
        "rms": num(p.primitive.rms()),
        "log10_nfa": num(p.log10_nfa),
        "simplices": p.simplices.len(),
    });
    match &p.primitive {
        Primitive::Plane(f) => {
            v["plane"] = json!(p.plane().unwrap_or([f64::NAN; 4]).map(num));
            v["polygon"] = json!(p.outline.iter().map(|&q| point(q)).collect::<Vec<_>>());
            v["triangles"] = json!(p.mesh.len());
            v["centroid"] = point(f.centroid);
            v["extent"] = json!(f.extent.map(num));
        }
        Primitive::Line(f) => {
            if let Some([a, b]) = p.segment() {
                v["segment"] = json!([point(a), point(b)]);
            }
            v["length"] = num(f.extent);
            v["direction"] = point(f.direction);
        }
        Primitive::None => {}
    }
    v
}

/// One structure with its parts (`first_part` is the global id of its
/// first part, as in the part labels).
pub fn structure_json(s: &Structure, first_part: usize) -> Value {
    let mut v = json!({
        "id": s.id,
        "kind": s.kind_name(),
        "points": s.vertices.len(),
        "simplices": s.simplices.len(),
        "log10_nfa": num(s.log10_nfa),
        "parts": s.parts.iter().enumerate().map(|(k, p)| part_json(first_part + k, p)).collect::<Vec<_>>(),
    });
    if s.parts.len() == 1 {
        v["rms"] = num(s.primitive.rms());
        if let Some(pl) = s.primitive.plane_equation() {
            v["plane"] = json!(pl.map(num));
        }
    }
    v
}

/// The structures array.
pub fn structures_json(det: &Detection) -> Value {
    let mut first = 0;
    Value::Array(
        det.structures
            .iter()
            .map(|s| {
                let v = structure_json(s, first);
                first += s.parts.len();
                v
            })
            .collect(),
    )
}

/// The whole report of a run: `parameters`, `orientations`, `stats`,
/// `structures`, `parts` and `background_points` (the CLI adds the input's
/// name, times and scores).
pub fn detection_json(det: &Detection, d: &Detector) -> Value {
    let s = &det.stats;
    json!({
        "points": det.labels.len(),
        "parameters": parameters_json(d),
        "orientations": s.orientations,
        "stats": {
            "triangulated_points": s.triangulated_points,
            "raw_simplices": s.raw_simplices,
            "filtered_simplices": s.filtered_simplices,
            "union_simplices": s.union_simplices,
            "kept_simplices": s.kept_simplices,
            "structure_simplices": s.structure_simplices,
            "rejected_parts": s.rejected_parts,
            "surface_lines": s.surface_lines,
            "out_of_proportion": s.out_of_proportion,
            "faces_apart": s.faces_apart,
            "reclaimed_points": s.reclaimed_points,
        },
        "structures": structures_json(det),
        "parts": det.num_parts(),
        "background_points": det.labels.iter().filter(|&&l| l < 0).count(),
    })
}

/// The clean meshes of a detection's parts over the input points, as the
/// CLI's `detect --output` and the Python package's `write` add them to a
/// PLY: a planar part's triangles (its 2D α-shape), a straight part's
/// polyline through its points in order along the line.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PartMeshes {
    /// The straight parts' edges.
    pub edges: Vec<[u32; 2]>,
    /// The planar parts' triangles.
    pub faces: Vec<[u32; 3]>,
    /// (structure id, global part id) of each edge, then of each face.
    pub element_labels: Vec<[i64; 2]>,
}

/// The [`PartMeshes`] of `det`, run on `points`.
pub fn part_meshes(det: &Detection, points: &[[f64; 3]]) -> PartMeshes {
    let mut edges = Vec::new();
    let mut edge_labels = Vec::new();
    let mut faces = Vec::new();
    let mut face_labels = Vec::new();
    let mut part = 0i64;
    for s in &det.structures {
        for p in &s.parts {
            let l = [i64::from(s.id), part];
            faces.extend_from_slice(&p.mesh);
            face_labels.extend(std::iter::repeat_n(l, p.mesh.len()));
            if let Primitive::Line(f) = &p.primitive {
                let mut along: Vec<(f64, u32)> = p
                    .vertices
                    .iter()
                    .map(|&v| {
                        let q = points[v as usize];
                        let t = (0..3)
                            .map(|k| (q[k] - f.centroid[k]) * f.direction[k])
                            .sum::<f64>();
                        (t, v)
                    })
                    .collect();
                along.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                for w in along.windows(2) {
                    edges.push([w[0].1, w[1].1]);
                    edge_labels.push(l);
                }
            }
            part += 1;
        }
    }
    edge_labels.extend(face_labels);
    PartMeshes {
        edges,
        faces,
        element_labels: edge_labels,
    }
}
