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

/// Points of a part from which its 2D α-shape is cut into strips
/// ([`strips_of`]): 2^16 (one strip per [`STRIP_POINTS`] besides). A
/// depth frame's table (79,000 points) or a tiling's ground was one
/// triangulation on one thread while the other parts were long done. At
/// 2^15, the simulated room's parts of 30,000–52,000 points, outlined in
/// parallel with each other already, were cut too, for nothing on two
/// threads (train scans, "Peaks of the claims, the parts and the
/// outlines" in BENCHMARKS.md); on the 20 train scans 2^15 left the peaks
/// and wall times as they were (medians of three, 2 threads: peak ratio
/// 1.00, wall 0.99), so the lower bound, which lowered two held-out depth
/// frames' peaks, is not taken.
#[cfg(not(test))]
const STRIPPED_POINTS: usize = 1 << 16;
/// A few hundred points in the tests, so that small parts take the path.
#[cfg(test)]
const STRIPPED_POINTS: usize = 1 << 9;

/// Points in one strip of a large part, besides its halo: 2^14.
#[cfg(not(test))]
const STRIP_POINTS: usize = 1 << 14;
/// A hundred-odd points in the tests.
#[cfg(test)]
const STRIP_POINTS: usize = 1 << 7;

/// The halo of a strip, in radii: 4 (3 would do, module doc of
/// [`strips_of`]; the fourth covers the rounding of circumcentres).
const HALO_RADII: f64 = 4.0;

/// A strip of a large part's projected points (sorted by x): its core,
/// the x range whose triangles it owns (a triangle by its circumcentre),
/// and the range of points it triangulates (the core and a halo).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Strip {
    core: (f64, f64),
    points: (usize, usize),
}

impl Strip {
    /// All `n` points, owning every triangle: one triangulation.
    fn whole(n: usize) -> Self {
        Strip {
            core: (f64::NEG_INFINITY, f64::INFINITY),
            points: (0, n),
        }
    }

    /// Whether this is [`Strip::whole`]'s strip.
    fn is_whole(&self) -> bool {
        self.core == (f64::NEG_INFINITY, f64::INFINITY)
    }
}

/// The 2D α-shape of `points[ids[..]]` on `plane` with radius `r` (module
/// doc). Points projecting onto one 2D position are merged (the first
/// index is kept). A large part is triangulated in strips on the pool's
/// threads ([`strips_of`]), with the same result as one triangulation.
pub fn outline(points: &[[f64; 3]], ids: &[u32], plane: &PlaneFit, r: f64) -> Outline {
    let [a0, a1] = plane.axes;
    let c = plane.centroid;
    let verts = projected(points, ids, plane);
    if verts.len() < 3 {
        return Outline::default();
    }
    let strips = strips_of(&verts, r);
    let Some((mut triangles, mut edges)) = kept_in_strips(&verts, &strips, r) else {
        return Outline::default();
    };
    crate::par::sort_unstable(&mut triangles);
    edges.sort_unstable_by_key(|e| (e.0, e.1));
    let polygon = largest_loop(&edges)
        .iter()
        .map(|p| [0, 1, 2].map(|k| c[k] + p.x * a0[k] + p.y * a1[k]))
        .collect();
    Outline { triangles, polygon }
}

/// The points `ids` on the plane's axes, sorted by (x, y, index), those
/// at one 2D position merged into the first (the smallest index), the
/// non-finite left out.
fn projected(points: &[[f64; 3]], ids: &[u32], plane: &PlaneFit) -> Vec<V> {
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
    verts.sort_by(|a, b| {
        (a.p.x, a.p.y, a.id)
            .partial_cmp(&(b.p.x, b.p.y, b.id))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    verts.dedup_by(|b, a| a.p == b.p);
    verts
}

/// The strips of `verts` (sorted by x) for radius `r`: one below
/// [`STRIPPED_POINTS`]; otherwise cores of about [`STRIP_POINTS`] points
/// cut at points' x, each triangulated with the points within
/// [`HALO_RADII`]·r of it in x, and no narrower than two halos.
///
/// Why the strips give the α-shape of one triangulation: a triangle with
/// circumradius ρ ≤ r whose circumcentre lies in a core has its disc
/// within r of the core in x, so the strip holds every point that could
/// lie in the disc: the triangle is Delaunay in the strip exactly when it
/// is in the whole part. A neighbour across one of its edges with ρ ≤ r
/// has its centre within 2r of the core and its disc within 3r, so
/// whether that neighbour is kept, which makes the edge a boundary edge or
/// not, is read in the strip as well. (In general position; where four
/// points are cocircular, the two triangulations may cut their circle
/// along different diagonals, two triangles of one circumradius either
/// way.)
fn strips_of(verts: &[V], r: f64) -> Vec<Strip> {
    let n = verts.len();
    let whole = Strip::whole(n);
    let halo = HALO_RADII * r;
    let extent = verts[n - 1].p.x - verts[0].p.x;
    if n < STRIPPED_POINTS || !halo.is_finite() || halo <= 0.0 {
        return vec![whole];
    }
    let by_count = n.div_ceil(STRIP_POINTS);
    let by_width = (extent / (2.0 * halo)).floor();
    let m = if by_width < by_count as f64 {
        by_width as usize
    } else {
        by_count
    };
    if m < 2 {
        return vec![whole];
    }
    let mut cuts: Vec<f64> = (1..m).map(|k| verts[k * n / m].p.x).collect();
    cuts.dedup();
    let mut bounds = vec![f64::NEG_INFINITY];
    bounds.extend(cuts);
    bounds.push(f64::INFINITY);
    bounds
        .windows(2)
        .map(|w| {
            let from = verts.partition_point(|v| v.p.x < w[0] - halo);
            let to = verts.partition_point(|v| v.p.x < w[1] + halo);
            Strip {
                core: (w[0], w[1]),
                points: (from, to),
            }
        })
        .collect()
}

/// A boundary edge of the kept triangles: (from, to, position of from),
/// counter-clockwise around the kept region.
type Edge = (u32, u32, Point2<f64>);

/// The kept triangles of each strip and their boundary edges
/// ([`kept_in_strip`]), strips on the pool's threads, joined; `None`
/// where fewer than three points remain. A part too sparse for radius r
/// (a strip one or two points wide, claimed along a fitted plane) has no
/// triangle at r: then the radius doubles, in one triangulation, until
/// one is kept, up to the convex hull (r = ∞), so that every planar part
/// of three non-collinear points has an outline.
fn kept_in_strips(verts: &[V], strips: &[Strip], r: f64) -> Option<(Vec<[u32; 3]>, Vec<Edge>)> {
    // r, 2r, 4r, … 32r, then ∞.
    let ladder: Vec<f64> = (0..=OUTLINE_DOUBLINGS)
        .map(|k| match k {
            OUTLINE_DOUBLINGS => f64::INFINITY,
            _ => r * r * 4f64.powi(k as i32),
        })
        .collect();
    let whole = Strip::whole(verts.len());
    if strips.len() < 2 {
        return kept_in_strip(verts, whole, &ladder);
    }
    let pieces = crate::par::map_each(strips.len(), |k| {
        kept_in_strip(verts, strips[k], &ladder[..1])
    });
    let mut triangles = Vec::with_capacity(pieces.iter().flatten().map(|p| p.0.len()).sum());
    let mut edges = Vec::new();
    for (t, e) in pieces.into_iter().flatten() {
        triangles.extend(t);
        edges.extend(e);
    }
    if triangles.is_empty() {
        return kept_in_strip(verts, whole, &ladder[1..]);
    }
    Some((triangles, edges))
}

/// The triangles of `strip`'s triangulation with circumradius² at most
/// the first of `r2s` that keeps any, whose circumcentre lies in its core,
/// each from its smallest index, counter-clockwise in (u, v) (spade's
/// order; (a0, a1, normal) is right-handed, so counter-clockwise seen from
/// the normal); and their edges whose other side is no kept triangle
/// (another face, or the outer one), read off the triangulation's
/// topology. `None` for fewer than three points.
fn kept_in_strip(verts: &[V], strip: Strip, r2s: &[f64]) -> Option<(Vec<[u32; 3]>, Vec<Edge>)> {
    let mine = &verts[strip.points.0..strip.points.1];
    if mine.len() < 3 {
        return None;
    }
    let tri = DelaunayTriangulation::<V>::bulk_load(mine.to_vec()).ok()?;
    let whole = strip.is_whole();
    let core = strip.core.0..strip.core.1;
    // Per face index of the triangulation: kept, and (in a strip's core,
    // or anywhere for the whole part) owned.
    let mut kept = vec![false; tri.num_all_faces()];
    let mut owned = Vec::new();
    let mut triangles: Vec<[u32; 3]> =
        Vec::with_capacity(if whole { tri.num_inner_faces() } else { 0 });
    for &r2 in r2s {
        for f in tri.inner_faces() {
            let t = from_smallest(f.vertices().map(|v| *v.data()));
            let (rho2, centre_x) = circle(t);
            if rho2 <= r2 {
                kept[f.fix().index()] = true;
                if whole {
                    triangles.push(t.map(|v| v.id));
                } else if core.contains(&centre_x) {
                    triangles.push(t.map(|v| v.id));
                    owned.push(f.fix());
                }
            }
        }
        if !triangles.is_empty() {
            break;
        }
    }
    let mut edges: Vec<Edge> = Vec::new();
    let mut boundary_of =
        |f: spade::handles::FaceHandle<'_, spade::handles::InnerTag, V, (), (), ()>| {
            for e in f.adjacent_edges() {
                let other = e.rev().face();
                if !other.as_inner().is_some_and(|g| kept[g.fix().index()]) {
                    edges.push((e.from().data().id, e.to().data().id, e.from().data().p));
                }
            }
        };
    if whole {
        for f in tri.inner_faces().filter(|f| kept[f.fix().index()]) {
            boundary_of(f);
        }
    } else {
        for f in owned {
            boundary_of(tri.face(f));
        }
    }
    Some((triangles, edges))
}

/// The triangle `t` (counter-clockwise) turned to start at its smallest
/// index, still counter-clockwise: the same numbers for a triangle
/// whichever strip, and whichever of its vertices, spade gives it from.
fn from_smallest([a, b, c]: [V; 3]) -> [V; 3] {
    if a.id < b.id && a.id < c.id {
        [a, b, c]
    } else if b.id < c.id {
        [b, c, a]
    } else {
        [c, a, b]
    }
}

/// The squared circumradius of a triangle and the x of its circumcentre
/// (both ∞ for a degenerate triangle).
fn circle(t: [V; 3]) -> (f64, f64) {
    let [a, b, c] = t.map(|v| v.p);
    let (bx, by) = (b.x - a.x, b.y - a.y);
    let (cx, cy) = (c.x - a.x, c.y - a.y);
    let d = 2.0 * (bx * cy - by * cx);
    if d == 0.0 {
        return (f64::INFINITY, f64::INFINITY);
    }
    let b2 = bx * bx + by * by;
    let c2 = cx * cx + cy * cy;
    let (ux, uy) = ((cy * b2 - by * c2) / d, (bx * c2 - cx * b2) / d);
    (ux * ux + uy * uy, a.x + ux)
}

/// The boundary loop of largest area (counter-clockwise) among the
/// boundary `edges` (sorted by (from, to)), as the positions of its
/// vertices: each boundary vertex may start several edges (a pinch),
/// taken in order and marked used.
fn largest_loop(edges: &[Edge]) -> Vec<Point2<f64>> {
    let at = |v: u32| -> Point2<f64> {
        let k = edges.partition_point(|e| e.0 < v);
        edges[k].2
    };
    let boundary: Vec<(u32, u32)> = edges.iter().map(|e| (e.0, e.1)).collect();
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
    best.1.iter().map(|&v| at(v)).collect()
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
    fn strips_give_the_triangles_and_boundary_of_one_triangulation() {
        // Random points (general position) with a hole, cut into strips
        // at several radii: the kept triangles and the boundary edges
        // equal those of one triangulation. Strips without their halo do
        // not: the comparison can fail.
        let mut rng = crate::rng::SplitMix64::new(41);
        for (n, r) in [(700, 0.3), (3000, 0.2), (3000, 0.08), (6000, 0.05)] {
            let mut pts = Vec::new();
            while pts.len() < n {
                let (x, y) = (10.0 * rng.uniform(), 4.0 * rng.uniform());
                if (x - 5.0).powi(2) + (y - 2.0).powi(2) > 1.0 {
                    pts.push([x, y, 0.5 * x]);
                }
            }
            let ids: Vec<u32> = (0..pts.len() as u32).collect();
            let plane = fit_plane_indices(&pts, &ids).unwrap();
            let verts = projected(&pts, &ids, &plane);
            let strips = strips_of(&verts, r);
            assert!(strips.len() >= 3, "n {n} r {r}: {} strips", strips.len());
            let whole = [Strip::whole(verts.len())];
            let sorted = |strips: &[Strip]| {
                let (mut t, mut e) = kept_in_strips(&verts, strips, r).unwrap();
                t.sort_unstable();
                e.sort_unstable_by_key(|e| (e.0, e.1));
                (t, e.iter().map(|e| (e.0, e.1)).collect::<Vec<_>>())
            };
            let want = sorted(&whole);
            assert!(want.0.len() > n / 10, "n {n} r {r}: {}", want.0.len());
            assert_eq!(sorted(&strips), want, "n {n} r {r}");
            let bare: Vec<Strip> = strips
                .iter()
                .map(|s| {
                    let from = verts.partition_point(|v| v.p.x < s.core.0);
                    let to = verts.partition_point(|v| v.p.x < s.core.1);
                    Strip {
                        core: s.core,
                        points: (from, to),
                    }
                })
                .collect();
            assert_ne!(sorted(&bare), want, "n {n} r {r}");
        }
    }

    #[test]
    fn a_wide_halo_leaves_one_strip() {
        // Strips no narrower than two halos: at a radius near the
        // part's width, one triangulation.
        let pts: Vec<[f64; 3]> = (0..2000)
            .map(|k| [f64::from(k % 50), f64::from(k / 50), 0.0])
            .collect();
        let ids: Vec<u32> = (0..pts.len() as u32).collect();
        let plane = fit_plane_indices(&pts, &ids).unwrap();
        let verts = projected(&pts, &ids, &plane);
        assert!(strips_of(&verts, 1.0).len() > 2);
        assert_eq!(strips_of(&verts, 10.0).len(), 1);
        assert_eq!(strips_of(&verts[..100], 1.0).len(), 1);
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
