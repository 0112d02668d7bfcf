//! `aniso-alpha synth`: benchmark scenes with ground truth.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use crate::common::{self, CliError, Timings};

/// A benchmark scene kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Scene {
    /// Lines in uniform background (paper Fig. 12)
    Lines,
    /// Planes in uniform background
    Planes,
    /// A polyhedral surface in uniform background (paper Fig. 10)
    Polyhedron,
}

/// Arguments of `synth`.
#[derive(Debug, Args)]
#[command(
    after_help = "Output: text `x y z label`, one point per line, label -1 for background.\n\n\
Example:\n  aniso-alpha synth lines --seed 7 --output lines.xyz"
)]
pub struct SynthArgs {
    /// Scene kind
    #[arg(value_enum)]
    pub scene: Scene,
    /// Random seed
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
    /// Output scene file
    #[arg(long, value_name = "OUT.xyz")]
    pub output: PathBuf,
}

/// Runs `synth`.
pub fn run(args: &SynthArgs, _timings: &mut Timings) -> Result<(), CliError> {
    common::check_output(&args.output)?;
    Err(CliError::not_available("synth"))
}
