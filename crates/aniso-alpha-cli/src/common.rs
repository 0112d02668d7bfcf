//! Helpers shared by the subcommands: errors, reading input with a progress
//! bar, atomic outputs, phase timings, progress bars, fast integer output.

use std::fmt;
use std::io::{IsTerminal, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use aniso_alpha::io::{self as aio, Mesh, PlyEncoding, PointCloud, ReadOptions};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

// ------------------------------------------------------------------ errors

/// An error for the user: printed by `main` as one line `error: <message>`,
/// exit status 1. Any `std::error::Error` converts into it with `?`.
#[derive(Debug)]
pub struct CliError(String);

impl CliError {
    /// An error with this message.
    pub fn msg(message: impl Into<String>) -> Self {
        CliError(message.into())
    }

    /// An error about a file whose message does not name it (e.g. an
    /// engine error on the points of `path`): `<path>: <error>`.
    pub fn in_file(path: &Path, err: impl fmt::Display) -> Self {
        CliError(format!("{}: {err}", path.display()))
    }

    /// The message on one line (newlines folded).
    pub fn one_line(&self) -> String {
        self.0
            .trim_end()
            .chars()
            .map(|c| if c == '\n' || c == '\r' { ' ' } else { c })
            .collect()
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl<E: std::error::Error> From<E> for CliError {
    fn from(e: E) -> Self {
        CliError(e.to_string())
    }
}

// ------------------------------------------------------------------ quiet

static QUIET: AtomicBool = AtomicBool::new(false);

static FORMAT: std::sync::OnceLock<aio::Format> = std::sync::OnceLock::new();

/// Sets `--format`: the input format, overriding file extensions.
pub fn set_format(format: Option<aio::Format>) {
    if let Some(f) = format {
        let _ = FORMAT.set(f);
    }
}

/// clap parser for `--format`.
pub fn parse_format(s: &str) -> Result<aio::Format, String> {
    aio::Format::from_name(s).ok_or_else(|| {
        format!("unknown format '{s}' (expected xyz, txt, csv, pts, ply, las, laz, pcd or e57)")
    })
}

/// Sets `--quiet`: no progress bars, no informational messages.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether `--quiet` was given.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// Prints an informational line on stderr, unless `--quiet`.
pub fn info(message: impl fmt::Display) {
    if !quiet() {
        eprintln!("{message}");
    }
}

static SILENT: AtomicBool = AtomicBool::new(false);

/// Sets `--quiet` as the user gave it (not implied by `--timings`): the
/// summaries on stdout are silenced too.
pub fn set_silent(silent: bool) {
    SILENT.store(silent, Ordering::Relaxed);
}

/// Writes a summary (e.g. `detect`'s table) to stdout, unless `--quiet`.
pub fn print_summary(text: &str) -> Result<(), CliError> {
    if SILENT.load(Ordering::Relaxed) {
        return Ok(());
    }
    print_stdout(text)
}

/// Writes `text` to stdout; a closed pipe (`| head`) is not an error.
pub fn print_stdout(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(CliError::msg(format!(
            "cannot write to standard output: {e}"
        ))),
        _ => Ok(()),
    }
}

// --------------------------------------------------------------- progress

fn draw_target() -> ProgressDrawTarget {
    if quiet() || !std::io::stderr().is_terminal() {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    }
}

/// A progress bar of `len` steps on stderr, hidden with `--quiet` or when
/// stderr is not a terminal. Call `inc`/`set_position`, then
/// `finish_and_clear`.
pub fn progress(len: u64, msg: &str) -> ProgressBar {
    let style = ProgressStyle::with_template(
        "{msg:>14} [{bar:40}] {pos}/{len} ({percent}%, {elapsed} elapsed, eta {eta})",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    ProgressBar::with_draw_target(Some(len), draw_target())
        .with_style(style)
        .with_message(msg.to_string())
}

/// Like [`progress`], counting bytes.
pub fn progress_bytes(len: u64, msg: &str) -> ProgressBar {
    let style = ProgressStyle::with_template(
        "{msg:>14} [{bar:40}] {bytes}/{total_bytes} ({bytes_per_sec}, eta {eta})",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    ProgressBar::with_draw_target(Some(len), draw_target())
        .with_style(style)
        .with_message(msg.to_string())
}

/// A spinner for a phase of unknown length (hidden like [`progress`]).
pub fn spinner(msg: &str) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(None, draw_target())
        .with_style(
            ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        )
        .with_message(msg.to_string());
    if !bar.is_hidden() {
        bar.enable_steady_tick(Duration::from_millis(120));
    }
    bar
}

// ---------------------------------------------------------------- timings

/// Wall time per phase, for `--timings`: one JSON object on stderr,
/// e.g. `{"read":0.012,"triangulate":1.5,"write":0.2,"total":1.72}`;
/// `detect` adds the stages of its detection phase as an object under
/// `stages` (`{"scan":0.4,"union":0.05,...}`, parts of `detect`).
#[derive(Debug)]
pub struct Timings {
    start: Instant,
    phases: Vec<(&'static str, f64)>,
    stages: Vec<(&'static str, f64)>,
}

impl Default for Timings {
    fn default() -> Self {
        Self::new()
    }
}

impl Timings {
    /// Starts the clock for `total`.
    pub fn new() -> Self {
        Timings {
            start: Instant::now(),
            phases: Vec::new(),
            stages: Vec::new(),
        }
    }

    /// Runs `f` as phase `name` (times of a repeated name add up).
    pub fn phase<T>(&mut self, name: &'static str, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let out = f();
        self.add(name, t.elapsed().as_secs_f64());
        out
    }

    /// Adds `seconds` to phase `name`.
    pub fn add(&mut self, name: &'static str, seconds: f64) {
        add_to(&mut self.phases, name, seconds);
    }

    /// Adds `seconds` to stage `name` of a phase (reported under
    /// `stages`, not counted as a phase of its own).
    pub fn add_stage(&mut self, name: &'static str, seconds: f64) {
        add_to(&mut self.stages, name, seconds);
    }

    /// The JSON object: phases in the order first seen, then `total`.
    pub fn to_json(&self) -> String {
        self.to_value().to_string()
    }

    /// The phases so far (and the total) as a JSON object.
    pub fn to_value(&self) -> serde_json::Value {
        let mut map = serde_json::Map::new();
        for (name, s) in &self.phases {
            map.insert((*name).to_string(), round_json(*s));
        }
        if !self.stages.is_empty() {
            let stages: serde_json::Map<String, serde_json::Value> = self
                .stages
                .iter()
                .map(|(n, s)| ((*n).to_string(), round_json(*s)))
                .collect();
            map.insert("stages".to_string(), serde_json::Value::Object(stages));
        }
        map.insert(
            "total".to_string(),
            round_json(self.start.elapsed().as_secs_f64()),
        );
        serde_json::Value::Object(map)
    }
}

/// Adds `seconds` to the entry `name` of `list`, or appends it.
fn add_to(list: &mut Vec<(&'static str, f64)>, name: &'static str, seconds: f64) {
    match list.iter_mut().find(|(n, _)| *n == name) {
        Some((_, s)) => *s += seconds,
        None => list.push((name, seconds)),
    }
}

fn round_json(s: f64) -> serde_json::Value {
    serde_json::Value::from((s * 1e6).round() / 1e6)
}

// ------------------------------------------------------------ input/output

/// Reads a point file (format by extension, or `--format`; `-` is
/// standard input) with a progress bar, as phase `read`. Errors name the
/// file and, for text, the line; the reader's warnings are printed unless
/// `--quiet`.
pub fn read_input(
    path: &Path,
    options: &ReadOptions,
    timings: &mut Timings,
) -> Result<PointCloud, CliError> {
    let options = ReadOptions {
        format: options.format.or(FORMAT.get().copied()),
        ..*options
    };
    let cloud = timings.phase("read", || {
        let bar = progress_bytes(0, "reading");
        let cloud = aio::read_points_with_progress(path, &options, &mut |done, total| {
            bar.set_length(total);
            bar.set_position(done);
        });
        bar.finish_and_clear();
        cloud
    })?;
    for w in &cloud.warnings {
        warn(format_args!("{}: {w}", display_input(path)));
    }
    Ok(cloud)
}

/// The format an input path will be read as (`--format`, or by
/// extension), if known.
pub fn input_format(path: &Path) -> Option<aio::Format> {
    let options = ReadOptions {
        format: FORMAT.get().copied(),
        ..ReadOptions::default()
    };
    aio::Format::resolve(path, &options).ok()
}

/// How an input path is named in messages (`-` is standard input).
pub fn display_input(path: &Path) -> String {
    if aio::is_stdin(path) {
        "<stdin>".to_string()
    } else {
        path.display().to_string()
    }
}

/// Prints `warning: <message>` on stderr, unless `--quiet`.
pub fn warn(message: impl fmt::Display) {
    if !quiet() {
        eprintln!("warning: {message}");
    }
}

/// Reads a point file that must carry labels (ground truth): text column
/// `label_column`, PLY `structure`/`label`, PCD `label`, LAS classification.
pub fn read_truth(
    path: &Path,
    label_column: usize,
    background_classes: aio::ClassSet,
    timings: &mut Timings,
) -> Result<(PointCloud, Vec<i64>), CliError> {
    let options = ReadOptions {
        background_classes,
        ..ReadOptions::with_labels(label_column)
    };
    let mut cloud = read_input(path, &options, timings)?;
    match cloud.labels.take() {
        Some(labels) => Ok((cloud, labels)),
        None => Err(CliError::in_file(
            path,
            "no labels in file (PLY needs a 'structure' or 'label' vertex property, PCD a 'label' field)",
        )),
    }
}

/// Fails early, before any long computation, when `path` cannot be an
/// output (missing or read-only folder, a directory, a device node or a
/// FIFO).
pub fn check_output(path: &Path) -> Result<(), CliError> {
    Ok(aio::check_output_path(path)?)
}

/// Checks a command's files before any work: every output can be written
/// ([`check_output`]), no output is also an input (the same file, through
/// any link), and no two outputs write the same file. `outputs` pairs each
/// output with the option that names it.
pub fn check_io(inputs: &[&Path], outputs: &[(&str, Option<&Path>)]) -> Result<(), CliError> {
    let given: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|(flag, p)| p.map(|p| (*flag, p)))
        .collect();
    let mut keys: Vec<(std::path::PathBuf, &str)> = Vec::new();
    for &(flag, out) in &given {
        for input in inputs {
            if aio::same_file(input, out) {
                return Err(CliError::msg(format!(
                    "{flag} {}: is the input file {}; refusing to overwrite an input",
                    out.display(),
                    input.display()
                )));
            }
        }
        let key = aio::output_key(out);
        if let Some((_, other)) = keys.iter().find(|(k, _)| *k == key) {
            return Err(CliError::msg(format!(
                "{other} and {flag} name the same file {}: give each output its own path",
                out.display()
            )));
        }
        keys.push((key, flag));
    }
    for &(_, out) in &given {
        check_output(out)?;
    }
    Ok(())
}

/// Removes the temporary files of unfinished outputs on SIGINT, SIGTERM
/// and SIGHUP, then exits with status 128 + the signal number.
pub fn install_signal_cleanup() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        if let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
            std::thread::spawn(move || {
                if let Some(sig) = signals.forever().next() {
                    aio::remove_temp_files();
                    std::process::exit(128 + sig);
                }
            });
        }
    }
}

/// Output formats for simplices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// `.ply` (binary little endian).
    Ply,
    /// `.obj`.
    Obj,
}

/// The mesh format of an output path, by extension (`.ply` or `.obj`).
pub fn mesh_format(path: &Path) -> Result<MeshFormat, CliError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "ply" => Ok(MeshFormat::Ply),
        "obj" => Ok(MeshFormat::Obj),
        _ => Err(CliError::msg(format!(
            "{}: unknown output extension (expected .ply or .obj)",
            path.display()
        ))),
    }
}

/// Writes simplices as PLY (binary) or OBJ by extension, atomically, as
/// phase `write`.
pub fn write_mesh(path: &Path, mesh: &Mesh<'_>, timings: &mut Timings) -> Result<(), CliError> {
    let format = mesh_format(path)?;
    timings.phase("write", || match format {
        MeshFormat::Ply => aio::write_ply(path, mesh, PlyEncoding::BinaryLittleEndian),
        MeshFormat::Obj => aio::write_obj(path, mesh),
    })?;
    Ok(())
}

/// What `detect --output` writes, by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudOutput {
    /// `.ply`, `.las`, `.laz`: the input cloud with its attributes, the
    /// structure and part ids (and, PLY, the part meshes).
    Labelled,
    /// `.obj`: geometry only.
    Obj,
}

/// The kind of a `detect --output` path, by extension.
pub fn cloud_output(path: &Path) -> Result<CloudOutput, CliError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "ply" | "las" | "laz" => Ok(CloudOutput::Labelled),
        "obj" => Ok(CloudOutput::Obj),
        _ => Err(CliError::msg(format!(
            "{}: unknown output extension (expected .ply, .las, .laz or .obj)",
            path.display()
        ))),
    }
}

/// The points a detection runs on: indices into the input, ascending;
/// `None` keeps every point. Left out: an organized cloud's points without
/// a return (NaN coordinates, [`PointCloud::finite_rows`]), and the LAS
/// classes of `--background-classes`, read from the cloud's
/// `classification` attribute (LAS, or a PLY/PCD property of that name).
pub fn kept_points(
    cloud: &PointCloud,
    input: &Path,
    exclude: Option<aio::ClassSet>,
) -> Result<Option<Vec<u32>>, CliError> {
    let finite = cloud.finite_rows();
    if let Some(rows) = &finite {
        info(format_args!(
            "{}: {} of {} points have no return (NaN coordinates of an organized cloud): labelled -1",
            display_input(input),
            cloud.points.len() - rows.len(),
            cloud.points.len()
        ));
    }
    let Some(exclude) = exclude else {
        return Ok(finite);
    };
    let class = cloud
        .attributes
        .iter()
        .find(|a| a.name == "classification")
        .ok_or_else(|| {
            CliError::in_file(
                input,
                "--background-classes needs a classification (LAS, or a PLY/PCD property 'classification')",
            )
        })?;
    let n = u32::try_from(cloud.points.len())
        .map_err(|_| CliError::in_file(input, "more than 2^32 - 1 points"))?;
    let rows = finite.unwrap_or_else(|| (0..n).collect());
    let before = rows.len();
    let keep: Vec<u32> = rows
        .into_iter()
        .filter(|&i| {
            let c = class.values.get_f64(i as usize);
            !(0.0..=255.0).contains(&c) || !exclude.contains(c as u8)
        })
        .collect();
    info(format_args!(
        "{}: {} of {} points excluded by --background-classes (labelled -1)",
        display_input(input),
        before - keep.len(),
        before
    ));
    Ok(Some(keep))
}

/// Per-point values of a subset spread back over all `n` input points
/// (−1 where a point was excluded).
pub fn spread(values: &[i64], keep: Option<&[u32]>, n: usize) -> Vec<i64> {
    match keep {
        None => values.to_vec(),
        Some(keep) => {
            let mut out = vec![-1; n];
            for (&i, &v) in keep.iter().zip(values) {
                out[i as usize] = v;
            }
            out
        }
    }
}

/// Indices into a subset mapped back to the input's.
pub fn reindex<const K: usize>(items: &mut [[u32; K]], keep: Option<&[u32]>) {
    if let Some(keep) = keep {
        for v in items.iter_mut().flatten() {
            *v = keep[*v as usize];
        }
    }
}

/// `--classify KIND=CLASS`: the LAS class given to the points of the
/// structures found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Classify {
    /// `planes` or `lines`.
    pub lines: bool,
    /// The class, 0–255.
    pub class: u8,
}

/// clap parser for `--classify planes=6` / `lines=N`.
pub fn parse_classify(s: &str) -> Result<Classify, String> {
    let (kind, class) = s
        .split_once('=')
        .ok_or_else(|| format!("expected planes=CLASS or lines=CLASS, got '{s}'"))?;
    let lines = match kind.trim() {
        "planes" => false,
        "lines" => true,
        k => return Err(format!("'{k}' is not planes or lines")),
    };
    let class = class
        .trim()
        .parse::<u8>()
        .map_err(|_| format!("'{}' is not a LAS class (0-255)", class.trim()))?;
    Ok(Classify { lines, class })
}

/// Writes the input cloud with structure and part ids (and meshes) as
/// PLY, LAS or LAZ, as phase `write`.
pub fn write_labelled(
    path: &Path,
    cloud: &PointCloud,
    labelled: &aio::Labelled<'_>,
    timings: &mut Timings,
) -> Result<(), CliError> {
    timings.phase("write", || aio::write_labelled_cloud(path, cloud, labelled))?;
    Ok(())
}

/// Writes an output atomically (complete or absent), as phase `write`.
pub fn write_output(
    path: &Path,
    timings: &mut Timings,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    Ok(timings.phase("write", || aio::atomic_write(path, write))?)
}

/// Writes `value` as pretty JSON (plus a newline), atomically.
pub fn write_json(
    path: &Path,
    value: &impl serde::Serialize,
    timings: &mut Timings,
) -> Result<(), CliError> {
    write_output(path, timings, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })
}

/// Appends the decimal form of `v` to `buf` (no allocation).
pub fn push_u32(buf: &mut Vec<u8>, mut v: u32) {
    let mut tmp = [0u8; 10];
    let mut i = tmp.len();
    loop {
        i -= 1;
        tmp[i] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    buf.extend_from_slice(&tmp[i..]);
}

// ----------------------------------------------------------- value parsers

/// clap parser for `a,b,c` (three finite numbers).
pub fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<&str> = s.split(',').map(str::trim).collect();
    if v.len() != 3 {
        return Err(format!("expected three comma-separated numbers, got '{s}'"));
    }
    let mut out = [0.0; 3];
    for (o, t) in out.iter_mut().zip(&v) {
        *o = t
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("'{t}' is not a finite number"))?;
    }
    Ok(out)
}

/// clap parser for `e1,e2,e3`, each > 0.
pub fn parse_positive_triple(s: &str) -> Result<[f64; 3], String> {
    let t = parse_triple(s)?;
    if t.iter().any(|&x| x <= 0.0) {
        return Err(format!("every component must be > 0, got '{s}'"));
    }
    Ok(t)
}

/// clap parser for `--background-classes`: `7,18`, or `none`.
pub fn parse_classes(s: &str) -> Result<aio::ClassSet, String> {
    if s.trim().eq_ignore_ascii_case("none") {
        return Ok(aio::ClassSet::EMPTY);
    }
    let classes = s
        .split(',')
        .map(|t| {
            t.trim()
                .parse::<u8>()
                .map_err(|_| format!("'{}' is not a LAS class (0-255)", t.trim()))
        })
        .collect::<Result<Vec<u8>, _>>()?;
    Ok(aio::ClassSet::from_classes(&classes))
}

/// clap parser for a finite number > 0.
pub fn parse_positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("expected a finite number > 0, got '{s}'")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_and_triples() {
        let mut b = Vec::new();
        for v in [0u32, 7, 10, 4_294_967_295] {
            push_u32(&mut b, v);
            b.push(b' ');
        }
        assert_eq!(b, b"0 7 10 4294967295 ");
        assert_eq!(parse_triple("1, -2,3e1"), Ok([1.0, -2.0, 30.0]));
        assert!(parse_triple("1,2").is_err());
        assert!(parse_triple("1,nan,2").is_err());
        assert!(parse_positive_triple("1,0,2").is_err());
        assert!(parse_positive("-1").is_err());
        assert_eq!(parse_classes("none"), Ok(aio::ClassSet::EMPTY));
        assert_eq!(
            parse_classes("7, 18"),
            Ok(aio::ClassSet::from_classes(&[7, 18]))
        );
        assert!(parse_classes("7,256").is_err());
    }

    #[test]
    fn timings_json() {
        let mut t = Timings::new();
        t.add("read", 0.5);
        t.add("write", 0.25);
        t.add("read", 0.25);
        let v: serde_json::Value = serde_json::from_str(&t.to_json()).unwrap();
        assert_eq!(v["read"], 0.75);
        assert_eq!(v["write"], 0.25);
        assert!(v["total"].is_number());
    }

    #[test]
    fn meshes_by_extension() {
        let dir = std::env::temp_dir().join(format!("aniso-cli-mesh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mesh = Mesh {
            faces: &[[0, 1, 2]],
            ..Mesh::new(&pts)
        };
        let mut t = Timings::new();
        write_mesh(&dir.join("m.PLY"), &mesh, &mut t).unwrap();
        write_mesh(&dir.join("m.obj"), &mesh, &mut t).unwrap();
        let back = aio::read_points(&dir.join("m.PLY"), &ReadOptions::default()).unwrap();
        assert_eq!(back.points, pts);
        assert!(std::fs::read_to_string(dir.join("m.obj"))
            .unwrap()
            .contains("f 1 2 3"));
        let e = write_mesh(&dir.join("m.stl"), &mesh, &mut t).unwrap_err();
        assert!(e.to_string().contains("m.stl: unknown output extension"));
        assert!(mesh_format(&dir.join("m.txt")).is_err());
        assert!(check_output(&dir.join("nope").join("m.ply")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn errors_fold_to_one_line() {
        assert_eq!(CliError::msg("a\nb  c\n").one_line(), "a b  c");
    }
}
