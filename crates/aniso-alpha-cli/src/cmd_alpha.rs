//! `aniso-alpha alpha`: alpha-shape intervals, or the shape at one alpha.

use std::io::Write;
use std::path::{Path, PathBuf};

use aniso_alpha::alpha::{AlphaComplex, EdgeInterval, TriangleInterval};
use aniso_alpha::aniso::Anisotropy;
use aniso_alpha::delaunay::Triangulation;
use aniso_alpha::io::{Mesh, ReadOptions};
use clap::{ArgGroup, Args};

use crate::common::{
    self, parse_positive, parse_positive_triple, parse_triple, push_u32, CliError, Timings,
};

/// Arguments of `alpha`.
#[derive(Debug, Args)]
#[command(
    // Something to do; --alpha alone then asks for an output of the shape.
    group(ArgGroup::new("action").required(true).multiple(true)
        .args(["intervals", "alpha", "output", "png", "optimal_alpha"])),
    group(ArgGroup::new("shape_out").multiple(true).args(["output", "png"])),
    group(ArgGroup::new("which_alpha").args(["alpha", "optimal_alpha"])),
    override_usage = "aniso-alpha alpha <INPUT> --intervals <OUT.csv> [--elongation <e1,e2,e3>] [--euler <theta,psi,phi>]\n       \
aniso-alpha alpha <INPUT> (--alpha <A> | --optimal-alpha) [--surface] (--output <shape.ply> | --png <OUT.png>)\n       \
aniso-alpha alpha <INPUT> --optimal-alpha",
    after_help = "Alpha is a radius: the ball (or, with --elongation, the ellipsoid's unit \
semi-axis) of radius alpha. CGAL's Alpha_shape_3 takes the squared radius instead: alpha 0.5 \
here is CGAL's alpha 0.25.\n\
With --intervals: CSV with header `dim,v0,v1,v2,alpha_min,alpha_max`, one row \
per Delaunay edge (dim 1, v2 empty) and triangle (dim 2) of Del(Q·P), vertex indices ascending, \
`inf` for an unbounded alpha_max (radii, like --alpha). Q = diag(e1,e2,e3)·R(theta,psi,phi), \
R = Rz(theta)·Rx(psi)·Ry(phi); the default is the identity (Euclidean). See docs/method.md §1-§2. \
With --intervals OUT.npy: the same rows as one NumPy structured array (np.load), fields dim (u1), \
v0, v1, v2 (u4; v2 = 4294967295 for an edge), alpha_min, alpha_max (f8), written 5-10 times \
faster than the CSV and 2.5 times smaller.\n\
With --alpha A --output shape.ply: the alpha-shape F_alpha of the paper, every edge and triangle \
with alpha_min <= A <= alpha_max (unoriented triangles, plus the edges that bound no triangle). \
With --surface: only the boundary of the alpha-complex's solid part, triangles oriented outward \
(CGAL's REGULAR facets; the mesh Open3D and CGAL users call the alpha shape).\n\
--optimal-alpha: the smallest alpha at which the alpha-complex is one solid holding every point \
(CGAL's find_optimal_alpha(1)); printed on stdout, and used by --output/--png.\n\n\
Examples:\n  aniso-alpha alpha scan.xyz --intervals intervals.csv\n  \
aniso-alpha alpha scan.xyz --intervals intervals.npy\n  \
aniso-alpha alpha scan.xyz --intervals aniso.csv --elongation 1,1,0.125 --euler=0,0.3,-1.2\n  \
aniso-alpha alpha scan.xyz --alpha 0.5 --output shape.ply\n  \
aniso-alpha alpha scan.xyz --optimal-alpha --surface --output surface.ply --png surface.png"
)]
pub struct AlphaArgs {
    /// Input point file (.xyz .txt .csv .pts .ply .las .laz .pcd .e57)
    pub input: PathBuf,
    /// Write the alpha interval of every edge and triangle to this CSV
    /// file, or NumPy .npy file (binary, by extension)
    #[arg(long, allow_negative_numbers = true, value_name = "OUT.csv|npy")]
    pub intervals: Option<PathBuf>,
    /// Elongation e1,e2,e3 (each > 0) of the metric Q = diag(e)·R
    #[arg(long, allow_negative_numbers = true, value_name = "e1,e2,e3", value_parser = parse_positive_triple)]
    pub elongation: Option<[f64; 3]>,
    /// Orientation angles theta,psi,phi (radians) of R = Rz(theta)·Rx(psi)·Ry(phi)
    #[arg(long, allow_negative_numbers = true, value_name = "theta,psi,phi", value_parser = parse_triple, allow_hyphen_values = true)]
    pub euler: Option<[f64; 3]>,
    /// Alpha of the shape written by --output/--png: a radius (CGAL's
    /// Alpha_shape_3 takes its square)
    #[arg(long, allow_negative_numbers = true, value_name = "A", value_parser = parse_positive, requires = "shape_out")]
    pub alpha: Option<f64>,
    /// Use (and print) the optimal alpha: the smallest at which the
    /// alpha-complex is one solid holding every point
    #[arg(long)]
    pub optimal_alpha: bool,
    /// Write the alpha-shape (PLY, or OBJ by extension)
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "shape.ply",
        requires = "which_alpha"
    )]
    pub output: Option<PathBuf>,
    /// Write only the oriented boundary surface (regular triangles, normals
    /// outward) instead of every edge and triangle of F_alpha
    #[arg(long, requires = "shape_out")]
    pub surface: bool,
    /// Write a picture of the alpha-shape (PNG, fixed view)
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "OUT.png",
        requires = "which_alpha"
    )]
    pub png: Option<PathBuf>,
    #[command(flatten)]
    pub input_format: crate::FormatArgs,
    #[command(flatten)]
    pub common: crate::CommonArgs,
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
            ("--png", args.png.as_deref()),
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
        if is_npy(path) {
            common::write_output(path, timings, |w| write_intervals_npy(w, &ac))?;
        } else {
            common::write_output(path, timings, |w| write_intervals(w, &ac))?;
        }
        common::info(format_args!(
            "{} edges, {} triangles -> {}",
            ac.num_edges(),
            ac.num_triangles(),
            path.display()
        ));
    }
    let alpha = if args.optimal_alpha {
        match ac.optimal_alpha() {
            Some(a) => {
                common::print_stdout(&format!("optimal alpha {a:?}\n"))?;
                Some(a)
            }
            None => {
                return Err(CliError::in_file(
                    &args.input,
                    "no tetrahedra (the points are coplanar or collinear): no optimal alpha",
                ))
            }
        }
    } else {
        args.alpha
    };
    let Some(alpha) = alpha else {
        return Ok(());
    };
    if args.output.is_none() && args.png.is_none() {
        return Ok(());
    }
    let (faces, edges) = if args.surface {
        (ac.regular_surface(alpha), Vec::new())
    } else {
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
        (faces, edges)
    };
    if let Some(path) = &args.output {
        let mesh = Mesh {
            edges: &edges,
            faces: &faces,
            ..Mesh::new(&cloud.points)
        };
        common::write_mesh(path, &mesh, timings)?;
    }
    if let Some(path) = &args.png {
        let png = timings.phase("picture", || {
            crate::picture::shape_png(&cloud.points, &faces, &edges)
        })?;
        common::write_output(path, timings, |w| w.write_all(&png))?;
    }
    let what = if args.surface {
        format!("{} boundary triangles", faces.len())
    } else {
        format!("{} triangles, {} dangling edges", faces.len(), edges.len())
    };
    let dest: Vec<String> = [&args.output, &args.png]
        .into_iter()
        .flatten()
        .map(|p| p.display().to_string())
        .collect();
    common::info(format_args!("alpha {alpha}: {what} -> {}", dest.join(", ")));
    Ok(())
}

/// Whether an intervals output is a NumPy file (by extension).
fn is_npy(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// The edges and the triangles of `ac`, each sorted by vertices: the rows
/// of an intervals output.
fn sorted_simplices(ac: &AlphaComplex) -> (Vec<EdgeInterval>, Vec<TriangleInterval>) {
    use rayon::slice::ParallelSliceMut;
    let mut edges: Vec<_> = ac.edges().collect();
    edges.par_sort_unstable_by_key(|e| e.vertices);
    let mut tris: Vec<_> = ac.triangles().collect();
    tris.par_sort_unstable_by_key(|t| t.vertices);
    (edges, tris)
}

/// The NumPy dtype of an intervals row (packed, little-endian, 29 bytes).
const NPY_DESCR: &str = "[('dim', '|u1'), ('v0', '<u4'), ('v1', '<u4'), ('v2', '<u4'), \
('alpha_min', '<f8'), ('alpha_max', '<f8')]";

/// The rows of [`write_intervals`] as a NumPy `.npy` file (format 1.0):
/// one structured array, v2 = `u32::MAX` for an edge, `inf` unbounded.
fn write_intervals_npy(w: &mut dyn Write, ac: &AlphaComplex) -> std::io::Result<()> {
    let (edges, tris) = sorted_simplices(ac);
    let mut header = format!(
        "{{'descr': {NPY_DESCR}, 'fortran_order': False, 'shape': ({},), }}",
        edges.len() + tris.len()
    );
    // Magic (6), version (2), header length (2), header: a multiple of 64.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let len = u16::try_from(header.len()).map_err(std::io::Error::other)?;
    let mut buf = Vec::with_capacity(1 << 20);
    buf.extend_from_slice(b"\x93NUMPY\x01\x00");
    buf.extend_from_slice(&len.to_le_bytes());
    buf.extend_from_slice(header.as_bytes());
    let rows = edges
        .iter()
        .map(|e| {
            (
                1u8,
                [e.vertices[0], e.vertices[1], u32::MAX],
                e.alpha_min,
                e.alpha_max,
            )
        })
        .chain(
            tris.iter()
                .map(|t| (2u8, t.vertices, t.alpha_min, t.alpha_max)),
        );
    for (dim, v, lo, hi) in rows {
        buf.push(dim);
        for x in v {
            buf.extend_from_slice(&x.to_le_bytes());
        }
        buf.extend_from_slice(&lo.to_le_bytes());
        buf.extend_from_slice(&hi.to_le_bytes());
        if buf.len() > 1 << 20 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

/// `dim,v0,v1,v2,alpha_min,alpha_max`, edges then triangles, each sorted
/// by vertices; values in Rust's shortest round-trip form, `inf` unbounded.
fn write_intervals(w: &mut dyn Write, ac: &AlphaComplex) -> std::io::Result<()> {
    let (edges, tris) = sorted_simplices(ac);
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
