//! Tests of the scene generators.

use super::*;
use crate::aniso::Anisotropy;
use crate::detect::fit::{fit_line, fit_plane};
use crate::detect::orientations::{orientations, Sampler};
use crate::detect::StructureKind;
use crate::io::{write_xyz_labels, write_xyz_labels_parts};

fn members(scene: &Scene, label: i64) -> Vec<[f64; 3]> {
    scene
        .points
        .iter()
        .zip(&scene.labels)
        .filter(|&(_, &l)| l == label)
        .map(|(p, _)| *p)
        .collect()
}

fn nearest_neighbour_mean(p: &[[f64; 3]]) -> f64 {
    let mut sum = 0.0;
    for (i, a) in p.iter().enumerate() {
        let mut best = f64::INFINITY;
        for (j, b) in p.iter().enumerate() {
            if i != j {
                best = best.min(dist2(*a, *b));
            }
        }
        sum += best.sqrt();
    }
    sum / p.len() as f64
}

#[test]
fn rng_is_deterministic_and_sane() {
    let mut a = Rng::new(42);
    let xs: Vec<u64> = (0..4).map(|_| a.next_u64()).collect();
    let mut b = Rng::new(42);
    assert_eq!(xs, (0..4).map(|_| b.next_u64()).collect::<Vec<_>>());
    assert_ne!(Rng::new(43).next_u64(), xs[0]);
    let mut r = Rng::new(1);
    let n = 200_000;
    let (mut m, mut v) = (0.0, 0.0);
    for _ in 0..n {
        let g = r.gaussian();
        m += g;
        v += g * g;
    }
    m /= n as f64;
    v = v / n as f64 - m * m;
    assert!(m.abs() < 0.01 && (v - 1.0).abs() < 0.01, "{m} {v}");
    let mut counts = [0u32; 7];
    for _ in 0..70_000 {
        counts[r.below(7) as usize] += 1;
    }
    assert!(
        counts.iter().all(|&c| (9_500..10_500).contains(&c)),
        "{counts:?}"
    );
    let u = r.unit_vector();
    assert!((dot(u, u) - 1.0).abs() < 1e-12);
}

#[test]
fn lines_scene() {
    let opts = SceneOptions::lines().seed(5);
    let s = opts.generate().unwrap();
    assert_eq!(s, opts.generate().unwrap(), "deterministic");
    assert_ne!(s, SceneOptions::lines().seed(6).generate().unwrap());
    assert_eq!(s.points.len(), 1550);
    assert_eq!(s.num_structures(), 5);
    assert!(s.parts.iter().all(|&p| p == -1));
    let side = opts.box_side();
    assert!((side - 184.5).abs() < 0.5, "{side}");
    assert!(s
        .points
        .iter()
        .all(|p| p.iter().all(|&x| (0.0..=side).contains(&x))));
    for l in 0..5 {
        let m = members(&s, l);
        assert_eq!(m.len(), 10);
        let f = fit_line(&m).unwrap();
        assert!(f.rms_residual < 1e-9);
        assert!((f.extent - 63.0).abs() < 1e-9);
        // Regular step d = 7.
        let mut t: Vec<f64> = m
            .iter()
            .map(|p| {
                dot(
                    [
                        p[0] - f.centroid[0],
                        p[1] - f.centroid[1],
                        p[2] - f.centroid[2],
                    ],
                    f.direction,
                )
            })
            .collect();
        t.sort_by(f64::total_cmp);
        assert!(t.windows(2).all(|w| (w[1] - w[0] - 7.0).abs() < 1e-9));
        // Clearance from the other lines.
        for o in 0..l {
            for p in &m {
                for q in members(&s, o) {
                    assert!(dist2(*p, q) >= 400.0 - 1e-9);
                }
            }
        }
    }
    // docs/method.md §5: background nearest-neighbour distance ≳ 1.25 d.
    let nn = nearest_neighbour_mean(&members(&s, -1));
    assert!(nn > 1.15 * 7.0 && nn < 1.45 * 7.0, "{nn}");
}

#[test]
fn lines_fit_the_box_orientations() {
    // Observation 3 under the box sampler: every line's consecutive step
    // maps, in its best orientation, to a segment of half-length ≤ 0.76 α.
    let a = orientations(StructureKind::Lines, &Sampler::default(), false).unwrap();
    let mut worst = 0.0f64;
    for seed in 0..10 {
        let s = SceneOptions::lines().seed(seed).generate().unwrap();
        for l in 0..5 {
            let f = fit_line(&members(&s, l)).unwrap();
            let step = [
                7.0 * f.direction[0],
                7.0 * f.direction[1],
                7.0 * f.direction[2],
            ];
            let best = a
                .iter()
                .map(|r| {
                    let q = Anisotropy::from_matrix_rows(*r, [1.0, 1.0, 0.1]).unwrap();
                    let v = q.transform_point(step);
                    dot(v, v).sqrt() / 2.0
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(best);
            assert!(best <= 0.76, "seed {seed} line {l}: {best}");
        }
    }
    eprintln!("worst best-orientation half-step over the lines: {worst:.3}");
}

fn circumradius(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let la = dist2(b, c).sqrt();
    let lb = dist2(a, c).sqrt();
    let lc = dist2(a, b).sqrt();
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let area2 = dot(cross(u, v), cross(u, v)).sqrt();
    la * lb * lc / (2.0 * area2)
}

#[test]
fn planes_scene() {
    let opts = SceneOptions::planes().seed(9);
    let s = opts.generate().unwrap();
    assert_eq!(s.points.len(), 270);
    assert_eq!(s.num_structures(), 3);
    assert!((opts.box_side() - 126.2).abs() < 0.5, "{}", opts.box_side());
    for l in 0..3 {
        let m = members(&s, l);
        assert_eq!(m.len(), 40);
        let f = fit_plane(&m).unwrap();
        assert!(f.rms_residual < 1e-9);
        assert!((f.extent[0] - 21.0).abs() < 1e-9 && (f.extent[1] - 12.0).abs() < 1e-9);
    }
}

#[test]
fn plane_triangles_fit_the_box_orientations() {
    // Observation 4 under the box sampler: for every plane, some
    // orientation maps each grid cell to two triangles (better diagonal) of
    // circumradius ≤ 0.7 α.
    let a = orientations(StructureKind::Planes, &Sampler::default(), false).unwrap();
    let mut worst = 0.0f64;
    for seed in 0..4 {
        let s = SceneOptions::planes().seed(seed).generate().unwrap();
        for l in 0..3 {
            let f = fit_plane(&members(&s, l)).unwrap();
            let (u, v) = (f.axes[0], f.axes[1]);
            let h = 3.0;
            let cell = [
                [0.0; 3],
                [h * u[0], h * u[1], h * u[2]],
                [h * (u[0] + v[0]), h * (u[1] + v[1]), h * (u[2] + v[2])],
                [h * v[0], h * v[1], h * v[2]],
            ];
            let best = a
                .iter()
                .map(|r| {
                    let q = Anisotropy::from_matrix_rows(*r, [1.0, 0.25, 0.125]).unwrap();
                    let c = q.transform(&cell);
                    let d1 = circumradius(c[0], c[1], c[2]).max(circumradius(c[0], c[2], c[3]));
                    let d2 = circumradius(c[0], c[1], c[3]).max(circumradius(c[1], c[2], c[3]));
                    d1.min(d2)
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(best);
            assert!(best <= 0.7, "seed {seed} plane {l}: {best}");
        }
    }
    eprintln!("worst best-orientation circumradius over the planes: {worst:.3}");
}

#[test]
fn polyhedron_scene() {
    let s = SceneOptions::polyhedron().seed(2).generate().unwrap();
    assert_eq!(s.points.len(), 990);
    assert_eq!(s.num_structures(), 1);
    let m = members(&s, 0);
    assert_eq!(m.len(), 190);
    let mut normals = Vec::new();
    let counts = [70, 40, 40, 20, 20];
    for part in 0..5 {
        let pts: Vec<[f64; 3]> = s
            .points
            .iter()
            .zip(&s.parts)
            .filter(|&(_, &q)| q == part)
            .map(|(p, _)| *p)
            .collect();
        assert_eq!(pts.len(), counts[part as usize], "part {part}");
        let f = fit_plane(&pts).unwrap();
        assert!(f.rms_residual < 1e-9);
        normals.push(f.normal);
    }
    // Top ⟂ walls; opposite walls parallel.
    for w in 1..5 {
        assert!(dot(normals[0], normals[w]).abs() < 1e-9);
    }
    assert!((dot(normals[1], normals[2]).abs() - 1.0).abs() < 1e-9);
    assert!(dot(normals[1], normals[3]).abs() < 1e-9);
    assert!(s
        .parts
        .iter()
        .zip(&s.labels)
        .all(|(&p, &l)| (p >= 0) == (l >= 0)));
}

#[test]
fn crossing_and_options() {
    let s = SceneOptions::lines()
        .crossing(true)
        .seed(4)
        .generate()
        .unwrap();
    let (l0, l1) = (members(&s, 0), members(&s, 1));
    assert_eq!(l0.len() + l1.len(), 19, "the shared point is counted once");
    let (f0, f1) = (fit_line(&l0).unwrap(), fit_line(&l1).unwrap());
    assert!(dot(f0.direction, f1.direction).abs() <= (PI / 4.0).cos() + 1e-9);
    // Line 1 passes through a point of line 0.
    let through = l0.iter().any(|p| {
        let q = [
            p[0] - f1.centroid[0],
            p[1] - f1.centroid[1],
            p[2] - f1.centroid[2],
        ];
        let t = dot(q, f1.direction);
        dot(q, q) - t * t < 1e-9
    });
    assert!(through);

    let s = SceneOptions::planes()
        .crossing(true)
        .seed(4)
        .generate()
        .unwrap();
    let (p0, p1) = (members(&s, 0), members(&s, 1));
    let (f0, f1) = (fit_plane(&p0).unwrap(), fit_plane(&p1).unwrap());
    let off = [
        f1.centroid[0] - f0.centroid[0],
        f1.centroid[1] - f0.centroid[1],
        f1.centroid[2] - f0.centroid[2],
    ];
    assert!(dot(off, off) < 1e-18, "same centre");
    assert!(dot(f0.normal, f1.normal).abs() <= (PI / 4.0).cos() + 1e-9);

    let s = SceneOptions::lines()
        .jitter(0.1)
        .random_sampling(true)
        .structures(2)
        .background(10)
        .seed(1)
        .generate()
        .unwrap();
    assert_eq!(s.points.len(), 30);
    let f = fit_line(&members(&s, 0)).unwrap();
    assert!(
        f.rms_residual > 0.05 && f.rms_residual < 0.3,
        "{}",
        f.rms_residual
    );
    let s = SceneOptions::polyhedron()
        .random_sampling(true)
        .background(0)
        .seed(1)
        .generate()
        .unwrap();
    assert_eq!(s.points.len(), 190);

    assert!(matches!(
        SceneOptions::lines().jitter(-1.0).generate(),
        Err(SynthError::BadOption { .. })
    ));
    assert!(matches!(
        SceneOptions::lines().spacing(f64::NAN).generate(),
        Err(SynthError::BadOption { .. })
    ));
    assert!(matches!(
        SceneOptions::lines()
            .structures(1)
            .crossing(true)
            .generate(),
        Err(SynthError::BadOption { .. })
    ));
    assert!(matches!(
        SceneOptions::lines()
            .structures(60)
            .background(100)
            .generate(),
        Err(SynthError::CannotPlace)
    ));
    assert_eq!(lines(3), SceneOptions::lines().seed(3).generate().unwrap());
    assert_eq!(planes(3).points.len(), 270);
    assert_eq!(polyhedron(3).points.len(), 990);
}

#[test]
fn write_format() {
    let s = SceneOptions::polyhedron()
        .background(5)
        .seed(8)
        .generate()
        .unwrap();
    let mut out = Vec::new();
    write_xyz_labels(&s, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    let rows: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows.len(), s.points.len());
    for (row, (p, l)) in rows.iter().zip(s.points.iter().zip(&s.labels)) {
        let f: Vec<&str> = row.split(' ').collect();
        assert_eq!(f.len(), 4);
        for k in 0..3 {
            assert_eq!(f[k].parse::<f64>().unwrap().to_bits(), p[k].to_bits());
        }
        assert_eq!(f[3].parse::<i64>().unwrap(), *l);
    }
    let mut out = Vec::new();
    write_xyz_labels_parts(&s, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    let last = text.lines().last().unwrap();
    assert_eq!(last.split(' ').count(), 5);
}
