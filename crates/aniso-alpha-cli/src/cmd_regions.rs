//! `detect --regions`: the detection region by region
//! (`aniso_alpha::detect::regions`), the default for clouds of more than
//! 1,000,000 points (`auto`): each region estimates its own parameters
//! from its points, the parts crossing region borders are joined, and the
//! peak memory is one region's run. Writes the labels, the labelled cloud
//! (without meshes) and a report of the joined parts; the views, the
//! union and the meshes need a whole run (asking for them without
//! `--regions` runs whole).

use std::path::{Path, PathBuf};

use aniso_alpha::detect::regions::stream::{
    detect_streamed, refit_streamed, survey, Pieces, Survey,
};
use aniso_alpha::detect::regions::{
    detect_by_regions_with_progress, side_for, side_for_extent, RegionJoin, RegionJoined,
    RegionRun, REGIONS_ABOVE,
};
use aniso_alpha::detect::{DetectError, Primitive};
use aniso_alpha::io::{self, PointCloud, ReadOptions};
use aniso_alpha::options::{region_warnings, DetectOptions, Style};
use serde_json::json;

use crate::common::{self, CliError, Timings};

/// `--regions`: a side, `auto` or `off`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Regions {
    /// Square columns of this side (input units).
    Side(f64),
    /// Regions of about `REGION_POINTS` points; none for smaller clouds.
    Auto,
    /// One whole run.
    Off,
}

/// clap parser for `--regions`: a side > 0, `auto` or `off`.
pub fn parse_regions(s: &str) -> Result<Regions, String> {
    match s.trim().to_ascii_lowercase().as_str() {
        "auto" => Ok(Regions::Auto),
        "off" => Ok(Regions::Off),
        _ => common::parse_positive(s)
            .map(Regions::Side)
            .map_err(|e| format!("{e}, 'auto' or 'off'")),
    }
}

/// The region side of a run on `points`, or `None` for one whole run:
/// `--regions` as given; without it, `auto` unless an output needs a
/// whole run (`whole_outputs`).
pub fn side(regions: Option<Regions>, whole_outputs: bool, points: &[[f64; 3]]) -> Option<f64> {
    match regions {
        Some(Regions::Side(s)) => Some(s),
        Some(Regions::Auto) => side_for(points),
        Some(Regions::Off) => None,
        None if whole_outputs => None,
        None => side_for(points),
    }
}

/// The outputs made from a whole run's simplices and meshes that were
/// asked for, by flag.
pub fn whole_outputs(
    html: &Option<PathBuf>,
    png: &Option<PathBuf>,
    union: &Option<PathBuf>,
    mesh_output: bool,
) -> Vec<&'static str> {
    [
        ("--html", html.is_some()),
        ("--png", png.is_some()),
        ("--union", union.is_some()),
        ("an .obj --output", mesh_output),
    ]
    .into_iter()
    .filter_map(|(flag, given)| given.then_some(flag))
    .collect()
}

/// `--regions` (a side or `auto`) with an output that needs a whole run is
/// refused before any work.
pub fn check_outputs(regions: Option<Regions>, whole: &[&str]) -> Result<(), CliError> {
    if matches!(regions, Some(Regions::Side(_) | Regions::Auto)) {
        if let Some(flag) = whole.first() {
            return Err(CliError::msg(format!(
                "{flag} needs a whole run: not with --regions (labels, a labelled .las/.laz/.ply \
                 --output and --report are written region by region; --regions off runs whole)"
            )));
        }
    }
    Ok(())
}

/// Where a region run writes.
pub struct RegionOutputs<'a> {
    /// `--labels`.
    pub labels: Option<&'a PathBuf>,
    /// `--part-labels`.
    pub parts: Option<&'a PathBuf>,
    /// A labelled `--output` (.las, .laz, .ply).
    pub output: Option<&'a PathBuf>,
    /// `--classify`'s class.
    pub classify: Option<u8>,
    /// `--report`.
    pub report: Option<&'a PathBuf>,
}

/// What a region run detects on: the input, the points it runs on (the
/// input's points at `keep`, or all of them) and their normals, the
/// region side and how many regions run at once (0: as many as threads).
pub struct RegionInput<'a> {
    /// The input's name, for the summary and the report.
    pub name: &'a str,
    /// The input cloud (its attributes go to a labelled `--output`).
    pub cloud: &'a PointCloud,
    /// The points detected on.
    pub points: &'a [[f64; 3]],
    /// Their normals, if the run uses the file's.
    pub normals: Option<&'a [[f64; 3]]>,
    /// The input indices of `points` (`None`: all of them).
    pub keep: Option<&'a [u32]>,
    /// The region side (input units).
    pub side: f64,
    /// Regions run at once (`--region-jobs`; 0: the thread count).
    pub jobs: usize,
}

/// A region run's progress function: `bar` shows the regions joined.
fn advance(bar: &indicatif::ProgressBar) -> impl FnMut(usize, usize) -> bool + Send + '_ {
    move |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        true
    }
}

/// The region run of `input` with `options`, then its outputs and summary.
pub fn run(
    input: &RegionInput<'_>,
    options: &DetectOptions,
    out: &RegionOutputs<'_>,
    timings: &mut Timings,
) -> Result<(), CliError> {
    let RegionInput {
        name,
        cloud,
        points,
        normals,
        keep,
        side,
        jobs,
    } = *input;
    let bar = common::progress(0, "regions");
    let start = std::time::Instant::now();
    let run = timings
        .phase("regions", || {
            detect_by_regions_with_progress(
                points,
                side,
                jobs,
                |ids, sub| options.build_region(ids, sub, normals, Style::Cli),
                &mut advance(&bar),
            )
        })
        .map_err(|e: DetectError| CliError::msg(e.to_string()))?;
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    for w in region_warnings(&run) {
        common::warn(format_args!("{w}"));
    }
    let n = cloud.points.len();
    let labels = common::spread(&run.labels, keep, n);
    let part_labels = common::spread(&run.part_labels, keep, n);
    if let Some(p) = out.labels {
        common::write_output(p, timings, |w| crate::cmd_detect::write_ints(w, &labels))?;
    }
    if let Some(p) = out.parts {
        common::write_output(p, timings, |w| {
            crate::cmd_detect::write_ints(w, &part_labels)
        })?;
    }
    if let Some(p) = out.output {
        let labelled = io::Labelled {
            classify: out.classify,
            ..io::Labelled::new(&labels, &part_labels)
        };
        common::write_labelled(p, cloud, &labelled, timings)?;
    }
    if let Some(p) = out.report {
        common::write_json(p, &report(name, side, &run, seconds), timings)?;
    }
    common::print_summary(&summary(name, points.len(), side, &run, seconds))
}

/// A joined part's primitive as JSON: a plane's `[a, b, c, d]` or a line's
/// direction and a point on it.
fn primitive_json(p: &Primitive) -> serde_json::Value {
    match p {
        Primitive::Plane(f) => json!({"plane": p.plane_equation(), "rms": f.rms_residual}),
        Primitive::Line(f) => {
            json!({"direction": f.direction, "point": f.centroid, "rms": f.rms_residual})
        }
        Primitive::None => json!(null),
    }
}

/// The report of a region run.
fn report(name: &str, side: f64, run: &RegionRun, seconds: f64) -> serde_json::Value {
    json!({
        "input": name,
        "regions": {
            "side": side, "count": run.regions, "widened": run.widened, "joins": run.joins,
            "skipped": run.skipped,
        },
        "seconds": seconds,
        "parts": run.parts.iter().map(|p| json!({
            "id": p.id,
            "structure": p.structure,
            "points": p.points,
            "pieces": p.pieces,
            "primitive": primitive_json(&p.primitive),
        })).collect::<Vec<_>>(),
    })
}

/// The terminal summary: the regions, then one row per part (at most 40).
fn summary(name: &str, n: usize, side: f64, run: &RegionRun, seconds: f64) -> String {
    let mut s = format!(
        "aniso-alpha detect: {name}\n  {n} points in {} region(s) of side {side} ({} widened for their \
         ellipsoids' reach{}), each with its own parameters; {} part(s) after {} join(s) across \
         borders, in {seconds:.2} s\n\n  part  structure    points  pieces  normal / direction\n",
        run.regions,
        run.widened,
        if run.skipped > 0 {
            format!(
                "; {} of one position, left as background",
                run.skipped
            )
        } else {
            String::new()
        },
        run.parts.len(),
        run.joins,
    );
    for p in run.parts.iter().take(40) {
        let dir = match &p.primitive {
            Primitive::Plane(f) => f.normal,
            Primitive::Line(f) => f.direction,
            Primitive::None => [f64::NAN; 3],
        };
        s.push_str(&format!(
            "  {:>4}  {:>9}  {:>8}  {:>6}  [{:.6} {:.6} {:.6}]\n",
            p.id, p.structure, p.points, p.pieces, dir[0], dir[1], dir[2]
        ));
    }
    if run.parts.len() > 40 {
        s.push_str(&format!("  ... {} more (--report)\n", run.parts.len() - 40));
    }
    s
}

/// Points read from a LAS/LAZ file at a time in a streamed region run
/// (2^20: 24 MiB of coordinates), as Python's `distributed.detect_tiles`
/// reads its tiles.
pub const PIECE_POINTS: u64 = 1 << 20;

/// A LAS/LAZ file read `piece` points at a time.
struct LasPieces<'a> {
    path: &'a Path,
    count: u64,
    piece: u64,
    /// The bar of the pass under way, advanced by each piece read (none
    /// while the regions read: they have their own).
    bar: std::sync::Mutex<Option<indicatif::ProgressBar>>,
    /// While the labelled copy is written: each piece is read with its
    /// records, and the last piece's records wait here for the writer
    /// (one decoding serves the refit and the copy).
    keep_records: std::sync::atomic::AtomicBool,
    last_records: std::sync::Mutex<Option<(usize, io::LasSource)>>,
}

impl<'a> LasPieces<'a> {
    /// The pieces of `path`: [`PIECE_POINTS`] points each (the CLI tests
    /// set smaller pieces through `ANISO_ALPHA_TEST_PIECE_POINTS`).
    fn new(path: &'a Path) -> Result<Self, CliError> {
        let piece = std::env::var("ANISO_ALPHA_TEST_PIECE_POINTS")
            .ok()
            .and_then(|v| v.parse::<u64>().ok())
            .filter(|&p| p > 0)
            .unwrap_or(PIECE_POINTS);
        Ok(LasPieces {
            path,
            count: io::las_point_count(path)?,
            piece,
            bar: std::sync::Mutex::new(None),
            keep_records: std::sync::atomic::AtomicBool::new(false),
            last_records: std::sync::Mutex::new(None),
        })
    }

    /// Shows a bar of `reads` pieces read (`None`: no bar), replacing the
    /// previous one.
    fn show(&self, reads: Option<(usize, &str)>) {
        let mut bar = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(b) = bar.take() {
            b.finish_and_clear();
        }
        *bar = reads.map(|(n, msg)| common::progress(n as u64, msg));
    }

    /// Piece `k`'s first record and number of records.
    fn range(&self, k: usize) -> (u64, u64) {
        let start = k as u64 * self.piece;
        (start, self.piece.min(self.count - start))
    }

    /// Piece `k`'s records, for the labelled copy: those its last read
    /// kept, else read again.
    fn records(&self, k: usize) -> Result<io::LasSource, CliError> {
        let mut last = self.last_records.lock().unwrap_or_else(|e| e.into_inner());
        match last.take() {
            Some((j, records)) if j == k => Ok(records),
            _ => Ok(self.read_records(k)?.1),
        }
    }

    /// Piece `k`'s points and records.
    fn read_records(&self, k: usize) -> Result<(Vec<[f64; 3]>, io::LasSource), CliError> {
        let (start, count) = self.range(k);
        let cloud = io::read_las_range_records(self.path, start, count)?;
        let records = cloud
            .las
            .map(|l| *l)
            .ok_or_else(|| CliError::in_file(self.path, "no LAS records read"))?;
        Ok((cloud.points, records))
    }
}

impl Pieces for LasPieces<'_> {
    type Error = CliError;

    fn len(&self) -> usize {
        self.count.div_ceil(self.piece) as usize
    }

    fn points(&self, k: usize) -> Result<Vec<[f64; 3]>, CliError> {
        let (start, count) = self.range(k);
        let options = ReadOptions {
            attributes: false,
            ..ReadOptions::default()
        };
        let points = if self.keep_records.load(std::sync::atomic::Ordering::Relaxed) {
            let (points, records) = self.read_records(k)?;
            *self.last_records.lock().unwrap_or_else(|e| e.into_inner()) = Some((k, records));
            points
        } else {
            io::read_las_range(self.path, start, count, &options)?.points
        };
        if let Some(b) = &*self.bar.lock().unwrap_or_else(|e| e.into_inner()) {
            b.inc(1);
        }
        Ok(points)
    }
}

/// Whether a run of `detect` on the LAS/LAZ file `input` is a region run
/// streamed from the file (never holding its points whole): `Some(side)`
/// (`None`: the side from the data) when `--regions` gives a side, or
/// asks for regions (`auto`, or no flag and no output that needs a whole
/// run) and the header counts more than `REGIONS_ABOVE` points. Not with
/// `--background-classes` (the points kept depend on their class) nor a
/// labelled PLY `--output` (written from the whole cloud): those read the
/// file whole.
pub fn streamed(
    input: &Path,
    regions: Option<Regions>,
    whole: bool,
    background_classes: bool,
    output: Option<&PathBuf>,
) -> Result<Option<Option<f64>>, CliError> {
    let las = matches!(common::input_format(input), Some(io::Format::Las));
    let las_output = output.is_none_or(|p| {
        p.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("las") || e.eq_ignore_ascii_case("laz"))
    });
    if !las || background_classes || !las_output {
        return Ok(None);
    }
    Ok(match regions {
        Some(Regions::Side(s)) => Some(Some(s)),
        Some(Regions::Off) => None,
        None if whole => None,
        Some(Regions::Auto) | None => {
            let n = io::las_point_count(input)?;
            (n > REGIONS_ABOVE as u64).then_some(None)
        }
    })
}

/// The region run of a LAS/LAZ file read a piece at a time
/// (`aniso_alpha::detect::regions::stream`): the same labels, parts and
/// report as the region run of the file read whole. Returns `false`
/// without output when the data give no region side (a cloud flat in x
/// or y): the caller reads the file whole.
pub fn run_streamed(
    input: &Path,
    side: Option<f64>,
    jobs: usize,
    options: &DetectOptions,
    out: &RegionOutputs<'_>,
    timings: &mut Timings,
) -> Result<bool, CliError> {
    let src = LasPieces::new(input)?;
    if src.count == 0 {
        return Err(CliError::in_file(input, "no points in file"));
    }
    src.show(Some((src.len(), "reading")));
    let survey = timings.phase("read", || survey(&src))?;
    src.show(None);
    let Some(side) = side.or_else(|| side_for_extent(survey.lo, survey.hi, survey.n)) else {
        return Ok(false);
    };
    // The part ids (4 bytes a point) in a scratch file, in a hidden folder
    // next to the first output (or in the system's temporary folder),
    // removed at the end or on an interruption.
    let folder = out
        .labels
        .or(out.parts)
        .or(out.output)
        .or(out.report)
        .and_then(|p| p.parent())
        .filter(|d| !d.as_os_str().is_empty())
        .map_or_else(std::env::temp_dir, Path::to_path_buf);
    let scratch = io::ScratchFolder::create(&folder)?;
    let join = RegionJoin::with_scratch(survey.n, scratch.path())?;
    let bar = common::progress(0, "regions");
    let start = std::time::Instant::now();
    let joined = timings.phase("regions", || {
        detect_streamed(
            &src,
            &survey,
            side,
            jobs,
            join,
            |ids, sub| options.build_region(ids, sub, None, Style::Cli),
            &mut advance(&bar),
        )
    })?;
    bar.finish_and_clear();
    src.show(Some((3 * src.len(), "writing")));
    let run = timings.phase("write", || write_streamed(&src, &survey, &joined, out))?;
    src.show(None);
    let seconds = start.elapsed().as_secs_f64();
    for w in region_warnings(&run) {
        common::warn(format_args!("{w}"));
    }
    let name = input.display().to_string();
    if let Some(p) = out.report {
        common::write_json(p, &report(&name, side, &run, seconds), timings)?;
    }
    let mut text = summary(&name, survey.n, side, &run, seconds);
    let read = format!(
        "  streamed from the file: {} piece(s) of at most {} points, never held whole\n",
        src.len(),
        src.piece
    );
    let at = text.find('\n').map_or(text.len(), |i| i + 1);
    text.insert_str(at, &read);
    common::print_summary(&text)?;
    Ok(true)
}

/// The joined parts' fits over the pieces, and in the first pass the
/// labels, part labels and labelled LAS/LAZ copy, a piece at a time; each
/// output complete or absent.
fn write_streamed(
    src: &LasPieces<'_>,
    survey: &Survey,
    joined: &RegionJoined,
    out: &RegionOutputs<'_>,
) -> Result<RegionRun, CliError> {
    let create = |p: Option<&PathBuf>| p.map(|p| io::AtomicWriter::create(p)).transpose();
    let mut labels = create(out.labels)?;
    let mut parts = create(out.parts)?;
    let mut las: Option<io::LasLabelWriter> = None;
    src.keep_records
        .store(out.output.is_some(), std::sync::atomic::Ordering::Relaxed);
    let run = refit_streamed(src, survey, joined, |k, _, _, structures, part_ids| {
        if let Some(w) = &mut labels {
            w.write(|w| crate::cmd_detect::write_ints(w, structures))?;
        }
        if let Some(w) = &mut parts {
            w.write(|w| crate::cmd_detect::write_ints(w, part_ids))?;
        }
        if let Some(path) = out.output {
            let records = src.records(k)?;
            if las.is_none() {
                las = Some(io::LasLabelWriter::create(
                    path,
                    &records,
                    src.count,
                    out.classify,
                )?);
            }
            if let Some(w) = &mut las {
                w.append(&records.records, structures, part_ids)?;
            }
        }
        Ok(())
    });
    src.keep_records
        .store(false, std::sync::atomic::Ordering::Relaxed);
    let run = run?;
    for w in [labels, parts].into_iter().flatten() {
        w.finish()?;
    }
    if let Some(w) = las {
        w.finish()?;
    }
    Ok(run)
}
