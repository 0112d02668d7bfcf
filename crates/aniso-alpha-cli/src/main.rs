//! `aniso-alpha`: command-line front end of the aniso-alpha library.
//!
//! `main` parses the command line (clap; bad usage exits 2), sets up the
//! global options, dispatches to one module per subcommand and turns any
//! error into one line `error: <message>` on stderr with exit status 1.
// Two calls into glibc (`memory::one_arena`, `memory::release_free`) are
// the only unsafe code.
#![deny(unsafe_code)]

mod cmd_alpha;
mod cmd_delaunay;
mod cmd_detect;
mod cmd_eval;
mod cmd_regions;
mod cmd_synth;
mod cmd_view;
mod common;
mod memory;
mod picture;
mod view;

use std::num::NonZeroUsize;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};

use common::{CliError, Timings};

/// Find lines and planes in noisy 3D point clouds with anisotropic
/// alpha-shapes (Bougleux, Melkemi & Elmoataz 2005), on an exact 3D
/// Delaunay triangulation.
#[derive(Debug, Parser)]
#[command(name = "aniso-alpha", version, propagate_version = true)]
#[command(
    after_help = "Point files: .xyz .txt .csv .pts (text), .ply, .las/.laz, .pcd, .e57; `-` reads text from \
standard input; --format overrides the extension.\n\
Alpha is a radius throughout (CGAL's Alpha_shape_3 takes its square). The method: docs/method.md.\n\
Errors exit with status 1 and one line on stderr; bad usage exits with 2.\n\n\
Example:\n  aniso-alpha synth planes --seed 1 --output scene.xyz\n  \
aniso-alpha detect scene.xyz --structure planes --alpha 1 --lambda3 8 --min-size 20 --labels labels.txt\n  \
aniso-alpha eval --truth scene.xyz --labels labels.txt"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The options of the subcommands that compute (`delaunay`, `alpha`,
/// `detect`), listed under their own heading in `--help`.
#[derive(Debug, Clone, Copy, Args)]
#[command(next_help_heading = "Common options")]
pub struct CommonArgs {
    /// Worker threads (default: all cores)
    #[arg(long, allow_negative_numbers = true, value_name = "N")]
    pub threads: Option<NonZeroUsize>,
    /// No progress bars, messages or summary: nothing but errors, the files
    /// asked for, and a value asked for on stdout (alpha --optimal-alpha)
    #[arg(long)]
    pub quiet: bool,
    /// Print the wall time of each phase (seconds) as one JSON object on stderr
    #[arg(long)]
    pub timings: bool,
}

/// The common options of the subcommands that run on one thread (`synth`,
/// `eval`, `view`): [`CommonArgs`] without `--threads`.
#[derive(Debug, Clone, Copy, Args)]
#[command(next_help_heading = "Common options")]
pub struct QuietArgs {
    /// No progress bars or messages (results asked for on stdout, such as
    /// eval's scores, still print)
    #[arg(long)]
    pub quiet: bool,
    /// Print the wall time of each phase (seconds) as one JSON object on stderr
    #[arg(long)]
    pub timings: bool,
}

/// The input format option of the subcommands that read a point file.
#[derive(Debug, Clone, Copy, Args)]
#[command(next_help_heading = "Common options")]
pub struct FormatArgs {
    /// Input format, overriding the extension: xyz, ply, las, laz, pcd, e57
    /// (an INPUT of `-` is standard input, text unless --format says otherwise)
    #[arg(long, allow_negative_numbers = true, value_name = "FMT", value_parser = common::parse_format)]
    pub format: Option<aniso_alpha::io::Format>,
}

impl From<QuietArgs> for CommonArgs {
    fn from(q: QuietArgs) -> Self {
        CommonArgs {
            threads: None,
            quiet: q.quiet,
            timings: q.timings,
        }
    }
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Delaunay tetrahedralization: one finite tetrahedron per line
    Delaunay(cmd_delaunay::DelaunayArgs),
    /// Alpha-shape intervals of every edge and triangle, or the shape at one alpha
    Alpha(cmd_alpha::AlphaArgs),
    /// Detect lines or planes with anisotropic alpha-shapes
    Detect(cmd_detect::DetectArgs),
    /// Write a benchmark scene with ground-truth labels
    Synth(cmd_synth::SynthArgs),
    /// Score detected labels against ground truth
    Eval(cmd_eval::EvalArgs),
    /// Write an interactive 3D view (one self-contained HTML file) of a
    /// point cloud and its structures
    View(cmd_view::ViewArgs),
}

impl Command {
    /// `--format`, for the subcommands that read a point file.
    fn format(&self) -> Option<aniso_alpha::io::Format> {
        match self {
            Command::Delaunay(a) => a.input_format.format,
            Command::Alpha(a) => a.input_format.format,
            Command::Detect(a) => a.input_format.format,
            Command::Eval(a) => a.input_format.format,
            Command::View(a) => a.input_format.format,
            Command::Synth(_) => None,
        }
    }

    fn common(&self) -> CommonArgs {
        match self {
            Command::Delaunay(a) => a.common,
            Command::Alpha(a) => a.common,
            Command::Detect(a) => a.common,
            Command::Synth(a) => a.common.into(),
            Command::Eval(a) => a.common.into(),
            Command::View(a) => a.common.into(),
        }
    }
}

/// Last resort: a panic is a bug, reported as one line, exit status 1.
fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let payload = info.payload();
        let msg = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".to_string());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let line = CliError::msg(format!(
            "internal error: {msg}{at} (this is a bug, please report it)"
        ))
        .one_line();
        eprintln!("error: {line}");
        std::process::exit(1);
    }));
}

fn run(cli: Cli) -> Result<(), CliError> {
    // With --timings, stderr carries exactly one JSON object for scripts:
    // no informational lines around it.
    let global = cli.command.common();
    common::set_quiet(global.quiet || global.timings);
    common::set_silent(global.quiet);
    common::set_format(cli.command.format());
    if let Some(n) = global.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n.get())
            .build_global()
            .map_err(|e| CliError::msg(format!("--threads {n}: {e}")))?;
    }
    let mut timings = Timings::new();
    match &cli.command {
        Command::Delaunay(a) => cmd_delaunay::run(a, &mut timings)?,
        Command::Alpha(a) => cmd_alpha::run(a, &mut timings)?,
        Command::Detect(a) => cmd_detect::run(a, &mut timings)?,
        Command::Synth(a) => cmd_synth::run(a, &mut timings)?,
        Command::Eval(a) => cmd_eval::run(a, &mut timings)?,
        Command::View(a) => cmd_view::run(a, &mut timings)?,
    }
    if global.timings {
        eprintln!("{}", timings.to_json());
    }
    Ok(())
}

fn main() -> ExitCode {
    memory::one_arena();
    install_panic_hook();
    common::install_signal_cleanup();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", e.one_line());
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_is_consistent() {
        Cli::command().debug_assert();
    }

    /// The help cites the method page that is in the repository, groups
    /// the common options, and says what α is.
    #[test]
    fn help_is_grouped_and_cites_what_exists() {
        let mut cmd = Cli::command();
        cmd.build();
        for sub in cmd.get_subcommands_mut() {
            let name = sub.get_name().to_string();
            if name == "help" {
                continue;
            }
            let help = sub.render_long_help().to_string();
            assert!(!help.contains("SPEC"), "{name}");
            // Every input format the readers take is named, E57 included.
            if matches!(name.as_str(), "delaunay" | "alpha" | "view") {
                assert!(help.contains(".pcd .e57)"), "{name}");
            }
            let common = help
                .find("Common options:")
                .unwrap_or_else(|| panic!("{name}"));
            // Every common option is listed under that heading, after the
            // subcommand's own options.
            for opt in ["--quiet", "--timings"] {
                assert!(help[common..].contains(opt), "{name} {opt}");
                assert!(
                    !help[..common].contains(&format!("      {opt}")),
                    "{name} {opt}"
                );
            }
            let threads = matches!(name.as_str(), "delaunay" | "alpha" | "detect");
            assert_eq!(help.contains("--threads"), threads, "{name}");
            if matches!(name.as_str(), "alpha" | "detect") {
                assert!(help.contains("radius") && help.contains("square"), "{name}");
            }
        }
        assert!(std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../docs/method.md")
            .is_file());
    }

    #[test]
    fn every_subcommand_has_an_example() {
        for sub in Cli::command().get_subcommands() {
            let help = sub
                .get_after_help()
                .map(|h| h.to_string())
                .unwrap_or_default();
            assert!(help.contains("aniso-alpha "), "{}", sub.get_name());
        }
    }
}
