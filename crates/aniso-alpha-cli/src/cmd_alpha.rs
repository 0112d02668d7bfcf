//! `aniso-alpha alpha`: alpha-shape intervals, or the shape at one alpha.

use std::path::PathBuf;

use aniso_alpha::io::ReadOptions;
use clap::Args;

use crate::common::{self, parse_positive, parse_positive_triple, parse_triple, CliError, Timings};

/// Arguments of `alpha`.
#[derive(Debug, Args)]
#[command(
    after_help = "With --intervals: CSV with header `dim,v0,v1,v2,alpha_min,alpha_max`, one row \
per Delaunay edge (dim 1, v2 empty) and triangle (dim 2) of Del(Q·P), vertex indices ascending, \
`inf` for an unbounded alpha_max. Q = diag(e1,e2,e3)·R(theta,psi,phi), R = Rz(theta)·Rx(psi)·Ry(phi); \
the default is the identity (Euclidean).\n\
With --alpha A --output shape.ply: the edges and triangles with alpha_min <= A <= alpha_max.\n\n\
Examples:\n  aniso-alpha alpha scan.xyz --intervals intervals.csv\n  \
aniso-alpha alpha scan.xyz --intervals aniso.csv --elongation 1,1,0.125 --euler=0,0.3,-1.2\n  \
aniso-alpha alpha scan.xyz --alpha 0.5 --output shape.ply"
)]
pub struct AlphaArgs {
    /// Input point file (.xyz .txt .csv .pts .ply .las .laz .pcd)
    pub input: PathBuf,
    /// Write the alpha interval of every edge and triangle to this CSV file
    #[arg(long, value_name = "OUT.csv", required_unless_present = "output")]
    pub intervals: Option<PathBuf>,
    /// Elongation e1,e2,e3 (each > 0) of the metric Q = diag(e)·R
    #[arg(long, value_name = "e1,e2,e3", value_parser = parse_positive_triple)]
    pub elongation: Option<[f64; 3]>,
    /// Orientation angles theta,psi,phi (radians) of R = Rz(theta)·Rx(psi)·Ry(phi)
    #[arg(long, value_name = "theta,psi,phi", value_parser = parse_triple, allow_hyphen_values = true)]
    pub euler: Option<[f64; 3]>,
    /// Alpha of the shape written by --output
    #[arg(long, value_name = "A", value_parser = parse_positive, requires = "output")]
    pub alpha: Option<f64>,
    /// Write the alpha-shape at --alpha (PLY, or OBJ by extension)
    #[arg(long, value_name = "shape.ply", requires = "alpha")]
    pub output: Option<PathBuf>,
}

/// Runs `alpha`.
pub fn run(args: &AlphaArgs, timings: &mut Timings) -> Result<(), CliError> {
    common::check_outputs([args.intervals.as_deref()])?;
    if let Some(out) = &args.output {
        common::check_mesh_output(out)?;
    }
    let cloud = common::read_input(&args.input, &ReadOptions::default(), timings)?;
    let _ = cloud;
    Err(CliError::not_available("alpha"))
}
