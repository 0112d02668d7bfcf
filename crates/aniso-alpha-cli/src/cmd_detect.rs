//! `aniso-alpha detect`: structures by anisotropic alpha-shapes (docs/method.md §4).

use std::path::PathBuf;

use std::time::Instant;

use aniso_alpha::detect::detector::{Detection, Detector, Primitive};
use aniso_alpha::detect::orientations::Sampler;
use aniso_alpha::eval::evaluate;
use aniso_alpha::io::{Mesh, ReadOptions};
use aniso_alpha::synth::{write_xyz_labels_parts, SceneOptions};
use clap::{Args, ValueEnum};
use serde_json::json;

use crate::common::{self, parse_positive, CliError, Timings};

/// What `detect` looks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Structure {
    /// Linear structures (k = 1): E = (1, 1, 1/lambda3)
    Lines,
    /// Planar structures (k = 2): E = (1, 1/lambda2, 1/lambda3)
    Planes,
}

/// Arguments of `detect`.
#[derive(Debug, Args)]
#[command(
    after_help = "Without INPUT, runs on a built-in example scene (a Fig. 10-like polyhedron in \
uniform background, planes, alpha 1, lambda2 4, lambda3 8, min-size 20) and says where it wrote \
its results.\n\
--labels writes one integer per input point, one per line: its structure id, or -1.\n\n\
Examples:\n  aniso-alpha detect\n  \
aniso-alpha detect scene.xyz --structure lines --alpha 1 --lambda3 10 --min-size 4 --labels labels.txt\n  \
aniso-alpha detect scan.ply --structure planes --alpha 1 --lambda2 4 --lambda3 8 --min-size 20 \
--output planes.ply --report report.json --threads 2"
)]
pub struct DetectArgs {
    /// Input point file; omit it to run the built-in example
    #[arg(requires_all = ["structure", "alpha", "lambda3", "min_size"])]
    pub input: Option<PathBuf>,
    /// Look for lines or planes
    #[arg(long, value_enum)]
    pub structure: Option<Structure>,
    /// Alpha, a radius: the ellipsoid's short semi-axis (CGAL's Alpha_shape_3
    /// takes the squared radius; docs/method.md §5)
    #[arg(long, value_name = "A", value_parser = parse_positive)]
    pub alpha: Option<f64>,
    /// Elongation lambda2 of planes (default: lambda3)
    #[arg(long, value_name = "L2", value_parser = parse_positive)]
    pub lambda2: Option<f64>,
    /// Elongation lambda3 (the long axis)
    #[arg(long, value_name = "L3", value_parser = parse_positive)]
    pub lambda3: Option<f64>,
    /// Minimum size nb_c of a structure (simplices)
    #[arg(long, value_name = "NBC")]
    pub min_size: Option<usize>,
    /// Orientation sampling step on the box surface
    #[arg(long, value_name = "M1", default_value_t = 0.3, value_parser = parse_positive)]
    pub m1: f64,
    /// Number of rotations theta about the normal (planes)
    #[arg(long, value_name = "M2", default_value_t = 12)]
    pub m2: usize,
    /// Write one label per input point (structure id or -1)
    #[arg(long, value_name = "OUT.txt")]
    pub labels: Option<PathBuf>,
    /// Write the detected simplices (PLY, or OBJ by extension)
    #[arg(long, value_name = "OUT.ply")]
    pub output: Option<PathBuf>,
    /// Write a JSON report of the structures
    #[arg(long, value_name = "OUT.json")]
    pub report: Option<PathBuf>,
    /// Write one part (facet) label per input point, or -1
    #[arg(long, value_name = "OUT.txt")]
    pub part_labels: Option<PathBuf>,
    /// Orientation sampler: the paper's box (default) or near-uniform
    /// Fibonacci directions with --step degrees
    #[arg(long, value_enum, default_value_t = SamplerKind::Box)]
    pub sampler: SamplerKind,
    /// Angular step (degrees) of the Fibonacci sampler
    #[arg(long, value_name = "DEG", default_value_t = 10.0, value_parser = parse_positive)]
    pub step: f64,
    /// Write an interactive 3D view of the result (one self-contained HTML file)
    #[arg(long, value_name = "OUT.html")]
    pub html: Option<PathBuf>,
    /// Write a picture of the result (PNG, fixed view)
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    #[command(flatten)]
    pub common: crate::CommonArgs,
}

/// The orientation sampler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SamplerKind {
    /// The paper's box sampler (--m1, --m2)
    Box,
    /// Near-uniform Fibonacci directions (--step)
    Fibonacci,
}

/// Runs `detect`.
pub fn run(args: &DetectArgs, timings: &mut Timings) -> Result<(), CliError> {
    let example = args.input.is_none();
    // The built-in example writes into a folder of its own.
    let dir = PathBuf::from("aniso-alpha-example");
    let pick = |given: &Option<PathBuf>, name: &str| -> Option<PathBuf> {
        given.clone().or_else(|| example.then(|| dir.join(name)))
    };
    let labels_path = pick(&args.labels, "labels.txt");
    let parts_path = pick(&args.part_labels, "parts.txt");
    let output_path = pick(&args.output, "structures.ply");
    let report_path = pick(&args.report, "report.json");
    let html_path = pick(&args.html, "view.html");
    let scene_path = example.then(|| dir.join("scene.xyz"));
    if example {
        std::fs::create_dir_all(&dir)
            .map_err(|e| CliError::msg(format!("{}: cannot create folder: {e}", dir.display())))?;
    }
    common::check_outputs([
        labels_path.as_deref(),
        parts_path.as_deref(),
        report_path.as_deref(),
        scene_path.as_deref(),
        html_path.as_deref(),
        args.png.as_deref(),
    ])?;
    if let Some(out) = &output_path {
        common::check_mesh_output(out)?;
    }
    let (points, truth, name) = match &args.input {
        Some(input) => {
            let cloud = common::read_input(input, &ReadOptions::default(), timings)?;
            (cloud.points, None, input.display().to_string())
        }
        None => {
            let scene = timings.phase("synth", || SceneOptions::polyhedron().seed(1).generate())?;
            if let Some(p) = &scene_path {
                common::write_output(p, timings, |w| {
                    let mut w = std::io::BufWriter::new(w);
                    write_xyz_labels_parts(&scene, &mut w)?;
                    std::io::Write::flush(&mut w)
                })?;
            }
            let name = "built-in example (Fig. 10-like polyhedron in background)".to_string();
            (scene.points.clone(), Some(scene), name)
        }
    };
    let structure = args.structure.unwrap_or(Structure::Planes);
    let alpha = args.alpha.unwrap_or(1.0);
    let lambda3 = args.lambda3.unwrap_or(8.0);
    let lambda2 = args.lambda2.unwrap_or(if example { 4.0 } else { lambda3 });
    let nb_c = args.min_size.unwrap_or(20);
    let nb_c = u32::try_from(nb_c).map_err(|_| CliError::msg("--min-size is too large"))?;
    let sampler = match args.sampler {
        SamplerKind::Box => Sampler::Box {
            m1: args.m1,
            m2: u32::try_from(args.m2).map_err(|_| CliError::msg("--m2 is too large"))?,
        },
        SamplerKind::Fibonacci => Sampler::Fibonacci {
            step_degrees: args.step,
        },
    };
    let detector = match structure {
        Structure::Lines => Detector::lines(alpha, lambda3, nb_c),
        Structure::Planes => Detector::planes(alpha, lambda2, lambda3, nb_c),
    }
    .sampler(sampler);
    let n_orient = detector.orientation_set()?.len();
    let bar = common::progress(n_orient as u64, "orientations");
    let tick = |done: usize, _total: usize| {
        bar.set_position(done as u64);
        true
    };
    let start = Instant::now();
    let det = timings
        .phase("detect", || detector.clone().progress(&tick).run(&points))
        .map_err(|e| match &args.input {
            Some(p) => CliError::in_file(p, e),
            None => CliError::msg(e.to_string()),
        })?;
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();

    let part_labels = det.part_labels();
    if let Some(p) = &labels_path {
        common::write_output(p, timings, |w| write_ints(w, &det.labels))?;
    }
    if let Some(p) = &parts_path {
        common::write_output(p, timings, |w| write_ints(w, &part_labels))?;
    }
    if let Some(p) = &output_path {
        let (edges, faces) = split_simplices(&det);
        let mesh = Mesh {
            points: &points,
            labels: Some(&det.labels),
            edges: &edges,
            faces: &faces,
        };
        common::write_mesh(p, &mesh, timings)?;
    }
    let params = json!({
        "structure": match structure { Structure::Lines => "lines", Structure::Planes => "planes" },
        "k": det.kind.k(),
        "alpha": alpha,
        "lambda2": if structure == Structure::Planes { Some(lambda2) } else { None },
        "lambda3": lambda3,
        "min_size": nb_c,
        "sampler": match sampler {
            Sampler::Box { m1, m2 } => json!({"kind": "box", "m1": m1, "m2": m2}),
            Sampler::Fibonacci { step_degrees } => json!({"kind": "fibonacci", "step_degrees": step_degrees}),
        },
        "elongation": detector.elongation(),
    });
    let scores = truth.as_ref().and_then(|scene| {
        evaluate(
            &scene.labels,
            Some(&scene.parts),
            &det.labels,
            Some(&part_labels),
        )
        .ok()
    });
    {
        let mut report = json!({
            "input": name,
            "points": points.len(),
            "parameters": params,
            "orientations": det.stats.orientations,
            "stats": {
                "triangulated_points": det.stats.triangulated_points,
                "raw_simplices": det.stats.raw_simplices,
                "filtered_simplices": det.stats.filtered_simplices,
                "union_simplices": det.stats.union_simplices,
                "kept_simplices": det.stats.kept_simplices,
                "structure_simplices": det.stats.structure_simplices,
            },
            "structures": det.structures.iter().map(structure_json).collect::<Vec<_>>(),
            "background_points": det.labels.iter().filter(|&&l| l < 0).count(),
            "seconds": seconds,
        });
        // Wall seconds of the phases so far (the report itself is the last
        // output written).
        report["timings"] = timings.to_value();
        if let Some(ev) = &scores {
            report["scores"] = json!({
                "precision": ev.precision, "recall": ev.recall, "f1": ev.f1,
                "structures_found": ev.structures_found, "structures_total": ev.structures_total,
                "parts_found": ev.parts_found, "parts_total": ev.parts_total,
            });
        }
        if let Some(p) = &report_path {
            common::write_json(p, &report, timings)?;
        }
        if let Some(p) = &html_path {
            crate::view::write_html(
                p,
                &name,
                &points,
                &det.labels,
                &part_labels,
                &report,
                timings,
            )?;
        }
    }
    if let Some(p) = &args.png {
        crate::picture::write_detection_png(p, &points, &det, &part_labels, timings)?;
    }
    let mut out = summary(&name, &det, &params, seconds);
    if let Some(ev) = &scores {
        out.push_str(&format!("\nAgainst the scene's ground truth:\n{ev}\n"));
    }
    if example {
        out.push_str(&format!(
            "\nWrote {}: scene.xyz (x y z label part), labels.txt, parts.txt, structures.ply, report.json, view.html\n",
            dir.display()
        ));
    }
    common::print_summary(&out)
}

fn write_ints(w: &mut dyn std::io::Write, values: &[i64]) -> std::io::Result<()> {
    let mut s = String::with_capacity(values.len() * 3);
    for v in values {
        s.push_str(&v.to_string());
        s.push('\n');
    }
    w.write_all(s.as_bytes())
}

fn split_simplices(det: &Detection) -> (Vec<[u32; 2]>, Vec<[u32; 3]>) {
    let mut edges = Vec::new();
    let mut faces = Vec::new();
    for s in &det.simplices {
        match s.as_slice() {
            [a, b] => edges.push([*a, *b]),
            [a, b, c] => faces.push([*a, *b, *c]),
            _ => {}
        }
    }
    (edges, faces)
}

fn primitive_json(p: &Primitive) -> serde_json::Value {
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

fn kind_name(s: &aniso_alpha::detect::detector::Structure) -> &'static str {
    match (&s.primitive, s.parts.len()) {
        (Primitive::Line(_), 1) => "line",
        (Primitive::Line(_), _) => "polyline",
        (Primitive::Plane(_), 1) => "plane",
        (Primitive::Plane(_), _) => "surface",
        (Primitive::None, _) => "?",
    }
}

fn structure_json(s: &aniso_alpha::detect::detector::Structure) -> serde_json::Value {
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

fn summary(name: &str, det: &Detection, params: &serde_json::Value, seconds: f64) -> String {
    let mut o = String::new();
    o.push_str(&format!("aniso-alpha detect: {name}\n"));
    o.push_str(&format!(
        "  {} points; {} (k = {}), alpha {}, {}lambda3 {}, min-size {}\n",
        det.labels.len(),
        params["structure"].as_str().unwrap_or("?"),
        det.kind.k(),
        params["alpha"].as_f64().unwrap_or(f64::NAN),
        params["lambda2"]
            .as_f64()
            .map(|l| format!("lambda2 {l}, "))
            .unwrap_or_default(),
        params["lambda3"].as_f64().unwrap_or(f64::NAN),
        params["min_size"],
    ));
    o.push_str(&format!(
        "  {} orientations in {:.2} s; union {} simplices, {} kept in structures\n\n",
        det.stats.orientations, seconds, det.stats.union_simplices, det.stats.structure_simplices
    ));
    o.push_str("   id  kind      points  simplices  parts   rms      extent            centroid\n");
    for s in det.structures.iter().take(20) {
        let (rms, extent, c) = match &s.primitive {
            Primitive::Line(f) => (f.rms_residual, format!("{:.2}", f.extent), f.centroid),
            Primitive::Plane(f) => (
                f.rms_residual,
                format!("{:.2} x {:.2}", f.extent[0], f.extent[1]),
                f.centroid,
            ),
            Primitive::None => (f64::NAN, "-".into(), [f64::NAN; 3]),
        };
        o.push_str(&format!(
            "  {:>3}  {:<8} {:>7}  {:>9}  {:>5}  {:>7.3}  {:<16}  ({:.2}, {:.2}, {:.2})\n",
            s.id,
            kind_name(s),
            s.vertices.len(),
            s.simplices.len(),
            s.parts.len(),
            rms,
            extent,
            c[0],
            c[1],
            c[2]
        ));
    }
    if det.structures.len() > 20 {
        o.push_str(&format!(
            "  ... and {} more (see --report)\n",
            det.structures.len() - 20
        ));
    }
    let bg = det.labels.iter().filter(|&&l| l < 0).count();
    o.push_str(&format!(
        "  {} structure(s); {} of {} points are background\n",
        det.structures.len(),
        bg,
        det.labels.len()
    ));
    o
}
