//! Alpha intervals equal CGAL's `Alpha_shape_3` (GENERAL mode, exact
//! constructions) on every reference fixture: the same edges and triangles
//! (input indices, smallest index of a duplicated point), values within
//! 1e-9 relative, `inf` exactly where CGAL has it. See
//! fixtures/CGAL_README.md.

use crate::common;
use aniso_alpha::alpha::{q_matrix, AlphaComplex};
use common::*;

/// One row of `NAME.intervals.csv`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Row {
    key: (u8, u32, u32, u32),
    min: f64,
    max: f64,
}

fn read_intervals(name: &str) -> Vec<Row> {
    let text = std::fs::read_to_string(fixture_path(&format!("{name}.intervals.csv"))).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "dim,v0,v1,v2,alpha_min,alpha_max",
        "{name}: header"
    );
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let dim: u8 = f[0].parse().unwrap();
            let v2 = if dim == 1 {
                u32::MAX
            } else {
                f[3].parse().unwrap()
            };
            Row {
                key: (dim, f[1].parse().unwrap(), f[2].parse().unwrap(), v2),
                min: f[4].parse().unwrap(),
                max: f[5].parse().unwrap(),
            }
        })
        .collect()
}

fn ours(ac: &AlphaComplex) -> Vec<Row> {
    let mut v: Vec<Row> = ac
        .edges()
        .map(|e| Row {
            key: (1, e.vertices[0], e.vertices[1], u32::MAX),
            min: e.alpha_min,
            max: e.alpha_max,
        })
        .chain(ac.triangles().map(|t| Row {
            key: (2, t.vertices[0], t.vertices[1], t.vertices[2]),
            min: t.alpha_min,
            max: t.alpha_max,
        }))
        .collect();
    v.sort_by_key(|r| r.key);
    v
}

fn close(a: f64, b: f64) -> bool {
    if a.is_infinite() || b.is_infinite() {
        return a == b;
    }
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

fn compare(name: &str, ac: &AlphaComplex) {
    let theirs = read_intervals(name);
    let ours = ours(ac);
    assert_eq!(
        ours.len(),
        theirs.len(),
        "{name}: {} rows vs CGAL's {}",
        ours.len(),
        theirs.len()
    );
    let mut worst = 0.0f64;
    for (o, t) in ours.iter().zip(&theirs) {
        assert_eq!(o.key, t.key, "{name}: simplex differs");
        assert!(
            close(o.min, t.min) && close(o.max, t.max),
            "{name}: {:?}: ours [{}, {}], CGAL [{}, {}]",
            o.key,
            o.min,
            o.max,
            t.min,
            t.max
        );
        for (a, b) in [(o.min, t.min), (o.max, t.max)] {
            if a.is_finite() && a != 0.0 {
                worst = worst.max((a - b).abs() / a.abs());
            }
        }
    }
    eprintln!(
        "{name}: {} rows, worst relative error {worst:.3e}",
        ours.len()
    );
}

fn check(name: &str, points_file: &str) {
    let pts = read_xyz(points_file);
    let ac = AlphaComplex::from_points(&pts).unwrap();
    compare(name, &ac);
}

#[test]
fn random_500() {
    check("random_500", "random_500.xyz");
}
#[test]
fn grid_6() {
    check("grid_6", "grid_6.xyz");
}
#[test]
fn grid_6_aniso_transformed() {
    check("grid_6_aniso", "grid_6_aniso.transformed.xyz");
}
#[test]
fn sphere_100() {
    check("sphere_100", "sphere_100.xyz");
}
#[test]
fn cocircular_plane() {
    check("cocircular_plane", "cocircular_plane.xyz");
}
#[test]
fn duplicates_50() {
    check("duplicates_50", "duplicates_50.xyz");
}
#[test]
fn collinear_10() {
    let ac = AlphaComplex::from_points(&read_xyz("collinear_10.xyz")).unwrap();
    assert_eq!(ac.triangulation().dimension(), 1);
    assert_eq!((ac.num_edges(), ac.num_triangles()), (0, 0));
    assert_eq!(ac.optimal_alpha(), None);
    compare("collinear_10", &ac);
}
#[test]
fn coplanar_30() {
    let ac = AlphaComplex::from_points(&read_xyz("coplanar_30.xyz")).unwrap();
    assert_eq!(ac.triangulation().dimension(), 2);
    assert!(ac.spectrum().is_empty());
    compare("coplanar_30", &ac);
}

/// The anisotropic API reproduces `grid_6_aniso.transformed.xyz` bit for
/// bit from `grid_6_aniso.xyz`, the R rows of `grid_6_aniso.transform.txt`
/// and E = (1, 1/4, 1/8), and then CGAL's intervals.
#[test]
fn grid_6_aniso_through_api() {
    let text = std::fs::read_to_string(fixture_path("grid_6_aniso.transform.txt")).unwrap();
    let mut r = Vec::new();
    let mut e = Vec::new();
    for l in text.lines() {
        let f: Vec<&str> = l.split_whitespace().collect();
        match f.first() {
            Some(&"R") => r.push([f[1], f[2], f[3]].map(|x| x.parse::<f64>().unwrap())),
            Some(&"e") => e = f[1..4].iter().map(|x| x.parse::<f64>().unwrap()).collect(),
            _ => {}
        }
    }
    assert_eq!(e, vec![1.0, 0.25, 0.125]);
    let r: [[f64; 3]; 3] = [r[0], r[1], r[2]];
    let q = q_matrix(&r, &[1.0, 0.25, 0.125]);
    let pts = read_xyz("grid_6_aniso.xyz");
    let expected = read_xyz("grid_6_aniso.transformed.xyz");
    let ac = AlphaComplex::anisotropic(&pts, &q).unwrap();
    let tri = ac.triangulation();
    for (i, want) in expected.iter().enumerate() {
        let got = tri.point(tri.vertex_of_input(i));
        assert_eq!(
            got.map(f64::to_bits),
            want.map(f64::to_bits),
            "point {i}: {got:?} vs {want:?}"
        );
    }
    compare("grid_6_aniso", &ac);
}

/// Closed intervals: on `grid_6`, 875 simplices have α_min = α_max (= √3/2,
/// the cube diagonals and the triangles inside each cube); they are in F_α
/// at exactly that α, and only there (CGAL never calls them SINGULAR or
/// REGULAR).
#[test]
fn grid_6_point_intervals_are_in_f_alpha() {
    let ac = AlphaComplex::from_points(&read_xyz("grid_6.xyz")).unwrap();
    let points: Vec<(Vec<u32>, f64)> = ac
        .edges()
        .filter(|e| e.alpha_min == e.alpha_max)
        .map(|e| (e.vertices.to_vec(), e.alpha_min))
        .chain(
            ac.triangles()
                .filter(|t| t.alpha_min == t.alpha_max)
                .map(|t| (t.vertices.to_vec(), t.alpha_min)),
        )
        .collect();
    assert_eq!(points.len(), 875);
    let a = points[0].1;
    assert!(points.iter().all(|p| p.1 == a));
    assert!((a - 3f64.sqrt() / 2.0).abs() < 1e-15);
    let at: std::collections::HashSet<Vec<u32>> = ac
        .edges_at(a)
        .map(|e| e.to_vec())
        .chain(ac.triangles_at(a).map(|t| t.to_vec()))
        .collect();
    assert!(points.iter().all(|p| at.contains(&p.0)));
    let below = a * (1.0 - 1e-12);
    let above = a * (1.0 + 1e-12);
    for alpha in [below, above] {
        let n = ac
            .edges_at(alpha)
            .map(|e| e.to_vec())
            .chain(ac.triangles_at(alpha).map(|t| t.to_vec()))
            .filter(|s| points.iter().any(|p| &p.0 == s))
            .count();
        assert_eq!(n, 0, "at {alpha}");
    }
}
