//! `aniso-alpha detect`: structures by anisotropic alpha-shapes (method
//! doc §4, §7, §8).

use std::num::NonZeroUsize;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use aniso_alpha::detect::quantized::Quantization;
use aniso_alpha::detect::StructureKind;
use aniso_alpha::detect::{DetectError, Detection, Detector, OrientationSet, Primitive, Stage};
use aniso_alpha::eval::{evaluate, Evaluation};
use aniso_alpha::io::{self, write_scene, Mesh, PointCloud, ReadOptions};
use aniso_alpha::options::{run_warnings, DetectOptions, SamplerChoice, Style};
use aniso_alpha::report::{detection_json, part_meshes, quantized_json, PartMeshes};
use aniso_alpha::synth::{Scene, SceneOptions};
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
    after_help = "With INPUT and --structure alone, every parameter is estimated from the data \
(spacing, noise, the modes of the local normals or directions) and printed with its reason; any of \
--alpha, --lambda2, --lambda3, --min-size given overrides its estimate. With --alpha, --lambda3 and \
--min-size all given, the paper's box orientation sampler is used by default (--sampler data for the \
orientations from the data).\n\
alpha is a radius (the short semi-axis of the ellipsoid), not CGAL's squared alpha.\n\
Without INPUT, runs on a built-in example scene (a Fig. 10-like polyhedron in uniform background, \
planes, alpha 1, lambda2 4, lambda3 8, min-size 20) and says where it wrote its results.\n\
The summary prints one row per plane (or segment): its normal and a point on it, points, RMS, \
extent. --labels writes one integer per input point: its structure id, or -1 (a polyhedral \
surface, e.g. a room's six walls, is one structure); --part-labels its plane (or segment) id, \
or -1: the per-plane ids. Parts are disjoint.\n\
--output OUT.las|.laz|.ply writes the input cloud back with every attribute it had (a LAS/LAZ \
input's records byte for byte; another input to LAS becomes point format 0 with its attributes \
as extra bytes) and two int32 fields, structure and part (-1 off the structures); .obj writes \
the parts' meshes only. --classify planes=6 also gives the structures' points that LAS class; \
--background-classes 7,18 leaves the points of those classes out of the detection (labelled -1).\n\n\
Examples:\n  aniso-alpha detect\n  \
aniso-alpha detect scan.ply --structure planes --labels labels.txt --part-labels parts.txt --report report.json\n  \
aniso-alpha detect scene.xyz --structure lines --alpha 1 --lambda3 10 --min-size 4 --labels labels.txt\n  \
aniso-alpha detect scan.ply --structure planes --alpha 1 --lambda2 4 --lambda3 8 --min-size 20 \
--output planes.ply --report report.json --threads 2\n  \
aniso-alpha detect scan.laz --structure planes --output scan_labelled.laz --classify planes=6 \
--background-classes 7,18"
)]
pub struct DetectArgs {
    /// Input point file; omit it to run the built-in example
    #[arg(requires = "structure")]
    pub input: Option<PathBuf>,
    /// Look for lines or planes
    #[arg(long, value_enum)]
    pub structure: Option<Structure>,
    /// Alpha: the ellipsoid's short semi-axis, a radius (default: estimated)
    #[arg(long, allow_negative_numbers = true, value_name = "A", value_parser = parse_positive)]
    pub alpha: Option<f64>,
    /// Elongation lambda2 of planes (default: lambda3)
    #[arg(long, allow_negative_numbers = true, value_name = "L2", value_parser = parse_positive)]
    pub lambda2: Option<f64>,
    /// Elongation lambda3, the long axis (default: estimated)
    #[arg(long, allow_negative_numbers = true, value_name = "L3", value_parser = parse_positive)]
    pub lambda3: Option<f64>,
    /// Minimum size nb_c of a piece, in simplices (default: estimated)
    #[arg(long, allow_negative_numbers = true, value_name = "NBC")]
    pub min_size: Option<u64>,
    /// Orientations: the data's (modes of normals or directions), the
    /// paper's box, or near-uniform Fibonacci directions (default: data,
    /// or box when alpha, lambda3 and min-size are all given)
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerKind>,
    /// Box sampler: sampling step on the box surface
    #[arg(long, allow_negative_numbers = true, value_name = "M1", default_value_t = 0.3, value_parser = parse_positive)]
    pub m1: f64,
    /// Number of rotations theta about the normal (planes, when lambda2 != lambda3)
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "M2",
        default_value_t = 12
    )]
    pub m2: u64,
    /// Fibonacci sampler: angular step in degrees
    #[arg(long, allow_negative_numbers = true, value_name = "DEG", default_value_t = 10.0, value_parser = parse_positive)]
    pub step: f64,
    /// Significance: keep parts with at most EPS expected false alarms
    #[arg(long, allow_negative_numbers = true, value_name = "EPS", default_value_t = 1.0, value_parser = parse_positive)]
    pub epsilon: f64,
    /// Keep every part (no significance test: nb_c alone, as the paper)
    #[arg(long)]
    pub no_significance: bool,
    /// Estimate every normal from its neighbourhood even when the input
    /// gives normals (nx ny nz or normal_x normal_y normal_z in a PLY or PCD)
    #[arg(long)]
    pub ignore_normals: bool,
    /// Triangulate in tiles of this side (input units) with halos: bounded
    /// memory, the same result
    #[arg(long, allow_negative_numbers = true, value_name = "SIZE", value_parser = parse_positive)]
    pub tile: Option<f64>,
    /// Detect region by region: square columns of this side in x-y
    /// (input units), each with its own parameters from its points and a
    /// margin for its ellipsoids' reach, parts joined across borders;
    /// memory bounded by one region's run. 'auto' (the default unless an
    /// output needs a whole run: --html, --png, --union, .obj): regions of
    /// about 250,000 points, a whole run up to 1,000,000 points. 'off': one
    /// whole run. A LAS/LAZ input of a region run is read a piece at a
    /// time, never whole (not with --background-classes or a labelled
    /// .ply --output)
    #[arg(long, value_name = "SIDE|auto|off", value_parser = crate::cmd_regions::parse_regions, requires = "input")]
    pub regions: Option<crate::cmd_regions::Regions>,
    /// Regions detected at once (default: the thread count); each holds
    /// one region's run in memory, and each runs on all threads
    #[arg(long, value_name = "N", requires = "input")]
    pub region_jobs: Option<NonZeroUsize>,
    /// Write one label per input point: its structure id (a polyhedral
    /// surface is one structure), or -1
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.txt")]
    pub labels: Option<PathBuf>,
    /// Write one part label per input point: its plane (or segment) id,
    /// the per-plane ids, or -1
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.txt")]
    pub part_labels: Option<PathBuf>,
    /// Write the input points with every attribute they had, their
    /// structure and part ids, and one clean mesh per part: PLY (faces and
    /// edges with structure and part ids), LAS/LAZ (every record kept byte
    /// for byte, the ids as two int32 extra-bytes fields), or OBJ
    /// (geometry only), by extension
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.ply|las|laz")]
    pub output: Option<PathBuf>,
    /// With a .las/.laz/.ply --output: give the points of the structures
    /// found this LAS classification, e.g. planes=6 (building)
    #[arg(long, allow_negative_numbers = true, value_name = "KIND=CLASS", value_parser = common::parse_classify, requires = "output")]
    pub classify: Option<common::Classify>,
    /// Exclude the points of these LAS classes from the detection
    /// (labelled -1), comma-separated, e.g. 7,18 (noise); needs a
    /// classification (LAS, or a PLY/PCD 'classification' property)
    #[arg(long, allow_negative_numbers = true, value_name = "C1,C2,...", value_parser = common::parse_classes)]
    pub background_classes: Option<aniso_alpha::io::ClassSet>,
    /// Write the raw union of the scanned alpha-shapes (debugging; PLY or OBJ)
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.ply")]
    pub union: Option<PathBuf>,
    /// Write a JSON report: parameters (estimated or given, with reasons),
    /// structures and their parts (planes, outlines, segments, NFA)
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.json")]
    pub report: Option<PathBuf>,
    /// Write an interactive 3D view of the result (one self-contained HTML file)
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.html")]
    pub html: Option<PathBuf>,
    /// Write a picture of the result (PNG, fixed view)
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    #[command(flatten)]
    pub input_format: crate::FormatArgs,
    #[command(flatten)]
    pub common: crate::CommonArgs,
}

/// The orientation sampler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SamplerKind {
    /// The modes of the data's local normals (planes) or directions (lines)
    Data,
    /// The paper's box sampler (--m1, --m2)
    Box,
    /// Near-uniform Fibonacci directions (--step)
    Fibonacci,
}

fn kind_of(s: Structure) -> StructureKind {
    match s {
        Structure::Lines => StructureKind::Lines,
        Structure::Planes => StructureKind::Planes,
    }
}

/// The options of a run, as the library's one options-to-detector
/// builder takes them: the flags given, or for the built-in example the
/// paper's Fig. 10 parameters where no flag overrides them.
fn options(args: &DetectArgs, example: bool) -> DetectOptions {
    let structure = args.structure.unwrap_or(Structure::Planes);
    let or_example = |given: Option<f64>, v: f64| given.or(example.then_some(v));
    DetectOptions {
        alpha: or_example(args.alpha, 1.0),
        lambda2: match structure {
            Structure::Planes => or_example(args.lambda2, 4.0),
            Structure::Lines => args.lambda2,
        },
        lambda3: or_example(args.lambda3, 8.0),
        min_size: args.min_size.or(example.then_some(20)),
        sampler: args.sampler.map(|s| match s {
            SamplerKind::Data => SamplerChoice::Data,
            SamplerKind::Box => SamplerChoice::Box,
            SamplerKind::Fibonacci => SamplerChoice::Fibonacci,
        }),
        m1: args.m1,
        m2: args.m2,
        step: args.step,
        epsilon: (!args.no_significance).then_some(args.epsilon),
        tile: args.tile,
        ..DetectOptions::new(kind_of(structure))
    }
}

/// The folder the built-in example writes into.
const EXAMPLE_DIR: &str = "aniso-alpha-example";

/// Where a run writes: the paths given, or for the built-in example its
/// default files in [`EXAMPLE_DIR`].
struct OutputPaths {
    labels: Option<PathBuf>,
    parts: Option<PathBuf>,
    output: Option<PathBuf>,
    report: Option<PathBuf>,
    html: Option<PathBuf>,
    /// The example's scene (x y z label part).
    scene: Option<PathBuf>,
    /// `output` is the input cloud with its labels (.las/.laz/.ply), not
    /// the parts' meshes alone.
    labelled_output: bool,
}

impl OutputPaths {
    /// The output paths of a run, checked before any work (formats,
    /// `--classify` against the output and the structure kind, no output
    /// overwriting the input or another output); creates the example's
    /// folder.
    fn prepare(args: &DetectArgs, example: bool) -> Result<Self, CliError> {
        let dir = PathBuf::from(EXAMPLE_DIR);
        let pick = |given: &Option<PathBuf>, name: &str| -> Option<PathBuf> {
            given.clone().or_else(|| example.then(|| dir.join(name)))
        };
        let paths = OutputPaths {
            labels: pick(&args.labels, "labels.txt"),
            parts: pick(&args.part_labels, "parts.txt"),
            output: pick(&args.output, "structures.ply"),
            report: pick(&args.report, "report.json"),
            html: pick(&args.html, "view.html"),
            scene: example.then(|| dir.join("scene.xyz")),
            labelled_output: false,
        };
        if example {
            std::fs::create_dir_all(&dir).map_err(|e| {
                CliError::msg(format!("{}: cannot create folder: {e}", dir.display()))
            })?;
        }
        let labelled_output = match &paths.output {
            Some(p) => common::cloud_output(p)? == common::CloudOutput::Labelled,
            None => false,
        };
        let paths = OutputPaths {
            labelled_output,
            ..paths
        };
        check_classify(args, labelled_output)?;
        crate::cmd_regions::check_outputs(args.regions, &paths.whole_outputs(args))?;
        if let Some(out) = &args.union {
            common::mesh_format(out)?;
        }
        let inputs: Vec<&std::path::Path> = args.input.iter().map(|p| p.as_path()).collect();
        common::check_io(
            &inputs,
            &[
                ("--labels", paths.labels.as_deref()),
                ("--part-labels", paths.parts.as_deref()),
                ("--output", paths.output.as_deref()),
                ("--union", args.union.as_deref()),
                ("--report", paths.report.as_deref()),
                ("(scene)", paths.scene.as_deref()),
                ("--html", paths.html.as_deref()),
                ("--png", args.png.as_deref()),
            ],
        )?;
        Ok(paths)
    }

    /// The outputs asked for that need a whole run (the views, the union,
    /// meshes alone), by flag; the built-in example writes a view.
    fn whole_outputs(&self, args: &DetectArgs) -> Vec<&'static str> {
        let mesh_output = self.output.is_some() && !self.labelled_output;
        let mut w =
            crate::cmd_regions::whole_outputs(&self.html, &args.png, &args.union, mesh_output);
        if self.scene.is_some() {
            w.push("the built-in example");
        }
        w
    }

    /// Whether an output holds the plane parts' outlines or meshes (the
    /// report's polygons, a mesh or labelled-cloud output, the views):
    /// without one, the run skips them ([`Detector::outlines`]).
    fn holds_outlines(&self, args: &DetectArgs) -> bool {
        self.report.is_some() || self.html.is_some() || self.output.is_some() || args.png.is_some()
    }
}

/// `--classify` needs a labelled cloud output and names the structure
/// kind looked for.
fn check_classify(args: &DetectArgs, labelled_output: bool) -> Result<(), CliError> {
    if let Some(c) = args.classify {
        if !labelled_output {
            return Err(CliError::msg(
                "--classify needs a .las, .laz or .ply --output",
            ));
        }
        if c.lines != (args.structure == Some(Structure::Lines)) {
            return Err(CliError::msg(
                "--classify names another structure kind than --structure",
            ));
        }
    }
    Ok(())
}

/// What a run reads: the cloud, its normals, the example's ground truth
/// and the name the summary and report give the input.
struct Input {
    cloud: PointCloud,
    normals: Option<Vec<[f64; 3]>>,
    truth: Option<Scene>,
    name: String,
}

/// The points to run on: the input file's, or the built-in example's
/// scene (generated, and written to `paths.scene`), with the normals the
/// input gives (unless `--ignore-normals`), the scene as the ground truth
/// and the name the summary and report give the input.
fn read_cloud(
    args: &DetectArgs,
    paths: &OutputPaths,
    timings: &mut Timings,
) -> Result<Input, CliError> {
    match &args.input {
        Some(input) => {
            let keep_attributes = paths.labelled_output || args.background_classes.is_some();
            // PLY and PCD files may carry normals: read their attributes
            // to find them (planes only: lines ignore normals).
            let normals_here = !args.ignore_normals
                && args.structure != Some(Structure::Lines)
                && matches!(
                    common::input_format(input),
                    Some(io::Format::Ply | io::Format::Pcd)
                );
            let options = ReadOptions {
                attributes: keep_attributes || normals_here,
                ..ReadOptions::default()
            };
            let mut cloud = common::read_input(input, &options, timings)?;
            let normals = if normals_here { cloud.normals() } else { None };
            if !keep_attributes {
                cloud.attributes = Vec::new();
            }
            Ok(Input {
                cloud,
                normals,
                truth: None,
                name: input.display().to_string(),
            })
        }
        None => {
            let scene = timings.phase("synth", || SceneOptions::polyhedron().seed(1).generate())?;
            if let Some(p) = &paths.scene {
                timings.phase("write", || write_scene(p, &scene, true))?;
            }
            let name = "built-in example (Fig. 10-like polyhedron in background)".to_string();
            let cloud = PointCloud {
                points: scene.points.clone(),
                ..PointCloud::default()
            };
            Ok(Input {
                cloud,
                normals: None,
                truth: Some(scene),
                name,
            })
        }
    }
}

/// Builds the detector (phase "estimate") and runs it on `points` (phase
/// "detect") behind a progress bar, for the built-in example or not, with
/// the plane parts' outlines or not: the detector, its detection and the
/// wall seconds of the two.
fn detect_points(
    args: &DetectArgs,
    points: &[[f64; 3]],
    normals: Option<&[[f64; 3]]>,
    (example, outlines): (bool, bool),
    timings: &mut Timings,
) -> Result<(Detector, Detection, f64), CliError> {
    let in_file = |e: DetectError| match (&args.input, &e) {
        (
            Some(p),
            DetectError::Empty | DetectError::NonFinite { .. } | DetectError::OutOfRange { .. },
        ) => CliError::in_file(p, e),
        _ => CliError::msg(e.to_string()),
    };
    let start = Instant::now();
    let options = options(args, example);
    let detector = timings
        .phase("estimate", || options.build(points, normals, Style::Cli))
        .map_err(in_file)?;
    crate::memory::release_free();
    let threads = rayon::current_num_threads();
    for w in run_warnings(&options, &detector, points.len(), threads, Style::Cli) {
        common::warn(format_args!("{w}"));
    }
    let n_orient = detector
        .orientation_count()
        .map_err(|e| CliError::msg(format!("{}: {e}", options.orientation_flags(Style::Cli))))?;
    let bar = common::progress(n_orient as u64, "orientations");
    let tick = {
        let bar = bar.clone();
        move |done: usize, _total: usize| {
            bar.set_position(done as u64);
            true
        }
    };
    let stages = Arc::new(Mutex::new(Vec::new()));
    let observe = {
        let stages = stages.clone();
        move |stage: Stage, secs: f64| {
            if stage == Stage::Scan {
                crate::memory::release_free();
            }
            if let Ok(mut s) = stages.lock() {
                s.push((stage, secs));
            }
        }
    };
    let det = timings
        .phase("detect", || {
            detector
                .clone()
                .outlines(outlines)
                .progress(tick)
                .on_stage(observe)
                .run(points)
        })
        .map_err(in_file)?;
    if let Ok(stages) = stages.lock() {
        for &(stage, secs) in stages.iter() {
            timings.add_stage(stage.name(), secs);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    Ok((detector, det, seconds))
}

/// A detection with its labels mapped back to the input's points (the
/// detection ran on `points`, the input's points at the positions `keep`,
/// or all of them).
struct Outcome<'a> {
    cloud: &'a PointCloud,
    points: &'a [[f64; 3]],
    keep: Option<&'a [u32]>,
    det: &'a Detection,
    /// Structure id per input point, or −1.
    labels: Vec<i64>,
    /// Part id per input point, or −1.
    part_labels: Vec<i64>,
}

/// Writes, in this order, the per-point labels (`--labels`,
/// `--part-labels`), the labelled cloud or the parts' meshes
/// (`--output`) and the raw union (`--union`).
fn write_labels_and_meshes(
    args: &DetectArgs,
    paths: &OutputPaths,
    run: &Outcome<'_>,
    timings: &mut Timings,
) -> Result<(), CliError> {
    let Outcome {
        cloud,
        points,
        keep,
        det,
        labels,
        part_labels,
    } = run;
    if let Some(p) = &paths.labels {
        common::write_output(p, timings, |w| write_ints(w, labels))?;
    }
    if let Some(p) = &paths.parts {
        common::write_output(p, timings, |w| write_ints(w, part_labels))?;
    }
    if let Some(p) = &paths.output {
        let PartMeshes {
            mut edges,
            mut faces,
            element_labels,
        } = part_meshes(det, points);
        common::reindex(&mut edges, *keep);
        common::reindex(&mut faces, *keep);
        if paths.labelled_output {
            let labelled = io::Labelled {
                edges: &edges,
                faces: &faces,
                element_labels: &element_labels,
                classify: args.classify.map(|c| c.class),
                ..io::Labelled::new(labels, part_labels)
            };
            common::write_labelled(p, cloud, &labelled, timings)?;
        } else {
            let mesh = Mesh {
                edges: &edges,
                faces: &faces,
                ..Mesh::new(&cloud.points)
            };
            common::write_mesh(p, &mesh, timings)?;
        }
    }
    if let Some(p) = &args.union {
        let (mut edges, mut faces) = split_simplices(det);
        common::reindex(&mut edges, *keep);
        common::reindex(&mut faces, *keep);
        let mesh = Mesh {
            labels: Some(labels),
            edges: &edges,
            faces: &faces,
            ..Mesh::new(&cloud.points)
        };
        common::write_mesh(p, &mesh, timings)?;
    }
    Ok(())
}

/// The JSON report of a run: the input's name, the detection (parameters
/// with their reasons, structures, parts), the seconds of the run and the
/// scores against a ground truth.
fn report_json(
    name: &str,
    det: &Detection,
    detector: &Detector,
    seconds: f64,
    scores: Option<&Evaluation>,
) -> serde_json::Value {
    let mut r = json!({"input": name});
    if let (Some(o), serde_json::Value::Object(rest)) =
        (r.as_object_mut(), detection_json(det, detector))
    {
        o.extend(rest);
    }
    r["seconds"] = json!(seconds);
    if let Some(ev) = scores {
        r["scores"] = json!({
            "precision": ev.precision, "recall": ev.recall, "f1": ev.f1,
            "structures_found": ev.structures_found, "structures_total": ev.structures_total,
            "parts_found": ev.parts_found, "parts_total": ev.parts_total,
        });
    }
    r
}

/// Writes, in this order, the report (`--report`, with the timings of the
/// phases so far), the interactive view (`--html`) and the picture
/// (`--png`).
fn write_report_and_views(
    args: &DetectArgs,
    paths: &OutputPaths,
    name: &str,
    run: &Outcome<'_>,
    report: &serde_json::Value,
    timings: &mut Timings,
) -> Result<(), CliError> {
    if let Some(p) = &paths.report {
        let mut r = report.clone();
        // Wall seconds of the phases so far (the report itself is the last
        // output written).
        r["timings"] = timings.to_value();
        common::write_json(p, &r, timings)?;
    }
    if let Some(p) = &paths.html {
        crate::view::write_html(
            p,
            name,
            run.points,
            &run.det.labels,
            &run.part_labels,
            report,
            timings,
        )?;
    }
    if let Some(p) = &args.png {
        crate::picture::write_detection_png(p, run.points, run.det, &run.part_labels, timings)?;
    }
    Ok(())
}

/// Where a region run writes: the labels, part labels, a labelled
/// `--output` and the report.
fn region_outputs<'a>(
    args: &DetectArgs,
    paths: &'a OutputPaths,
) -> crate::cmd_regions::RegionOutputs<'a> {
    crate::cmd_regions::RegionOutputs {
        labels: paths.labels.as_ref(),
        parts: paths.parts.as_ref(),
        output: paths.output.as_ref(),
        classify: args.classify.map(|c| c.class),
        report: paths.report.as_ref(),
    }
}

/// The region run of a LAS/LAZ `input` streamed from the file, when the
/// run is one (`cmd_regions::streamed`); `false` when it is not (or the
/// data give no region side), and the file is read whole.
fn run_streamed(
    args: &DetectArgs,
    input: &std::path::Path,
    paths: &OutputPaths,
    timings: &mut Timings,
) -> Result<bool, CliError> {
    let whole = !paths.whole_outputs(args).is_empty();
    let Some(side) = crate::cmd_regions::streamed(
        input,
        args.regions,
        whole,
        args.background_classes.is_some(),
        paths.output.as_ref(),
    )?
    else {
        return Ok(false);
    };
    crate::cmd_regions::run_streamed(
        input,
        side,
        args.region_jobs.map_or(0, NonZeroUsize::get),
        &options(args, false),
        &region_outputs(args, paths),
        timings,
    )
}

/// Runs `detect`.
pub fn run(args: &DetectArgs, timings: &mut Timings) -> Result<(), CliError> {
    let example = args.input.is_none();
    let paths = OutputPaths::prepare(args, example)?;
    if let Some(input) = &args.input {
        if run_streamed(args, input, &paths, timings)? {
            return Ok(());
        }
    }
    let Input {
        cloud,
        normals,
        truth,
        name,
    } = read_cloud(args, &paths, timings)?;
    // --background-classes: the detection runs on the other points; ids
    // and meshes are mapped back to the input's points.
    let keep = match &args.input {
        Some(input) => common::kept_points(&cloud, input, args.background_classes)?,
        None => None,
    };
    // A labelled LAS output cannot hold an organized cloud's NaN rows:
    // said before the run, not after it.
    let las_out = paths.output.as_ref().filter(|p| {
        paths.labelled_output && matches!(io::Format::from_path(p), Ok(io::Format::Las))
    });
    if let Some(out) = las_out.filter(|_| !cloud.all_finite()) {
        return Err(CliError::in_file(out, io::NO_RETURN_IN_LAS));
    }
    let subset: Option<Vec<[f64; 3]>> = keep
        .as_ref()
        .map(|k| k.iter().map(|&i| cloud.points[i as usize]).collect());
    let points: &[[f64; 3]] = subset.as_deref().unwrap_or(&cloud.points);
    let normals: Option<Vec<[f64; 3]>> = match (normals, &keep) {
        (Some(n), Some(k)) => Some(k.iter().map(|&i| n[i as usize]).collect()),
        (n, _) => n,
    };
    let keep = keep.as_deref();
    // Coordinates stored in steps coarser than a neighbourhood (a depth
    // camera's): the run sees each point moved within its step; the
    // outputs keep the input's coordinates.
    let quantization = Quantization::of(points);
    for line in quantization.describe() {
        common::warn(format_args!("{name}: {line}"));
    }
    let seen = quantization.seen(points);
    let seen: &[[f64; 3]] = &seen;
    let whole = !paths.whole_outputs(args).is_empty();
    if let Some(side) = crate::cmd_regions::side(args.regions, whole, points) {
        let out = region_outputs(args, &paths);
        let input = crate::cmd_regions::RegionInput {
            name: &name,
            cloud: &cloud,
            points: seen,
            normals: normals.as_deref(),
            keep,
            side,
            jobs: args.region_jobs.map_or(0, NonZeroUsize::get),
        };
        return crate::cmd_regions::run(&input, &options(args, example), &out, timings);
    }
    let n_input = cloud.points.len();
    let (detector, det, seconds) = detect_points(
        args,
        seen,
        normals.as_deref(),
        (example, paths.holds_outlines(args)),
        timings,
    )?;

    let run = Outcome {
        cloud: &cloud,
        points,
        keep,
        det: &det,
        labels: common::spread(&det.labels, keep, n_input),
        part_labels: common::spread(&det.part_labels(), keep, n_input),
    };
    write_labels_and_meshes(args, &paths, &run, timings)?;
    let scores = truth.as_ref().and_then(|scene| {
        evaluate(
            &scene.labels,
            Some(&scene.parts),
            &det.labels,
            Some(&run.part_labels),
        )
        .ok()
    });
    let mut report = report_json(&name, &det, &detector, seconds, scores.as_ref());
    report["parameters"]["quantized"] = quantized_json(&quantization);
    write_report_and_views(args, &paths, &name, &run, &report, timings)?;

    let mut out = summary(&name, &det, &detector, &report, seconds);
    if let Some(ev) = &scores {
        out.push_str(&format!("\nAgainst the scene's ground truth:\n{ev}\n"));
    }
    if example {
        out.push_str(&format!(
            "\nWrote {EXAMPLE_DIR}: scene.xyz (x y z label part), labels.txt, parts.txt, structures.ply, report.json, view.html\n",
        ));
    }
    common::print_summary(&out)
}

pub(crate) fn write_ints(w: &mut dyn std::io::Write, values: &[i64]) -> std::io::Result<()> {
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
        match s {
            [a, b] => edges.push([*a, *b]),
            [a, b, c] => faces.push([*a, *b, *c]),
            _ => {}
        }
    }
    (edges, faces)
}

fn fmt_param(r: &serde_json::Value, name: &str) -> String {
    let p = &r["parameters"][name];
    match p["value"].as_f64() {
        Some(v) => format!(
            "{name} {}{}",
            trim(v),
            if p["estimated"].as_bool() == Some(true) {
                " (estimated)"
            } else {
                ""
            }
        ),
        None => String::new(),
    }
}

fn trim(v: f64) -> String {
    if v == v.round() && v.abs() < 1e9 {
        format!("{v}")
    } else {
        format!("{v:.4}")
    }
}

fn summary(
    name: &str,
    det: &Detection,
    d: &Detector,
    report: &serde_json::Value,
    seconds: f64,
) -> String {
    let mut o = String::new();
    let kind = match d.kind() {
        StructureKind::Lines => "lines",
        StructureKind::Planes => "planes",
    };
    o.push_str(&format!("aniso-alpha detect: {name}\n"));
    let mut params = vec![fmt_param(report, "alpha")];
    if d.kind() == StructureKind::Planes {
        params.push(fmt_param(report, "lambda2"));
    }
    params.push(fmt_param(report, "lambda3"));
    params.push(fmt_param(report, "min_size").replace("min_size", "min-size"));
    o.push_str(&format!(
        "  {} points; {kind} (k = {}), {}\n",
        det.labels.len(),
        d.kind().k(),
        params.join(", ")
    ));
    if let Some(e) = d.estimate() {
        o.push_str(&format!(
            "  estimated: spacing {:.4} (90th percentile; median {:.4}), noise {:.4}, {:.0}% of points locally {}\n",
            e.spacing,
            e.spacing_median,
            e.noise,
            100.0 * e.structure_fraction,
            d.kind().locally()
        ));
        o.push_str(&format!("  alpha: {}\n", e.alpha.reason));
    }
    if let Some(l) = d.ladder() {
        o.push_str(&format!(
            "  orientations: the Fibonacci sampler ({} deg) at {} levels of alpha, each structure at its most significant (see --report)\n",
            l.step_deg,
            l.alphas.len()
        ));
    }
    if let OrientationSet::Data(modes) = d.orientations() {
        let cover = modes.iter().filter(|m| m.cover).count();
        let covering = match cover {
            0 => String::new(),
            c => format!(" and {c} direction(s) covering the normals no mode scans"),
        };
        o.push_str(&format!(
            "  orientations from the data: {} mode(s) of the local {}s{covering}, each with its own alpha and lambda (see --report)\n",
            modes.len() - cover,
            if d.kind() == StructureKind::Planes { "normal" } else { "direction" }
        ));
        let thick: Vec<String> = modes
            .iter()
            .filter_map(|m| m.thinned_from.map(|n| format!("{n} -> {}", m.points.len())))
            .collect();
        let rescaled = modes.iter().filter(|m| m.cloud_scale).count();
        if rescaled > 0 {
            o.push_str(&format!(
                "  {rescaled} thick plane mode(s) (3 x noise over the reach: lambda would be 1, a ball): scanned at the cloud's spacing and noise\n"
            ));
        }
        if !thick.is_empty() {
            o.push_str(&format!(
                "  {} thick line mode(s) (3 x noise over the reach: lambda would be 1): members thinned to one chain along each ({}), lambda 4\n",
                thick.len(),
                thick.join(", ")
            ));
        }
    }
    if let (StructureKind::Planes, Some(n)) = (d.kind(), d.normals_given()) {
        o.push_str(&format!(
            "  normals: the input's ({n} of {} usable; --ignore-normals to estimate them): a point joins a plane only if its normal is within 36.9 degrees of the plane's\n",
            det.labels.len()
        ));
    }
    if let Some(g) = d.given_normals().filter(|g| !g.in_full()) {
        o.push_str(&format!(
            "  normals: the input's were {}: {}\n",
            if g.ignored() {
                "ignored"
            } else {
                "used in part"
            },
            g.ignored_reason()
        ));
    }
    o.push_str(&format!(
        "  {} orientations in {:.2} s; union {} simplices; {} part(s) kept, {} rejected by the significance test{}{}{}\n\n",
        det.stats.orientations,
        seconds,
        det.stats.union_simplices,
        det.num_parts(),
        det.stats.rejected_parts,
        match det.stats.surface_lines {
            0 => String::new(),
            n => format!(", {n} inside a surface (scanner rows, creases)"),
        },
        match (det.stats.out_of_proportion, d.kind()) {
            (0, _) => String::new(),
            (n, StructureKind::Planes) => format!(", {n} narrower than their ellipsoid (strips: wires, poles, edges)"),
            (n, StructureKind::Lines) => format!(", {n} less elongated than their ellipsoid (blobs)"),
        },
        match det.stats.faces_apart {
            0 => String::new(),
            n => format!(", {n} pair(s) of coplanar pieces kept apart by a solid between them (two faces)"),
        }
    ));
    o.push_str(&part_table(det));
    let bg = det.labels.iter().filter(|&&l| l < 0).count();
    o.push_str(&format!(
        "  {} structure(s), {} part(s); {} of {} points are background \
         (--labels: structure ids; --part-labels: {} ids)\n",
        det.structures.len(),
        det.num_parts(),
        bg,
        det.labels.len(),
        if d.kind() == StructureKind::Planes {
            "plane"
        } else {
            "segment"
        }
    ));
    o
}

/// Rows of the summary's part table at most (the report has every part).
const TABLE_ROWS: usize = 30;

/// One row per part (a plane, a facet of a surface, a line or a segment
/// of a polyline): its structure, points, RMS, NFA, extent, and the plane
/// or line as a unit normal (direction) through a point on it, the
/// centroid of its points. A plane through a point keeps its precision
/// far from the origin (UTM coordinates), where `[a b c d]` would need
/// about 12 digits in a, b and c: the normal is printed to 1e-6, the
/// point to 1e-5 of the part's size (at least millimetres in metres).
fn part_table(det: &Detection) -> String {
    let mut o = String::from(
        "  structure  part  kind       points        rms  log10 NFA  extent               \
         normal (planes) / direction (lines)  through point\n",
    );
    let mut rows = 0usize;
    let mut part = 0usize;
    for s in &det.structures {
        for p in &s.parts {
            if rows < TABLE_ROWS {
                let kind = match (&p.primitive, s.parts.len()) {
                    (Primitive::Plane(_), 1) => "plane",
                    (Primitive::Plane(_), _) => "facet",
                    (Primitive::Line(_), 1) => "line",
                    (Primitive::Line(_), _) => "segment",
                    (Primitive::None, _) => "unfitted",
                };
                let (extent, axis, centroid) = match &p.primitive {
                    Primitive::Plane(f) => (f.extent.to_vec(), f.normal, f.centroid),
                    Primitive::Line(f) => (vec![f.extent], f.direction, f.centroid),
                    Primitive::None => (vec![], [f64::NAN; 3], [f64::NAN; 3]),
                };
                let size = extent.iter().fold(1e-12f64, |m, &e| m.max(e.abs()));
                let digits = (5 - size.log10().floor() as i64).clamp(3, 12) as usize;
                let extent = extent
                    .iter()
                    .map(|e| format!("{e:.0$}", digits - 2))
                    .collect::<Vec<_>>()
                    .join(" x ");
                o.push_str(&format!(
                    "  {:>9}  {:>4}  {:<8} {:>8}  {:>9.3e}  {:>9.1}  {:<19}  [{:>9.6} {:>9.6} {:>9.6}]        [{:.digits$} {:.digits$} {:.digits$}]\n",
                    s.id,
                    part,
                    kind,
                    p.vertices.len(),
                    p.primitive.rms(),
                    p.log10_nfa,
                    extent,
                    axis[0],
                    axis[1],
                    axis[2],
                    centroid[0],
                    centroid[1],
                    centroid[2],
                ));
                rows += 1;
            }
            part += 1;
        }
    }
    if part > rows {
        o.push_str(&format!(
            "  ... and {} more part(s) (see --report)\n",
            part - rows
        ));
    }
    o
}
