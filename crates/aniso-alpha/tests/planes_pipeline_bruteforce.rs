//! End-to-end check of the k = 2 method layer on the synthetic planes
//! (Fig. 5) and polyhedron (Fig. 10) scenes, without the Delaunay engine:
//! F_{2,α,Q}(P) is computed by brute force (a triangle of circumradius
//! R ≤ α is exposed when one of the two balls of radius α through its
//! transformed vertices, centred at circumcentre ± √(α² − R²)·normal, is
//! empty of the other transformed points). Then the docs/method.md §4 loop runs with
//! the box sampler (1,944 orientations), the path filter per orientation,
//! the union, the component clean-up, labelling and scores.

use aniso_alpha::aniso::Anisotropy;
use aniso_alpha::detect::filter::{component_size_mask, components, filter};
use aniso_alpha::detect::orientations::{orientations, Sampler};
use aniso_alpha::detect::parts::{label_points, planar_parts};
use aniso_alpha::detect::StructureKind;
use aniso_alpha::eval::{evaluate, Evaluation};
use aniso_alpha::synth::SceneOptions;
use std::collections::{BTreeSet, HashMap};

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

/// Triangles (i < j < k) of F_{2,α}(q), brute force with a grid.
fn exposed_triangles(q: &[[f64; 3]], alpha: f64) -> Vec<[u32; 3]> {
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
    let mut tris = Vec::new();
    for (i, &a) in q.iter().enumerate() {
        let mut nb: Vec<u32> = near(a, 2.0 * alpha)
            .into_iter()
            .filter(|&j| j as usize > i)
            .collect();
        nb.sort_unstable();
        if nb.len() < 2 {
            continue;
        }
        // Every point that can be inside a ball through a is within 2α of a.
        let ball_candidates = near(a, 2.0 * alpha);
        for (x, &j) in nb.iter().enumerate() {
            for &k in &nb[x + 1..] {
                let (b, c) = (q[j as usize], q[k as usize]);
                let (u, v) = (sub(b, a), sub(c, a));
                if dot(sub(c, b), sub(c, b)) > 4.0 * alpha * alpha {
                    continue;
                }
                let n = cross(u, v);
                let n2 = dot(n, n);
                if n2 == 0.0 {
                    continue;
                }
                // Circumcentre a + ((|u|²v − |v|²u) × n) / (2|n|²).
                let (uu, vv) = (dot(u, u), dot(v, v));
                let w = [
                    uu * v[0] - vv * u[0],
                    uu * v[1] - vv * u[1],
                    uu * v[2] - vv * u[2],
                ];
                let t = cross(w, n);
                let off = [t[0] / (2.0 * n2), t[1] / (2.0 * n2), t[2] / (2.0 * n2)];
                let r2 = dot(off, off);
                if r2 > alpha * alpha {
                    continue;
                }
                let cc = [a[0] + off[0], a[1] + off[1], a[2] + off[2]];
                let h = (alpha * alpha - r2).sqrt() / n2.sqrt();
                let exposed = [1.0, -1.0].iter().any(|&s| {
                    let c0 = [
                        cc[0] + s * h * n[0],
                        cc[1] + s * h * n[1],
                        cc[2] + s * h * n[2],
                    ];
                    ball_candidates.iter().all(|&m| {
                        if m as usize == i || m == j || m == k {
                            return true;
                        }
                        let d = sub(q[m as usize], c0);
                        dot(d, d) >= alpha * alpha
                    })
                });
                if exposed {
                    tris.push([i as u32, j, k]);
                }
            }
        }
    }
    tris
}

pub(crate) fn run(opts: SceneOptions, name: &str) -> Evaluation {
    run_with(opts, name, &Sampler::default(), false)
}

pub(crate) fn run_with(opts: SceneOptions, name: &str, sampler: &Sampler, l23: bool) -> Evaluation {
    let opts_crossing = name.contains("crossing");
    let scene = opts.generate().unwrap();
    let p = opts.paper_params();
    let e = [1.0, 1.0 / p.lambda2, 1.0 / p.lambda3];
    let rotations = orientations(StructureKind::Planes, sampler, l23).unwrap();
    let mut union: BTreeSet<[u32; 3]> = BTreeSet::new();
    for r in &rotations {
        let a = Anisotropy::from_matrix_rows(*r, e).unwrap();
        let q = a.transform(&scene.points);
        let f = exposed_triangles(&q, p.alpha);
        union.extend(filter(&f, p.nb_c).unwrap());
    }
    let union: Vec<[u32; 3]> = union.into_iter().collect();
    let keep = component_size_mask(&union, p.nb_c).unwrap();
    let kept: Vec<[u32; 3]> = union
        .iter()
        .zip(&keep)
        .filter_map(|(t, &k)| k.then_some(*t))
        .collect();
    let comp = components(&kept).unwrap();
    let n_comp = comp.iter().copied().max().map_or(0, |m| m as usize + 1);
    let mut size = vec![0usize; n_comp];
    for &c in &comp {
        size[c as usize] += 1;
    }
    let mut label = vec![-1i64; scene.points.len()];
    let mut best = vec![0usize; scene.points.len()];
    for (t, &c) in kept.iter().zip(&comp) {
        for &v in t {
            if size[c as usize] > best[v as usize] {
                best[v as usize] = size[c as usize];
                label[v as usize] = i64::from(c);
            }
        }
    }
    // Facets: planar parts of the kept triangles (10°), each point labelled
    // with its largest part.
    let part_ids = planar_parts(&scene.points, &kept, 10.0).unwrap();
    let part_label = label_points(scene.points.len(), &kept, &part_ids).unwrap();
    let ev = evaluate(&scene.labels, Some(&scene.parts), &label, Some(&part_label)).unwrap();
    if opts_crossing {
        // Crossing planes: the planar parts are the structures.
        let ev2 = evaluate(&scene.labels, None, &part_label, None).unwrap();
        eprintln!("{name}, parts as structures:\n{ev2}");
        return ev2;
    }
    eprintln!(
        "{name}: {} union triangles, {} kept in {n_comp} components\n{ev}",
        union.len(),
        kept.len()
    );
    ev
}

#[test]
fn planes_scene_is_detected_at_paper_parameters() {
    let ev = run(SceneOptions::planes().seed(1), "planes seed 1");
    assert_eq!(ev.structures_found, 3);
    assert!(ev.f1 > 0.8, "{}", ev.f1);
}

#[test]
fn polyhedron_scene_is_detected_at_paper_parameters() {
    let ev = run(SceneOptions::polyhedron().seed(1), "polyhedron seed 1");
    assert_eq!(ev.structures_found, 1);
    assert!(ev.f1 > 0.8, "{}", ev.f1);
    assert_eq!(ev.parts_found, 5, "facets as planar parts");
}

#[test]
fn crossing_planes_are_split_into_two() {
    let ev = run(
        SceneOptions::planes().crossing(true).seed(1),
        "planes crossing seed 1",
    );
    assert_eq!(ev.structures_found, 3);
}

/// The engine's anisotropic α-shape (Delaunay of Q·P, exact intervals,
/// pruning) equals the brute-force "some empty ellipsoid touches the
/// triangle" on the polyhedron scene, orientation by orientation.
#[test]
fn detector_orientation_faces_equal_brute_force() {
    use aniso_alpha::detect::Detector;
    let opts = SceneOptions::polyhedron().seed(2);
    let scene = opts.generate().unwrap();
    let p = opts.paper_params();
    let det = Detector::planes(p.alpha, p.lambda2, p.lambda3, p.nb_c);
    let rotations = orientations(StructureKind::Planes, &Sampler::default(), false).unwrap();
    let mut compared = 0;
    for r in rotations.iter().step_by(97) {
        let a = Anisotropy::from_matrix_rows(*r, det.elongation()).unwrap();
        let mut brute = exposed_triangles(&a.transform(&scene.points), p.alpha);
        brute.sort_unstable();
        let ours: Vec<[u32; 3]> = det
            .orientation_faces(&scene.points, r)
            .unwrap()
            .iter()
            .map(|f| [f[0], f[1], f[2]])
            .collect();
        assert_eq!(ours, brute);
        compared += ours.len();
    }
    assert!(compared > 100, "{compared} triangles compared");
}
