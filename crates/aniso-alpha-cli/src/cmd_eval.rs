//! `aniso-alpha eval`: scores of a detection against ground truth (docs/method.md §6).

use std::path::PathBuf;

use clap::Args;

use aniso_alpha::eval::evaluate;
use serde_json::json;

use crate::common::{self, CliError, Timings};

/// Arguments of `eval`.
#[derive(Debug, Args)]
#[command(
    after_help = "TRUTH is a point file with labels: text `x y z label` (label column set by \
--label-column), PLY with a `structure` vertex property, PCD with a `label` field, LAS \
classification. LABELS has one integer per line, as written by `detect --labels`.\n\n\
Scores (docs/method.md §6): per-point precision, recall and F1 of structure vs background, and \
structures found (one detected structure holds at least half of a true structure's points, \
and most of its own points are that structure's).\n\n\
Examples:\n  aniso-alpha eval --truth scene.xyz --labels labels.txt --json\n  \
aniso-alpha eval --truth poly.xyz --labels labels.txt --part-column 4 --part-labels parts.txt"
)]
pub struct EvalArgs {
    /// Ground-truth scene
    #[arg(long, allow_negative_numbers = true, value_name = "SCENE.xyz")]
    pub truth: PathBuf,
    /// Detected labels, one per line
    #[arg(long, allow_negative_numbers = true, value_name = "LABELS.txt")]
    pub labels: PathBuf,
    /// Print the scores as JSON
    #[arg(long)]
    pub json: bool,
    /// 0-based column of the label in a text truth file
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "N",
        default_value_t = 3
    )]
    pub label_column: usize,
    /// 0-based column of the true facet (part) id, to score parts too
    /// (`synth polyhedron` writes it in column 4)
    #[arg(long, allow_negative_numbers = true, value_name = "N")]
    pub part_column: Option<usize>,
    /// Detected part labels, one per line (`detect --part-labels`)
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "PARTS.txt",
        requires = "part_column"
    )]
    pub part_labels: Option<PathBuf>,
    /// LAS truth: classes read as background (-1), comma-separated, or
    /// `none` [default: 0,1,7,18: never classified, unclassified, noise]
    #[arg(long, allow_negative_numbers = true, value_name = "C1,C2,...", value_parser = common::parse_classes)]
    pub background_classes: Option<aniso_alpha::io::ClassSet>,
    #[command(flatten)]
    pub input_format: crate::FormatArgs,
    #[command(flatten)]
    pub common: crate::QuietArgs,
}

/// Runs `eval`.
pub fn run(args: &EvalArgs, timings: &mut Timings) -> Result<(), CliError> {
    let background = args.background_classes.unwrap_or_default();
    let (cloud, truth) = common::read_truth(&args.truth, args.label_column, background, timings)?;
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
    let truth_parts = match args.part_column {
        Some(col) => Some(common::read_truth(&args.truth, col, background, timings)?.1),
        None => None,
    };
    let predicted_parts = match &args.part_labels {
        Some(p) => Some(timings.phase("read", || aniso_alpha::io::read_labels(p))?),
        None => None,
    };
    let ev = timings.phase("eval", || {
        evaluate(
            &truth,
            truth_parts.as_deref(),
            &labels,
            predicted_parts.as_deref(),
        )
    })?;
    if args.json {
        let v = json!({
            "points": ev.points,
            "true_positives": ev.true_positives,
            "false_positives": ev.false_positives,
            "false_negatives": ev.false_negatives,
            "true_negatives": ev.true_negatives,
            "precision": ev.precision,
            "recall": ev.recall,
            "f1": ev.f1,
            "structures_total": ev.structures_total,
            "structures_found": ev.structures_found,
            "detected_structures": ev.detected_structures,
            "parts_total": ev.parts_total,
            "parts_found": ev.parts_found,
        });
        common::print_stdout(&format!("{v}\n"))
    } else {
        common::print_stdout(&format!("{ev}\n"))
    }
}
