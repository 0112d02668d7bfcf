//! `aniso-alpha synth`: benchmark scenes with ground truth.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use aniso_alpha::io::write_scene;
use aniso_alpha::synth::SceneOptions;

use crate::common::{self, parse_positive, CliError, Timings};

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
    after_help = "Output: text `x y z label`, one point per line, label -1 for background \
(plus a 5th column `part`, the facet id, for the polyhedron or with --parts). The scales \
follow the paper's Observations 3 and 4 so that the paper's parameters work (lines: alpha 1, \
lambda3 10, min-size 4; planes and polyhedron: alpha 1, lambda2 4, lambda3 8, min-size 20); \
the command prints the matching detect line.\n\n\
Examples:\n  aniso-alpha synth lines --seed 7 --output lines.xyz\n  \
aniso-alpha synth planes --structures 2 --crossing --jitter 0.1 --output crossing.xyz\n  \
aniso-alpha synth lines --jitter-d 0.1 --density 0.03 --output hard.xyz"
)]
pub struct SynthArgs {
    /// Scene kind
    #[arg(value_enum)]
    pub scene: Scene,
    /// Random seed
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "S",
        default_value_t = 0
    )]
    pub seed: u64,
    /// Output scene file
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.xyz")]
    pub output: PathBuf,
    /// Number of uniform background points (default: the paper's count,
    /// scaled with --density)
    #[arg(long, allow_negative_numbers = true, value_name = "N")]
    pub background: Option<usize>,
    /// Background density in points per alpha-ellipsoid (default 0.01).
    /// Alone it keeps the paper's box and scales the background count
    /// (--density 0.03: 3x the paper's background in the same box); with
    /// --background N it sizes the box to hold N points at that density
    #[arg(long, allow_negative_numbers = true, value_name = "X", value_parser = parse_positive)]
    pub density: Option<f64>,
    /// Gaussian jitter (standard deviation, input units) of every
    /// coordinate of the structure points
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "SIGMA",
        default_value_t = 0.0,
        conflicts_with = "jitter_d"
    )]
    pub jitter: f64,
    /// Gaussian jitter as a fraction of the structure spacing d (lines
    /// d = 7, planes and polyhedron d = 3): sigma = F * d
    #[arg(long, allow_negative_numbers = true, value_name = "F", value_parser = parse_nonnegative)]
    pub jitter_d: Option<f64>,
    /// Sample the structures at random positions instead of on a grid
    #[arg(long)]
    pub random_sampling: bool,
    /// Number of structures (lines or planes; not for the polyhedron)
    #[arg(long, allow_negative_numbers = true, value_name = "N")]
    pub structures: Option<usize>,
    /// Make the structures cross (two lines through one point, planes
    /// cutting each other)
    #[arg(long)]
    pub crossing: bool,
    /// Also write the facet id of each point as a 5th column (polyhedron)
    #[arg(long)]
    pub parts: bool,
    #[command(flatten)]
    pub common: crate::QuietArgs,
}

/// clap parser for a finite number >= 0.
fn parse_nonnegative(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("expected a finite number >= 0, got '{s}'")),
    }
}

/// Runs `synth`.
pub fn run(args: &SynthArgs, timings: &mut Timings) -> Result<(), CliError> {
    common::check_io(&[], &[("--output", Some(&args.output))])?;
    let mut opts = match args.scene {
        Scene::Lines => SceneOptions::lines(),
        Scene::Planes => SceneOptions::planes(),
        Scene::Polyhedron => SceneOptions::polyhedron(),
    }
    .seed(args.seed)
    .jitter(args.jitter)
    .random_sampling(args.random_sampling)
    .crossing(args.crossing);
    if let Some(f) = args.jitter_d {
        opts = opts.jitter_of_spacing(f);
    }
    match (args.background, args.density) {
        (Some(n), Some(x)) => opts = opts.background(n).background_per_ellipsoid(x),
        (Some(n), None) => opts = opts.background(n),
        (None, Some(x)) => opts = opts.background_density_in_box(x),
        (None, None) => {}
    }
    if let Some(n) = args.structures {
        opts = opts.structures(n);
    }
    let scene = timings.phase("synth", || opts.generate())?;
    let with_parts = args.parts || args.scene == Scene::Polyhedron;
    timings.phase("write", || write_scene(&args.output, &scene, with_parts))?;
    let p = opts.paper_params();
    let structure = if p.k == 1 { "lines" } else { "planes" };
    let lambda2 = if p.k == 2 {
        format!(" --lambda2 {}", p.lambda2)
    } else {
        String::new()
    };
    common::info(format_args!(
        "{} points ({} structures) -> {}\ndetect with: aniso-alpha detect {} --structure {structure} \
--alpha {}{lambda2} --lambda3 {} --min-size {}",
        scene.points.len(),
        scene.num_structures(),
        args.output.display(),
        args.output.display(),
        p.alpha,
        p.lambda3,
        p.nb_c
    ));
    Ok(())
}
