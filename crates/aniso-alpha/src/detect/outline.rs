//! Outlines and clean meshes of planar parts: the 2D α-shape of a part's
//! points projected on its plane.
//!
//! The points are projected on the plane's two in-plane axes, triangulated
//! in 2D (Delaunay, `spade`'s exact predicates), and the triangles whose
//! circumradius is at most `r` are kept: the part's mesh (one planar
//! triangulation, so it is a clean 2-manifold with boundary, unlike the
//! union of the scanned α-shapes). Its boundary edges (edges of exactly one
//! kept triangle) are chained into closed loops; the loop enclosing the
//! largest area is the outline, oriented counter-clockwise seen from the
//! plane's normal (a concave, L-shaped part keeps its notch: this is not a
//! convex hull).
//!
//! `r` is the in-plane reach of the ellipsoid (α·λ): two points of the part
//! closer than 2r along the plane are joined, as the anisotropic α-shape
//! joins them.

use super::fit::PlaneFit;
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

#[derive(Clone, Copy)]
struct V {
    p: Point2<f64>,
    id: u32,
}

impl HasPosition for V {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.p
    }
}

/// The 2D α-shape of a planar part: its triangles (over the given point
/// indices) and its outline (points on the plane).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outline {
    /// Kept triangles, over input point indices, each counter-clockwise
    /// seen from the normal.
    pub triangles: Vec<[u32; 3]>,
    /// The outer boundary loop, counter-clockwise seen from the normal.
    pub polygon: Vec<[f64; 3]>,
}

/// Doublings of the radius tried before the convex hull, for a part with no
/// triangle at its own radius (`outline`).
const OUTLINE_DOUBLINGS: usize = 6;

fn circumradius2(a: Point2<f64>, b: Point2<f64>, c: Point2<f64>) -> f64 {
    let (bx, by) = (b.x - a.x, b.y - a.y);
    let (cx, cy) = (c.x - a.x, c.y - a.y);
    let d = 2.0 * (bx * cy - by * cx);
    if d == 0.0 {
        return f64::INFINITY;
    }
    let b2 = bx * bx + by * by;
    let c2 = cx * cx + cy * cy;
    let ux = (cy * b2 - by * c2) / d;
    let uy = (bx * c2 - cx * b2) / d;
    ux * ux + uy * uy
}

/// The 2D α-shape of `points[ids[..]]` on `plane` with radius `r` (module
/// doc). Points projecting onto one 2D position are merged (the first
/// index is kept).
pub fn outline(points: &[[f64; 3]], ids: &[u32], plane: &PlaneFit, r: f64) -> Outline {
    let [a0, a1] = plane.axes;
    let c = plane.centroid;
    let uv = |p: &[f64; 3]| -> Point2<f64> {
        let w = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        Point2::new(
            w[0] * a0[0] + w[1] * a0[1] + w[2] * a0[2],
            w[0] * a1[0] + w[1] * a1[1] + w[2] * a1[2],
        )
    };
    let mut verts: Vec<V> = Vec::with_capacity(ids.len());
    verts.extend(
        ids.iter()
            .map(|&i| V {
                p: uv(&points[i as usize]),
                id: i,
            })
            .filter(|v| v.p.x.is_finite() && v.p.y.is_finite()),
    );
    // Merge equal 2D positions (keep the smallest index).
    verts.sort_by(|a, b| {
        (a.p.x, a.p.y, a.id)
            .partial_cmp(&(b.p.x, b.p.y, b.id))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    verts.dedup_by(|b, a| a.p == b.p);
    if verts.len() < 3 {
        return Outline::default();
    }
    let Ok(tri) = DelaunayTriangulation::<V>::bulk_load(verts) else {
        return Outline::default();
    };
    // Kept triangles (spade's faces are counter-clockwise in (u, v), and
    // (a0, a1, normal) is right-handed, so they are counter-clockwise seen
    // from the normal). A part too sparse for radius r (a strip one or two
    // points wide, claimed along a fitted plane) has no triangle at r: the
    // radius doubles until one is kept, up to the convex hull (r = ∞), so
    // every planar part of three non-collinear points has an outline.
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(tri.num_inner_faces());
    // Per face index of the triangulation: kept.
    let mut kept = vec![false; tri.num_all_faces()];
    let mut r2 = r * r;
    for attempt in 0..=OUTLINE_DOUBLINGS {
        if attempt == OUTLINE_DOUBLINGS {
            r2 = f64::INFINITY;
        }
        for f in tri.inner_faces() {
            let [a, b, cc] = f.vertices();
            let (pa, pb, pc) = (a.data().p, b.data().p, cc.data().p);
            if circumradius2(pa, pb, pc) <= r2 {
                kept[f.fix().index()] = true;
                triangles.push([a.data().id, b.data().id, cc.data().id]);
            }
        }
        if !triangles.is_empty() {
            break;
        }
        r2 *= 4.0;
    }
    triangles.sort_unstable();
    // Boundary: the directed edges of kept triangles whose other side is
    // not kept (another face or the outer one), read off the
    // triangulation's topology in one pass; with the position of their
    // first vertex. Sorted, they are few (the outline's length).
    let mut edges: Vec<(u32, u32, Point2<f64>)> = Vec::new();
    for f in tri.inner_faces().filter(|f| kept[f.fix().index()]) {
        for e in f.adjacent_edges() {
            let other = e.rev().face();
            if !other.as_inner().is_some_and(|g| kept[g.fix().index()]) {
                edges.push((e.from().data().id, e.to().data().id, e.from().data().p));
            }
        }
    }
    edges.sort_unstable_by_key(|e| (e.0, e.1));
    let at = |v: u32| -> Point2<f64> {
        let k = edges.partition_point(|e| e.0 < v);
        edges[k].2
    };
    let boundary: Vec<(u32, u32)> = edges.iter().map(|e| (e.0, e.1)).collect();
    // Chain into loops: each boundary vertex may start several edges (a
    // pinch); take them in order and mark used.
    let mut used = vec![false; boundary.len()];
    let start_of = |v: u32| boundary.partition_point(|e| e.0 < v);
    let mut best: (f64, Vec<u32>) = (0.0, Vec::new());
    for e0 in 0..boundary.len() {
        if used[e0] {
            continue;
        }
        let mut loop_v = Vec::new();
        let mut e = e0;
        loop {
            used[e] = true;
            let (a, b) = boundary[e];
            loop_v.push(a);
            // Next edge starting at b, unused.
            let mut k = start_of(b);
            let mut next = None;
            while k < boundary.len() && boundary[k].0 == b {
                if !used[k] {
                    next = Some(k);
                    break;
                }
                k += 1;
            }
            match next {
                Some(k) => e = k,
                None => break,
            }
        }
        // Shoelace area (positive for counter-clockwise).
        let mut area = 0.0;
        for i in 0..loop_v.len() {
            let (p, q) = (at(loop_v[i]), at(loop_v[(i + 1) % loop_v.len()]));
            area += p.x * q.y - q.x * p.y;
        }
        area *= 0.5;
        if area > best.0 {
            best = (area, loop_v);
        }
    }
    let polygon = best
        .1
        .iter()
        .map(|&v| {
            let p = at(v);
            [0, 1, 2].map(|k| c[k] + p.x * a0[k] + p.y * a1[k])
        })
        .collect();
    Outline { triangles, polygon }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::fit::fit_plane_indices;

    fn area(poly: &[[f64; 3]]) -> f64 {
        // Area of a polygon in the plane z = const.
        let mut a = 0.0;
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            a += p[0] * q[1] - q[0] * p[1];
        }
        0.5 * a
    }

    /// The outline by brute force from the kept triangles: directed edges
    /// whose reverse is no kept triangle's, chained from the smallest
    /// (from, to) in order, the loop of largest area (the first on ties).
    fn brute_outline(points: &[[f64; 3]], o: &Outline) -> Vec<[f64; 3]> {
        let mut edges: Vec<(u32, u32)> = o
            .triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .collect();
        edges.sort_unstable();
        let boundary: Vec<(u32, u32)> = edges
            .iter()
            .copied()
            .filter(|&(a, b)| edges.binary_search(&(b, a)).is_err())
            .collect();
        let mut used = vec![false; boundary.len()];
        let mut best: (f64, Vec<u32>) = (0.0, Vec::new());
        for e0 in 0..boundary.len() {
            if used[e0] {
                continue;
            }
            let (mut lp, mut e) = (Vec::new(), e0);
            loop {
                used[e] = true;
                lp.push(boundary[e].0);
                let b = boundary[e].1;
                match (0..boundary.len()).find(|&k| !used[k] && boundary[k].0 == b) {
                    Some(k) => e = k,
                    None => break,
                }
            }
            let poly: Vec<[f64; 3]> = lp.iter().map(|&v| points[v as usize]).collect();
            let a = area(&poly);
            if a > best.0 {
                best = (a, lp);
            }
        }
        best.1.iter().map(|&v| points[v as usize]).collect()
    }

    #[test]
    fn outline_equals_the_brute_force_boundary() {
        // Random points on z = 0 with holes (a disc and a strip left
        // empty), at several radii: the outline read off the
        // triangulation's topology is the brute-force loop, vertex for
        // vertex (the plane's axes may turn the coordinates, so compare
        // in 2D up to rounding).
        let mut rng = crate::rng::SplitMix64::new(40);
        for (n, r) in [(300, 0.6), (2000, 0.3), (2000, 0.15), (5000, 0.1)] {
            let mut pts = Vec::new();
            while pts.len() < n {
                let (x, y) = (10.0 * rng.uniform(), 10.0 * rng.uniform());
                let hole = (x - 3.0).powi(2) + (y - 3.0).powi(2) < 2.0 || (6.0..6.5).contains(&x);
                if !hole {
                    pts.push([x, y, 0.0]);
                }
            }
            let ids: Vec<u32> = (0..pts.len() as u32).collect();
            let plane = fit_plane_indices(&pts, &ids).unwrap();
            let o = outline(&pts, &ids, &plane, r);
            let want = brute_outline(&pts, &o);
            assert!(want.len() >= 3);
            assert_eq!(o.polygon.len(), want.len(), "n {n} r {r}");
            for (p, q) in o.polygon.iter().zip(&want) {
                assert!((p[0] - q[0]).abs() < 1e-9 && (p[1] - q[1]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn l_shaped_part_keeps_its_notch() {
        // An L: a 20 × 20 grid minus its 10 × 10 upper-right quarter.
        let mut pts = Vec::new();
        for i in 0..=20 {
            for j in 0..=20 {
                if !(i > 10 && j > 10) {
                    pts.push([i as f64, j as f64, 3.0]);
                }
            }
        }
        let ids: Vec<u32> = (0..pts.len() as u32).collect();
        let plane = fit_plane_indices(&pts, &ids).unwrap();
        let o = outline(&pts, &ids, &plane, 1.0);
        // 300 unit squares, 2 triangles each, and the half square at the
        // inner corner (10, 10), (11, 10), (10, 11), whose circumradius is
        // 0.71.
        assert_eq!(o.triangles.len(), 601);
        let a = area(&o.polygon).abs();
        assert!((a - 300.5).abs() < 1e-6, "area {a}");
        // The convex hull would have area 400: the notch is there.
        assert!(o.polygon.iter().all(|p| (p[2] - 3.0).abs() < 1e-9));
        // A radius too small for any triangle (0.5 < 0.71) is doubled
        // until triangles are kept: here at 1, the same shape.
        assert_eq!(outline(&pts, &ids, &plane, 0.5), o);
    }

    #[test]
    fn sparse_strip_still_has_an_outline() {
        // Two rows 10 apart, points 1 apart along them: no triangle has a
        // circumradius under 5, so at radius 1 the α-shape is empty and the
        // doubling (2, 4, 8) gives the strip between the rows.
        let mut pts = Vec::new();
        for i in 0..=20 {
            pts.push([i as f64, 0.0, 1.0]);
            pts.push([i as f64 + 0.5, 10.0, 1.0]);
        }
        let ids: Vec<u32> = (0..pts.len() as u32).collect();
        let plane = fit_plane_indices(&pts, &ids).unwrap();
        let o = outline(&pts, &ids, &plane, 1.0);
        assert!(!o.triangles.is_empty());
        assert!(o.polygon.len() >= 4);
        let a = area(&o.polygon).abs();
        assert!(a > 150.0 && a <= 20.5 * 10.0 + 1e-9, "area {a}");
        // Fewer than three points have no outline.
        assert_eq!(outline(&pts, &ids[..2], &plane, 1.0), Outline::default());
    }

    #[test]
    fn mesh_is_manifold_and_outline_is_the_largest_loop() {
        // Two squares far apart: the outline is the bigger one.
        let mut pts = Vec::new();
        for i in 0..=10 {
            for j in 0..=10 {
                pts.push([i as f64, j as f64, 0.0]);
            }
        }
        for i in 0..=3 {
            for j in 0..=3 {
                pts.push([100.0 + i as f64, j as f64, 0.0]);
            }
        }
        let ids: Vec<u32> = (0..pts.len() as u32).collect();
        let plane = fit_plane_indices(&pts, &ids).unwrap();
        let o = outline(&pts, &ids, &plane, 1.0);
        assert!((area(&o.polygon).abs() - 100.0).abs() < 1e-6);
        // Every undirected edge in at most two triangles.
        let mut e: Vec<(u32, u32)> = o
            .triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[0], t[2])])
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        e.sort_unstable();
        let mut i = 0;
        while i < e.len() {
            let j = e[i..].iter().take_while(|x| **x == e[i]).count();
            assert!(j <= 2);
            i += j;
        }
    }
}
