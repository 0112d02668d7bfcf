//! End-to-end check of the k = 1 method layer on the synthetic lines scene
//! (Fig. 12), without the Delaunay engine: F_{1,α,Q}(P) is computed by brute
//! force (an edge is exposed when some ball of radius α through its two
//! transformed endpoints is empty of the other transformed points), then
//! the docs/method.md §4 loop runs with the real sampler, path filter, union,
//! component clean-up, labelling and scores.
//!
//! This validates the scale choices of `synth` (step d = 7, background
//! density 0.01 per α-ellipsoid) against the paper's α = 1, λ₃ = 10,
//! nb_c = 4 and the box sampler.

use aniso_alpha::aniso::Anisotropy;
use aniso_alpha::detect::filter::{component_size_mask, components, filter};
use aniso_alpha::detect::orientations::{orientations, Sampler};
use aniso_alpha::detect::parts::{label_points, linear_parts};
use aniso_alpha::detect::StructureKind;
use aniso_alpha::eval::evaluate;
use aniso_alpha::synth::SceneOptions;
use std::collections::{BTreeSet, HashMap};
use std::f64::consts::PI;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// Edges (i < j) of F_{1,α}(q): pairs at distance ≤ 2α having an empty open
/// ball of radius α through both. The centres of such balls form a circle
/// around the midpoint; each other point x excludes the open arc of
/// centres c with |c − x| < α; the edge is exposed when the arcs leave a gap.
fn exposed_edges(q: &[[f64; 3]], alpha: f64) -> Vec<[u32; 2]> {
    let cell = 2.0 * alpha;
    let key = |p: [f64; 3]| {
        (
            (p[0] / cell).floor() as i64,
            (p[1] / cell).floor() as i64,
            (p[2] / cell).floor() as i64,
        )
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
    for (i, &p) in q.iter().enumerate() {
        grid.entry(key(p)).or_default().push(i as u32);
    }
    let near = |p: [f64; 3], r: f64| -> Vec<u32> {
        let (kx, ky, kz) = key(p);
        let mut out = Vec::new();
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(v) = grid.get(&(kx + dx, ky + dy, kz + dz)) {
                        for &j in v {
                            let d = sub(q[j as usize], p);
                            if dot(d, d) <= r * r {
                                out.push(j);
                            }
                        }
                    }
                }
            }
        }
        out
    };
    let mut edges = Vec::new();
    for (i, &p) in q.iter().enumerate() {
        for j in near(p, 2.0 * alpha) {
            if j as usize <= i {
                continue;
            }
            let r = q[j as usize];
            let pr = sub(r, p);
            let len2 = dot(pr, pr);
            let m = [
                (p[0] + r[0]) / 2.0,
                (p[1] + r[1]) / 2.0,
                (p[2] + r[2]) / 2.0,
            ];
            let rho2 = alpha * alpha - len2 / 4.0;
            if rho2 < 0.0 {
                continue;
            }
            let rho = rho2.sqrt();
            let w = unit(pr);
            let a0 = if w[0].abs() < 0.6 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            let e1 = unit(cross(w, a0));
            let e2 = cross(w, e1);
            // Excluded open arcs (start, length) in [0, 2π).
            let mut arcs: Vec<(f64, f64)> = Vec::new();
            let mut blocked = false;
            for k in near(m, 2.0 * alpha) {
                if k as usize == i || k == j {
                    continue;
                }
                let d = sub(m, q[k as usize]);
                let (a, b) = (dot(d, e1), dot(d, e2));
                let rab = (a * a + b * b).sqrt();
                let c0 = dot(d, d) + rho2 - alpha * alpha; // |c−x|² − α² = c0 + 2ρ·rab·cos(t−φ)
                if rho * rab == 0.0 {
                    if c0 < 0.0 {
                        blocked = true;
                        break;
                    }
                    continue;
                }
                let kappa = -c0 / (2.0 * rho * rab); // inside ⟺ cos(t − φ) < κ
                if kappa > 1.0 {
                    blocked = true;
                    break;
                }
                if kappa <= -1.0 {
                    continue;
                }
                let half = kappa.acos(); // inside for t − φ ∈ (half, 2π − half)
                let phi = b.atan2(a);
                let start = (phi + half).rem_euclid(2.0 * PI);
                arcs.push((start, 2.0 * PI - 2.0 * half));
            }
            if blocked || !arcs_leave_gap(&mut arcs) {
                continue;
            }
            edges.push([i as u32, j]);
        }
    }
    edges
}

/// Whether the union of open arcs misses some point of the circle.
fn arcs_leave_gap(arcs: &mut [(f64, f64)]) -> bool {
    if arcs.is_empty() {
        return true;
    }
    arcs.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Unroll onto [s0, s0 + 2π): the first arc starts at s0.
    let s0 = arcs[0].0;
    let mut reach = s0 + arcs[0].1;
    for &(s, l) in arcs.iter().skip(1) {
        if s >= reach {
            return true; // a gap (a closed endpoint at least) before s
        }
        reach = reach.max(s + l);
    }
    reach <= s0 + 2.0 * PI
}

#[test]
fn arcs() {
    assert!(arcs_leave_gap(&mut [(0.0, 1.0), (2.0, 1.0)]));
    assert!(!arcs_leave_gap(&mut [(0.0, 4.0), (3.0, 4.0)]));
    assert!(arcs_leave_gap(&mut [(0.0, 3.0), (3.5, 2.0)]));
    assert!(!arcs_leave_gap(&mut [(6.0, 3.0), (2.0, 4.5)]));
}

pub(crate) fn run_lines(seed: u64, density: f64) -> (f64, usize, usize) {
    run_lines_with(seed, density, &Sampler::default())
}

pub(crate) fn run_lines_with(seed: u64, density: f64, sampler: &Sampler) -> (f64, usize, usize) {
    run_scene(
        SceneOptions::lines()
            .seed(seed)
            .background_per_ellipsoid(density),
        sampler,
        false,
    )
}

/// Runs the k = 1 loop; with `split`, structures are the straight parts
/// (10°) of the kept edges instead of their components.
fn run_scene(opts: SceneOptions, sampler: &Sampler, split: bool) -> (f64, usize, usize) {
    let scene = opts.generate().unwrap();
    let p = opts.paper_params();
    let rotations = orientations(StructureKind::Lines, sampler, false).unwrap();
    let mut union: BTreeSet<[u32; 2]> = BTreeSet::new();
    for r in &rotations {
        let a = Anisotropy::from_matrix_rows(*r, [1.0, 1.0, 1.0 / p.lambda3]).unwrap();
        let q = a.transform(&scene.points);
        let f = exposed_edges(&q, p.alpha);
        union.extend(filter(&f, p.nb_c).unwrap());
    }
    let union: Vec<[u32; 2]> = union.into_iter().collect();
    let keep = component_size_mask(&union, p.nb_c).unwrap();
    let kept: Vec<[u32; 2]> = union
        .iter()
        .zip(&keep)
        .filter_map(|(e, &k)| k.then_some(*e))
        .collect();
    let comp = if split {
        linear_parts(&scene.points, &kept, 10.0).unwrap()
    } else {
        components(&kept).unwrap()
    };
    let n_comp = comp.iter().copied().max().map_or(0, |m| m as usize + 1);
    let mut size = vec![0usize; n_comp];
    for &c in &comp {
        size[c as usize] += 1;
    }
    // Label: the largest structure containing the point.
    let mut label = vec![-1i64; scene.points.len()];
    let mut best = vec![0usize; scene.points.len()];
    for (e, &c) in kept.iter().zip(&comp) {
        for &v in e {
            if size[c as usize] > best[v as usize] {
                best[v as usize] = size[c as usize];
                label[v as usize] = i64::from(c);
            }
        }
    }
    let ev = evaluate(&scene.labels, None, &label, None).unwrap();
    eprintln!(
        "lines (split {split}): {} union edges, {} kept\n{ev}",
        union.len(),
        kept.len()
    );
    (ev.f1, ev.structures_found, ev.structures_total)
}

#[test]
fn lines_scene_is_detected_at_paper_parameters() {
    let mut f1s = Vec::new();
    for seed in 1..=3 {
        let (f1, found, total) = run_lines(seed, 0.01);
        f1s.push(f1);
        assert!(found * 5 >= total * 4, "seed {seed}: {found}/{total}");
    }
    let mean = f1s.iter().sum::<f64>() / f1s.len() as f64;
    eprintln!("mean F1 {mean:.3} over {f1s:?}");
    assert!(mean > 0.8, "{f1s:?}");
}

#[test]
fn crossing_lines_are_split_into_two() {
    let opts = SceneOptions::lines().crossing(true).seed(2);
    let (f1, found, total) = run_scene(opts.clone(), &Sampler::default(), true);
    assert_eq!(total, 5);
    assert!(found >= 4, "{found}/{total}");
    assert!(f1 > 0.8, "{f1}");
    // The labelling helper agrees with the hand-written one above.
    let scene = opts.generate().unwrap();
    let edges = [[0u32, 1], [1, 2]];
    assert_eq!(
        label_points(scene.points.len(), &edges, &[0, 0]).unwrap()[..3],
        [0, 0, 0]
    );
}

/// The engine's anisotropic α-shape (Delaunay of Q·P, exact intervals,
/// pruning) equals the brute-force "some empty ellipsoid touches the edge"
/// on the lines scene, orientation by orientation.
#[test]
fn detector_orientation_faces_equal_brute_force() {
    use aniso_alpha::detect::Detector;
    let opts = SceneOptions::lines().seed(3);
    let scene = opts.generate().unwrap();
    let p = opts.paper_params();
    let det = Detector::lines(p.alpha, p.lambda3, p.nb_c);
    let rotations = orientations(StructureKind::Lines, &Sampler::default(), false).unwrap();
    let mut compared = 0;
    for r in rotations.iter().step_by(9) {
        let a = Anisotropy::from_matrix_rows(*r, det.elongation()).unwrap();
        let mut brute = exposed_edges(&a.transform(&scene.points), p.alpha);
        brute.sort_unstable();
        let ours: Vec<[u32; 2]> = det
            .orientation_faces(&scene.points, r)
            .unwrap()
            .iter()
            .map(|f| [f[0], f[1]])
            .collect();
        assert_eq!(ours, brute);
        compared += ours.len();
    }
    assert!(compared > 100, "{compared} edges compared");
}
