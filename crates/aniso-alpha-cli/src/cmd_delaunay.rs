//! `aniso-alpha delaunay INPUT --tets OUT`.

use std::path::{Path, PathBuf};

use aniso_alpha::delaunay::Triangulation;
use aniso_alpha::io::{atomic_write, IoError, ReadOptions};
use clap::Args;

use crate::common::{self, push_u32, CliError, Timings};

/// Arguments of `delaunay`.
#[derive(Debug, Args)]
#[command(
    after_help = "Output: one finite tetrahedron per line, `i j k l` (0-based indices into \
INPUT, a duplicate point mapped to its first occurrence), positively oriented: \
orient3d(p_i, p_j, p_k, p_l) > 0. Coplanar or collinear input has no tetrahedron.\n\n\
Example:\n  aniso-alpha delaunay scan.ply --tets scan.tets --timings"
)]
pub struct DelaunayArgs {
    /// Input point file (.xyz .txt .csv .pts .ply .las .laz .pcd .e57)
    pub input: PathBuf,
    /// Output file of tetrahedra
    #[arg(long, allow_negative_numbers = true, value_name = "OUT")]
    pub tets: PathBuf,
    #[command(flatten)]
    pub input_format: crate::FormatArgs,
    #[command(flatten)]
    pub common: crate::CommonArgs,
}

/// Runs `delaunay`: input is read (and its errors reported) before anything else.
pub fn run(args: &DelaunayArgs, timings: &mut Timings) -> Result<(), CliError> {
    common::check_io(&[&args.input], &[("--tets", Some(&args.tets))])?;
    let cloud = common::read_input(&args.input, &ReadOptions::default(), timings)?;
    let bar = common::spinner("triangulating");
    let tri = timings
        .phase("triangulate", || {
            Triangulation::with_threads(&cloud.points, rayon::current_num_threads())
        })
        .map_err(|e| CliError::in_file(&args.input, e))?;
    bar.finish_and_clear();
    if tri.dimension() < 3 {
        common::info(format_args!(
            "{}: the points span {} dimension(s): no tetrahedra",
            args.input.display(),
            tri.dimension()
        ));
    }
    timings
        .phase("write", || write_tets(&args.tets, tri.finite_tets_input()))
        .map_err(|e| CliError::msg(e.to_string()))?;
    common::info(format_args!(
        "{} points ({} distinct), {} tetrahedra -> {}",
        tri.num_input_points(),
        tri.num_vertices(),
        tri.num_finite_tets(),
        args.tets.display()
    ));
    Ok(())
}

/// Writes tetrahedra, one per line `i j k l` (single spaces, `\n`),
/// atomically through a large buffer with hand-rolled integer formatting.
pub fn write_tets(path: &Path, tets: impl Iterator<Item = [u32; 4]>) -> Result<(), IoError> {
    const CHUNK: usize = 1 << 20;
    atomic_write(path, |w| {
        let mut buf = Vec::with_capacity(CHUNK + 64);
        for t in tets {
            push_u32(&mut buf, t[0]);
            buf.push(b' ');
            push_u32(&mut buf, t[1]);
            buf.push(b' ');
            push_u32(&mut buf, t[2]);
            buf.push(b' ');
            push_u32(&mut buf, t[3]);
            buf.push(b'\n');
            if buf.len() >= CHUNK {
                w.write_all(&buf)?;
                buf.clear();
            }
        }
        w.write_all(&buf)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tets_format() {
        let dir = std::env::temp_dir().join(format!("aniso-cli-tets-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.tets");
        write_tets(&p, [[0, 1, 2, 3], [10, 200, 3000, u32::MAX]].into_iter()).unwrap();
        assert_eq!(
            std::fs::read_to_string(&p).unwrap(),
            "0 1 2 3\n10 200 3000 4294967295\n"
        );
        write_tets(&p, std::iter::empty()).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "");
        // Large output crosses the buffer boundary.
        let n = 200_000u32;
        write_tets(&p, (0..n).map(|i| [i, i + 1, i + 2, i + 3])).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(text.lines().count(), n as usize);
        assert_eq!(text.lines().last(), Some("199999 200000 200001 200002"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
