//! `aniso-alpha alpha`: alpha-shape intervals, or the shape at one alpha.

use std::io::Write;
use std::path::PathBuf;

use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::aniso::Anisotropy;
use aniso_alpha::delaunay::Triangulation;
use aniso_alpha::io::{Mesh, ReadOptions};
use clap::Args;

use crate::common::{
    self, parse_positive, parse_positive_triple, parse_triple, push_u32, CliError, Timings,
};

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
    if let Some(out) = &args.output {
        common::mesh_format(out)?;
    }
    common::check_io(
        &[&args.input],
        &[
            ("--intervals", args.intervals.as_deref()),
            ("--output", args.output.as_deref()),
        ],
    )?;
    let cloud = common::read_input(&args.input, &ReadOptions::default(), timings)?;
    let e = args.elongation.unwrap_or([1.0, 1.0, 1.0]);
    let [theta, psi, phi] = args.euler.unwrap_or([0.0, 0.0, 0.0]);
    let aniso = Anisotropy::from_euler(theta, psi, phi, e)?;
    let euclidean = args.elongation.is_none() && args.euler.is_none();
    let bar = common::spinner("triangulating");
    let tri = timings
        .phase("triangulate", || {
            let threads = rayon::current_num_threads();
            if euclidean {
                Triangulation::with_threads(&cloud.points, threads)
            } else {
                Triangulation::with_threads(&aniso.transform(&cloud.points), threads)
            }
        })
        .map_err(|err| CliError::in_file(&args.input, err))?;
    bar.set_message("alpha intervals");
    let ac = timings.phase("intervals", || AlphaComplex::new(tri));
    bar.finish_and_clear();
    if ac.triangulation().dimension() < 3 {
        common::info(format_args!(
            "{}: the points span {} dimension(s): no tetrahedra, so no alpha intervals",
            args.input.display(),
            ac.triangulation().dimension()
        ));
    }
    if let Some(path) = &args.intervals {
        common::write_output(path, timings, |w| write_intervals(w, &ac))?;
        common::info(format_args!(
            "{} edges, {} triangles -> {}",
            ac.num_edges(),
            ac.num_triangles(),
            path.display()
        ));
    }
    if let (Some(alpha), Some(path)) = (args.alpha, &args.output) {
        let faces: Vec<[u32; 3]> = ac.triangles_at(alpha).collect();
        // Edges of F_alpha that bound no triangle of F_alpha.
        let mut in_tri: Vec<[u32; 2]> = faces
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[0], t[2]], [t[1], t[2]]])
            .collect();
        in_tri.sort_unstable();
        in_tri.dedup();
        let edges: Vec<[u32; 2]> = ac
            .edges_at(alpha)
            .filter(|e| in_tri.binary_search(e).is_err())
            .collect();
        let mesh = Mesh {
            edges: &edges,
            faces: &faces,
            ..Mesh::new(&cloud.points)
        };
        common::write_mesh(path, &mesh, timings)?;
        common::info(format_args!(
            "alpha {alpha}: {} triangles, {} dangling edges -> {}",
            faces.len(),
            edges.len(),
            path.display()
        ));
    }
    Ok(())
}

/// `dim,v0,v1,v2,alpha_min,alpha_max`, edges then triangles, each sorted
/// by vertices; values in Rust's shortest round-trip form, `inf` unbounded.
fn write_intervals(w: &mut dyn Write, ac: &AlphaComplex) -> std::io::Result<()> {
    let mut edges: Vec<_> = ac.edges().collect();
    edges.sort_unstable_by_key(|e| e.vertices);
    let mut tris: Vec<_> = ac.triangles().collect();
    tris.sort_unstable_by_key(|t| t.vertices);
    let mut buf = Vec::with_capacity(1 << 20);
    buf.extend_from_slice(b"dim,v0,v1,v2,alpha_min,alpha_max\n");
    let num = |buf: &mut Vec<u8>, x: f64| {
        if x.is_infinite() {
            buf.extend_from_slice(b"inf");
        } else {
            buf.extend_from_slice(format!("{x:?}").as_bytes());
        }
    };
    for e in &edges {
        buf.extend_from_slice(b"1,");
        push_u32(&mut buf, e.vertices[0]);
        buf.push(b',');
        push_u32(&mut buf, e.vertices[1]);
        buf.extend_from_slice(b",,");
        num(&mut buf, e.alpha_min);
        buf.push(b',');
        num(&mut buf, e.alpha_max);
        buf.push(b'\n');
        if buf.len() > 1 << 20 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    for t in &tris {
        buf.extend_from_slice(b"2,");
        for (i, v) in t.vertices.iter().enumerate() {
            if i > 0 {
                buf.push(b',');
            }
            push_u32(&mut buf, *v);
        }
        buf.push(b',');
        num(&mut buf, t.alpha_min);
        buf.push(b',');
        num(&mut buf, t.alpha_max);
        buf.push(b'\n');
        if buf.len() > 1 << 20 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}
