//! Property tests of the Delaunay engine on random and degenerate inputs,
//! and a brute-force oracle on small inputs.
//!
//! Every generated case calls `validate_with_input()`: neighbour symmetry,
//! orientation, local Delaunay with the perturbation (including hull
//! convexity), Euler characteristic, every input point a vertex.

use crate::common;
use aniso_alpha::delaunay::Triangulation;
use aniso_alpha::geometry::predicates::{insphere_perturbed, orient3d, Sign};
use common::{canonical_sorted, Rng};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// A fixed-seed runner so that CI runs are reproducible.
fn runner(cases: u32) -> TestRunner {
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &[7u8; 32]))
}

fn check_valid(pts: &[[f64; 3]]) -> Triangulation {
    let tri = Triangulation::new(pts).expect("triangulation");
    if let Err(e) = tri.validate_with_input(pts) {
        panic!("invalid triangulation of {} points: {e}", pts.len());
    }
    tri
}

/// Expected dimension by brute force on the distinct points.
fn affine_dim(pts: &[[f64; 3]]) -> usize {
    let a = pts[0];
    let Some(b) = pts.iter().find(|p| **p != a) else {
        return 0;
    };
    let Some(c) = pts
        .iter()
        .find(|p| !aniso_alpha::geometry::predicates::collinear(&a, b, p))
    else {
        return 1;
    };
    if pts.iter().any(|p| orient3d(&a, b, c, p) != Sign::Zero) {
        3
    } else {
        2
    }
}

fn points(rng: &mut Rng, n: usize) -> Vec<[f64; 3]> {
    (0..n)
        .map(|_| [rng.uniform(), rng.uniform(), rng.uniform()])
        .collect()
}

fn grid(n: usize) -> Vec<[f64; 3]> {
    let mut v = Vec::new();
    for x in 0..n {
        for y in 0..n {
            for z in 0..n {
                v.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    v
}

fn shuffled(mut v: Vec<[f64; 3]>, rng: &mut Rng) -> Vec<[f64; 3]> {
    for i in (1..v.len()).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        v.swap(i, j);
    }
    v
}

#[test]
fn uniform_random() {
    runner(40)
        .run(&(any::<u64>(), 4usize..400), |(seed, n)| {
            let pts = points(&mut Rng::new(seed), n);
            let tri = check_valid(&pts);
            prop_assert_eq!(tri.dimension(), 3);
            prop_assert_eq!(tri.num_vertices(), n);
            Ok(())
        })
        .unwrap();
}

#[test]
fn clustered() {
    runner(30)
        .run(
            &(any::<u64>(), 1usize..6, 10usize..120),
            |(seed, k, per)| {
                let mut rng = Rng::new(seed);
                let mut pts = Vec::new();
                for _ in 0..k {
                    let c = [
                        rng.uniform() * 100.0,
                        rng.uniform() * 100.0,
                        rng.uniform() * 100.0,
                    ];
                    let r = 10f64.powi(-((rng.next_u64() % 6) as i32));
                    for _ in 0..per {
                        pts.push([
                            c[0] + r * (rng.uniform() - 0.5),
                            c[1] + r * (rng.uniform() - 0.5),
                            c[2] + r * (rng.uniform() - 0.5),
                        ]);
                    }
                }
                check_valid(&pts);
                Ok(())
            },
        )
        .unwrap();
}

#[test]
fn integer_grids() {
    // n³ grids in random order: 8 cospherical points per cube, coplanar hull.
    for n in 2..=7 {
        let pts = shuffled(grid(n), &mut Rng::new(n as u64));
        let tri = check_valid(&pts);
        assert_eq!(tri.dimension(), 3);
        // CGAL's perturbed triangulation of a grid has 6 tets per cube
        // (705,894 on the 50³ grid: 6·49³ = 705,894).
        assert_eq!(tri.num_finite_tets(), 6 * (n - 1).pow(3), "grid {n}");
    }
}

#[test]
fn grid_under_random_affine_map() {
    runner(25)
        .run(&(any::<u64>(), 2usize..6), |(seed, n)| {
            let mut rng = Rng::new(seed);
            let m: Vec<f64> = (0..9).map(|_| rng.uniform() * 2.0 - 1.0).collect();
            let t = [rng.uniform() * 10.0, rng.uniform(), -rng.uniform()];
            let pts: Vec<[f64; 3]> = grid(n)
                .iter()
                .map(|p| {
                    let mut q = [0.0; 3];
                    for i in 0..3 {
                        q[i] = t[i] + m[3 * i] * p[0] + m[3 * i + 1] * p[1] + m[3 * i + 2] * p[2];
                    }
                    q
                })
                .collect();
            let tri = check_valid(&pts);
            prop_assert_eq!(tri.dimension(), affine_dim(&pts));
            Ok(())
        })
        .unwrap();
}

#[test]
fn dyadic_affine_grids_stay_degenerate() {
    // Maps with dyadic entries keep the grid exactly degenerate (coplanar
    // and cospherical sets survive rounding): ties everywhere.
    for (k, m) in [
        [1.0, 0.5, 0.0, 0.0, 1.0, 0.25, 0.0, 0.0, 2.0],
        [0.5, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 0.125],
        [1.0, 1.0, 0.0, -1.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    ]
    .iter()
    .enumerate()
    {
        let pts: Vec<[f64; 3]> = shuffled(grid(5), &mut Rng::new(k as u64))
            .iter()
            .map(|p| {
                [
                    m[0] * p[0] + m[1] * p[1] + m[2] * p[2],
                    m[3] * p[0] + m[4] * p[1] + m[5] * p[2],
                    m[6] * p[0] + m[7] * p[1] + m[8] * p[2],
                ]
            })
            .collect();
        check_valid(&pts);
    }
}

#[test]
fn points_on_a_sphere() {
    // All integer points of x² + y² + z² = r²: exactly cospherical.
    for r in [3i32, 5, 7, 9, 11] {
        let mut pts = Vec::new();
        for x in -r..=r {
            for y in -r..=r {
                for z in -r..=r {
                    if x * x + y * y + z * z == r * r {
                        pts.push([x as f64, y as f64, z as f64]);
                    }
                }
            }
        }
        let pts = shuffled(pts, &mut Rng::new(r as u64));
        let tri = check_valid(&pts);
        // Every point is on the hull.
        let mut on_hull = vec![false; tri.num_vertices()];
        for f in tri.hull_facets() {
            for v in f {
                on_hull[v as usize] = true;
            }
        }
        assert!(on_hull.iter().all(|&h| h), "sphere {r}");
    }
    // Floating-point points near a sphere (not exactly cospherical).
    runner(20)
        .run(&(any::<u64>(), 5usize..300), |(seed, n)| {
            let mut rng = Rng::new(seed);
            let pts: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let z = 2.0 * rng.uniform() - 1.0;
                    let t = 2.0 * std::f64::consts::PI * rng.uniform();
                    let s = (1.0 - z * z).sqrt();
                    [s * t.cos(), s * t.sin(), z]
                })
                .collect();
            check_valid(&pts);
            Ok(())
        })
        .unwrap();
}

#[test]
fn stacked_cocircular_planes() {
    // Regular polygons (exactly cocircular after rounding? not always) and
    // square grids stacked in z: many cocircular, coplanar and cospherical sets.
    runner(20)
        .run(
            &(any::<u64>(), 2usize..6, 3usize..9),
            |(seed, layers, k)| {
                let mut rng = Rng::new(seed);
                let mut pts = Vec::new();
                for l in 0..layers {
                    // square k x k grid layer (exactly cocircular squares)
                    for i in 0..k {
                        for j in 0..k {
                            pts.push([i as f64, j as f64, 2.0 * l as f64]);
                        }
                    }
                    // octagon with integer coordinates: (±1, ±2), (±2, ±1)
                    for (a, b) in [(1.0, 2.0), (2.0, 1.0)] {
                        for (sa, sb) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                            pts.push([10.0 + sa * a, 10.0 + sb * b, 2.0 * l as f64 + 1.0]);
                        }
                    }
                }
                let pts = shuffled(pts, &mut rng);
                check_valid(&pts);
                Ok(())
            },
        )
        .unwrap();
}

#[test]
fn duplicates_merge() {
    runner(30)
        .run(
            &(any::<u64>(), 1usize..80, 1usize..4),
            |(seed, n, copies)| {
                let mut rng = Rng::new(seed);
                let base = points(&mut rng, n);
                let mut pts = Vec::new();
                for _ in 0..copies {
                    pts.extend_from_slice(&base);
                }
                let pts = shuffled(pts, &mut rng);
                let tri = check_valid(&pts);
                prop_assert_eq!(tri.num_vertices(), n);
                prop_assert_eq!(tri.num_duplicates(), n * (copies - 1));
                for (i, p) in pts.iter().enumerate() {
                    let v = tri.vertex_of_input(i);
                    let first = pts.iter().position(|q| q == p).unwrap();
                    prop_assert_eq!(tri.input_index(v) as usize, first);
                }
                Ok(())
            },
        )
        .unwrap();
}

#[test]
fn signed_zeros_are_one_point() {
    let pts = [
        [0.0, 0.0, 0.0],
        [-0.0, 0.0, -0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let tri = check_valid(&pts);
    assert_eq!(tri.num_vertices(), 4);
    assert_eq!(tri.vertex_of_input(0), tri.vertex_of_input(1));
}

#[test]
fn coplanar_and_collinear_have_lower_dimension() {
    runner(40)
        .run(&(any::<u64>(), 1usize..60), |(seed, n)| {
            let mut rng = Rng::new(seed);
            // coplanar: integer points in the plane z = x + 2y
            let plane: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let (u, v) = ((rng.next_u64() % 20) as f64, (rng.next_u64() % 20) as f64);
                    [u, v, u + 2.0 * v]
                })
                .collect();
            let tri = check_valid(&plane);
            prop_assert_eq!(tri.num_finite_tets(), 0);
            prop_assert_eq!(tri.dimension(), affine_dim(&plane));
            // collinear
            let line: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let t = (rng.next_u64() % 50) as f64;
                    [1.0 + 2.0 * t, 2.0 - t, 3.0 + 3.0 * t]
                })
                .collect();
            let tri = check_valid(&line);
            prop_assert_eq!(tri.num_finite_tets(), 0);
            prop_assert_eq!(tri.dimension(), affine_dim(&line));
            Ok(())
        })
        .unwrap();
    // a single point, repeated
    let tri = check_valid(&[[1.0, 2.0, 3.0]; 5]);
    assert_eq!(tri.dimension(), 0);
    assert_eq!(tri.num_vertices(), 1);
}

#[test]
fn four_points() {
    runner(60)
        .run(&any::<u64>(), |seed| {
            let pts = points(&mut Rng::new(seed), 4);
            let tri = check_valid(&pts);
            prop_assert_eq!(tri.num_finite_tets(), 1);
            prop_assert_eq!(tri.hull_facets().count(), 4);
            Ok(())
        })
        .unwrap();
}

#[test]
fn extreme_scales_and_offsets() {
    for (scale, offset) in [
        (1e-12, 0.0),
        (1e12, 0.0),
        (1.0, 1e6),
        (1e-3, 1e6),
        (1e-12, 1.0),
    ] {
        // Random points and a grid at that scale and offset.
        let pts: Vec<[f64; 3]> = points(&mut Rng::new(5), 300)
            .iter()
            .map(|p| p.map(|c| offset + scale * c))
            .collect();
        check_valid(&pts);
        let g: Vec<[f64; 3]> = shuffled(grid(5), &mut Rng::new(6))
            .iter()
            .map(|p| p.map(|c| offset + scale * c))
            .collect();
        let tri = check_valid(&g);
        if offset == 0.0 || scale == 1.0 {
            // Exactly representable grid: still 6 tets per cube.
            assert_eq!(
                tri.num_finite_tets(),
                6 * 64,
                "scale {scale} offset {offset}"
            );
        }
    }
}

#[test]
fn result_does_not_depend_on_input_order() {
    // The perturbation depends only on coordinates, so any permutation of
    // the input gives the same tets (this is what makes CGAL's output
    // unique too).
    for (k, base) in [grid(4), points(&mut Rng::new(9), 200)]
        .into_iter()
        .enumerate()
    {
        let tri = check_valid(&base);
        let reference = canonical_sorted(tri.finite_tets_input());
        for s in 0..3 {
            let mut rng = Rng::new(100 * k as u64 + s);
            let mut perm: Vec<usize> = (0..base.len()).collect();
            for i in (1..perm.len()).rev() {
                let j = (rng.next_u64() % (i as u64 + 1)) as usize;
                perm.swap(i, j);
            }
            let pts: Vec<[f64; 3]> = perm.iter().map(|&i| base[i]).collect();
            let t2 = check_valid(&pts);
            let mapped = canonical_sorted(
                t2.finite_tets_input()
                    .map(|t| t.map(|i| perm[i as usize] as u32)),
            );
            assert_eq!(mapped, reference);
        }
    }
}

/// Brute force: a 4-subset is a tet of the perturbed Delaunay triangulation
/// iff it is not flat and no other point is in (perturbed) conflict with it.
fn brute_force(pts: &[[f64; 3]]) -> Vec<[u32; 4]> {
    let n = pts.len();
    let mut out = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            for c in b + 1..n {
                for d in c + 1..n {
                    let mut t = [a, b, c, d];
                    let o = orient3d(&pts[a], &pts[b], &pts[c], &pts[d]);
                    if o == Sign::Zero {
                        continue;
                    }
                    if o == Sign::Negative {
                        t.swap(0, 1);
                    }
                    let empty = (0..n).all(|e| {
                        t.contains(&e)
                            || insphere_perturbed(
                                &pts[t[0]], &pts[t[1]], &pts[t[2]], &pts[t[3]], &pts[e],
                            ) == Sign::Negative
                    });
                    if empty {
                        out.push(t.map(|x| x as u32));
                    }
                }
            }
        }
    }
    canonical_sorted(out)
}

#[test]
fn brute_force_oracle_small_sets() {
    // Generic and degenerate small sets; the oracle shares only the
    // predicates with the engine.
    let mut cases: Vec<Vec<[f64; 3]>> = Vec::new();
    for s in 0..30 {
        cases.push(points(&mut Rng::new(s), 6 + (s as usize % 9)));
    }
    cases.push(grid(2));
    cases.push(shuffled(grid(3)[..14].to_vec(), &mut Rng::new(1)));
    // cocircular square + apexes
    cases.push(vec![
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 2.0, 0.0],
        [2.0, 2.0, 0.0],
        [1.0, 1.0, 1.0],
        [1.0, 1.0, -1.0],
        [1.0, 3.0, 0.5],
    ]);
    // small grid subsets with random integer points
    for s in 0..20 {
        let mut rng = Rng::new(1000 + s);
        let pts: Vec<[f64; 3]> = (0..10)
            .map(|_| {
                [
                    (rng.next_u64() % 3) as f64,
                    (rng.next_u64() % 3) as f64,
                    (rng.next_u64() % 3) as f64,
                ]
            })
            .collect();
        let mut uniq: Vec<[f64; 3]> = Vec::new();
        for p in pts {
            if !uniq.contains(&p) {
                uniq.push(p);
            }
        }
        if affine_dim(&uniq) == 3 {
            cases.push(uniq);
        }
    }
    for pts in &cases {
        let tri = check_valid(pts);
        let ours = canonical_sorted(tri.finite_tets_input());
        assert_eq!(ours, brute_force(pts), "{pts:?}");
    }
}

#[test]
fn coordinates_outside_the_exact_range_are_refused() {
    use aniso_alpha::delaunay::{DelaunayError, COORD_RANGE};
    // Overflow (1e200) or underflow (1e-300) would make the predicates
    // silently inexact: typed error naming the point.
    let mut pts = points(&mut Rng::new(1), 20);
    pts[7][1] = 1e200;
    assert!(matches!(
        Triangulation::new(&pts),
        Err(DelaunayError::OutOfRange {
            index: 7,
            coord: 1,
            ..
        })
    ));
    let tiny: Vec<[f64; 3]> = points(&mut Rng::new(2), 20)
        .iter()
        .map(|p| p.map(|c| c * 1e-300))
        .collect();
    assert!(matches!(
        Triangulation::new(&tiny),
        Err(DelaunayError::OutOfRange { .. })
    ));
    // The ends of the range, and zero, are fine.
    let mut edge = points(&mut Rng::new(3), 20);
    edge[0] = [COORD_RANGE.1, 0.0, 0.0];
    edge[1] = [COORD_RANGE.0, 0.0, -0.0];
    check_valid(&edge);
    let msg = Triangulation::new(&pts).unwrap_err().to_string();
    assert!(msg.contains("point 7") && msg.contains("rescale"), "{msg}");
}

#[test]
fn triangle_and_hull_orientations() {
    use aniso_alpha::delaunay::INFINITE;
    for pts in [
        points(&mut Rng::new(11), 200),
        shuffled(grid(4), &mut Rng::new(12)),
    ] {
        let tri = check_valid(&pts);
        let mut n = 0;
        for t in tri.triangles() {
            let (c, i) = t.sides[0];
            let apex = tri.tet(c)[i];
            let [a, b, d] = t.vertices.map(|v| *tri.point(v));
            if apex != INFINITE {
                // The normal points into sides[0]: towards its apex.
                assert_eq!(orient3d(&a, &b, &d, tri.point(apex)), Sign::Positive);
            }
            n += 1;
        }
        assert_eq!(n, tri.num_triangles());
        // Hull facets face outward: every vertex is on their inner side.
        for f in tri.hull_facets() {
            let [a, b, c] = f.map(|v| *tri.point(v));
            for v in 0..tri.num_vertices() as u32 {
                assert!(orient3d(&a, &b, &c, tri.point(v)) <= Sign::Zero);
            }
        }
    }
}
