//! `aniso-alpha eval`: scores of a detection against ground truth (SPEC §6).

use std::path::PathBuf;

use clap::Args;

use crate::common::{self, CliError, Timings};

/// Arguments of `eval`.
#[derive(Debug, Args)]
#[command(
    after_help = "TRUTH is a point file with labels: text `x y z label` (label column set by \
--label-column), PLY with a `structure` vertex property, PCD with a `label` field, LAS \
classification. LABELS has one integer per line, as written by `detect --labels`.\n\n\
Example:\n  aniso-alpha eval --truth scene.xyz --labels labels.txt --json"
)]
pub struct EvalArgs {
    /// Ground-truth scene
    #[arg(long, value_name = "SCENE.xyz")]
    pub truth: PathBuf,
    /// Detected labels, one per line
    #[arg(long, value_name = "LABELS.txt")]
    pub labels: PathBuf,
    /// Print the scores as JSON
    #[arg(long)]
    pub json: bool,
    /// 0-based column of the label in a text truth file
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub label_column: usize,
}

/// Runs `eval`.
pub fn run(args: &EvalArgs, timings: &mut Timings) -> Result<(), CliError> {
    let (cloud, truth) = common::read_truth(&args.truth, args.label_column, timings)?;
    let labels = timings.phase("read", || aniso_alpha::io::read_labels(&args.labels))?;
    if labels.len() != truth.len() {
        return Err(CliError::msg(format!(
            "{}: {} labels for {} points in {}",
            args.labels.display(),
            labels.len(),
            cloud.points.len(),
            args.truth.display()
        )));
    }
    Err(CliError::not_available("eval"))
}
