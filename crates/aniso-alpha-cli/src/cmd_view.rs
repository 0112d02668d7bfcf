//! `aniso-alpha view`: an interactive 3D view of a point cloud and its
//! structures, as one self-contained HTML file (see [`crate::view`]).

use std::path::{Path, PathBuf};

use aniso_alpha::io::ReadOptions;
use clap::Args;

use crate::common::{self, CliError, Timings};
use crate::view::{self, ViewInput, DEFAULT_MAX_POINTS};
use crate::QuietArgs;

/// Arguments of `view`.
#[derive(Debug, Args)]
#[command(
    after_help = "Writes one HTML file that any browser opens offline (no server, no network): \
the points coloured by structure and part over a dimmed background, each part's outline \
(the report's polygon or segment, else the hull of its points on its fitted plane or line), \
a legend with each structure's kind, size, plane equation or segment, RMS (and NFA when the \
report has it), toggles for the background and each structure. Drag to orbit, right-drag or \
shift-drag to pan, wheel to zoom, double-click to reset.\n\
Without --labels every point is drawn as background. Beyond --max-points the background is \
thinned first, then the structures; the page says how many points it shows.\n\n\
Examples:\n  aniso-alpha view scan.xyz --labels labels.txt --part-labels parts.txt \
--report report.json --output view.html\n  \
aniso-alpha view scan.las --output scan.html"
)]
pub struct ViewArgs {
    /// Input point file (.xyz .txt .csv .pts .ply .las .laz .pcd .e57), as given to detect
    pub input: PathBuf,
    /// Structure label per point, one per line (`detect --labels`)
    #[arg(long, allow_negative_numbers = true, value_name = "L.txt")]
    pub labels: Option<PathBuf>,
    /// Part label per point, one per line (`detect --part-labels`)
    #[arg(long, allow_negative_numbers = true, value_name = "P.txt")]
    pub part_labels: Option<PathBuf>,
    /// The report of the detection (`detect --report`): kinds, planes,
    /// segments, outlines, RMS, NFA
    #[arg(long, allow_negative_numbers = true, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// The HTML file to write
    #[arg(long, short = 'o', value_name = "OUT.html")]
    pub output: PathBuf,
    /// Most points drawn (the background is thinned first)
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = DEFAULT_MAX_POINTS)]
    pub max_points: usize,
    #[command(flatten)]
    pub input_format: crate::FormatArgs,
    #[command(flatten)]
    pub common: QuietArgs,
}

fn read_labels(path: &Path, n: usize, timings: &mut Timings) -> Result<Vec<i64>, CliError> {
    let labels = timings.phase("read", || aniso_alpha::io::read_labels(path))?;
    if labels.len() != n {
        return Err(CliError::in_file(
            path,
            format!("{} labels for {n} points", labels.len()),
        ));
    }
    Ok(labels)
}

/// Runs `view`.
pub fn run(args: &ViewArgs, timings: &mut Timings) -> Result<(), CliError> {
    let mut inputs: Vec<&Path> = vec![&args.input];
    inputs.extend(
        [&args.labels, &args.part_labels, &args.report]
            .into_iter()
            .flatten()
            .map(PathBuf::as_path),
    );
    common::check_io(&inputs, &[("--output", Some(&args.output))])?;
    if args.max_points == 0 {
        return Err(CliError::msg("--max-points must be at least 1"));
    }
    let cloud = common::read_input(&args.input, &ReadOptions::default(), timings)?;
    let n = cloud.points.len();
    let labels = match &args.labels {
        Some(p) => Some(read_labels(p, n, timings)?),
        None => None,
    };
    let parts = match &args.part_labels {
        Some(p) => Some(read_labels(p, n, timings)?),
        None => None,
    };
    let report = match &args.report {
        Some(p) => {
            let text = timings
                .phase("read", || std::fs::read_to_string(p))
                .map_err(|e| CliError::in_file(p, e))?;
            let v: serde_json::Value =
                serde_json::from_str(&text).map_err(|e| CliError::in_file(p, e))?;
            Some(v)
        }
        None => None,
    };
    // An organized cloud's points without a return (NaN) are not drawn.
    let (cloud, labels, parts) = match cloud.finite_rows() {
        None => (cloud, labels, parts),
        Some(rows) => {
            let pick =
                |l: Option<Vec<i64>>| l.map(|l| rows.iter().map(|&i| l[i as usize]).collect());
            (cloud.select(&rows), pick(labels), pick(parts))
        }
    };
    let title = args.input.file_name().map_or_else(
        || args.input.display().to_string(),
        |f| f.to_string_lossy().into_owned(),
    );
    let page = timings.phase("view", || {
        view::html(&ViewInput {
            title: &title,
            points: &cloud.points,
            labels: labels.as_deref(),
            parts: parts.as_deref(),
            report: report.as_ref(),
            max_points: args.max_points,
        })
    })?;
    common::write_output(&args.output, timings, |w| w.write_all(page.as_bytes()))?;
    common::info(format_args!(
        "{} points -> {} ({:.1} MB)",
        n,
        args.output.display(),
        page.len() as f64 / 1e6
    ));
    Ok(())
}
