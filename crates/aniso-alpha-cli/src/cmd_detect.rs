//! `aniso-alpha detect`: structures by anisotropic alpha-shapes (SPEC §4).

use std::path::PathBuf;

use aniso_alpha::io::ReadOptions;
use clap::{Args, ValueEnum};

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
    /// Alpha (ball radius before elongation)
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
}

/// Runs `detect`.
pub fn run(args: &DetectArgs, timings: &mut Timings) -> Result<(), CliError> {
    common::check_outputs([args.labels.as_deref(), args.report.as_deref()])?;
    if let Some(out) = &args.output {
        common::check_mesh_output(out)?;
    }
    if let Some(input) = &args.input {
        let cloud = common::read_input(input, &ReadOptions::default(), timings)?;
        let _ = cloud;
    }
    Err(CliError::not_available("detect"))
}
