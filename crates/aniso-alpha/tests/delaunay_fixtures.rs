//! Our tets equal CGAL's, tet for tet, on every reference fixture
//! (copied from the project's shared fixtures; see fixtures/CGAL_README.md).

use crate::common;
use aniso_alpha::delaunay::Triangulation;
use common::*;

fn check(name: &str, points_file: &str) {
    let pts = read_xyz(points_file);
    let tri = Triangulation::new(&pts).unwrap();
    tri.validate_with_input(&pts).unwrap();
    let ours = canonical_sorted(tri.finite_tets_input());
    let theirs = read_tets(&format!("{name}.tets"));
    assert_eq!(
        ours.len(),
        theirs.len(),
        "{name}: {} tets vs CGAL's {}",
        ours.len(),
        theirs.len()
    );
    let diff = ours.iter().zip(&theirs).filter(|(a, b)| a != b).count();
    assert_eq!(diff, 0, "{name}: tets differ from CGAL's");
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
    let pts = read_xyz("duplicates_50.xyz");
    let tri = Triangulation::new(&pts).unwrap();
    assert_eq!(tri.num_vertices(), 50);
    assert_eq!(tri.num_duplicates(), 50);
    check("duplicates_50", "duplicates_50.xyz");
}
#[test]
fn collinear_10() {
    let pts = read_xyz("collinear_10.xyz");
    let tri = Triangulation::new(&pts).unwrap();
    assert_eq!(tri.dimension(), 1);
    assert_eq!(tri.num_finite_tets(), 0);
    check("collinear_10", "collinear_10.xyz");
}
#[test]
fn coplanar_30() {
    let pts = read_xyz("coplanar_30.xyz");
    let tri = Triangulation::new(&pts).unwrap();
    assert_eq!(tri.dimension(), 2);
    check("coplanar_30", "coplanar_30.xyz");
}
