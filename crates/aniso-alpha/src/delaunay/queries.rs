//! Read-only queries: triangles, edges with their rings, hull facets,
//! vertex stars, circumspheres.

use super::cell::{EDGES, FACE};
use super::{Triangulation, INFINITE};
use crate::geometry::circum;
use crate::geometry::Point3;

/// A finite triangle of the triangulation with the two tetrahedra on its
/// sides (one of them infinite on the convex hull).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Triangle {
    /// The three vertex ids, ordered so that the triangle's normal (right-
    /// hand rule) points into the tetrahedron `sides[0].0` (towards its
    /// fourth vertex; outward from the hull when that tet is infinite).
    pub vertices: [u32; 3],
    /// `(tet, local face index)` on each side; `sides[0].0 < sides[1].0`.
    pub sides: [(u32, usize); 2],
}

/// A finite edge with one incident tetrahedron and the local indices of the
/// edge's endpoints in it; [`Triangulation::edge_ring`] walks around it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    /// The two vertex ids, smaller first.
    pub vertices: [u32; 2],
    /// A tetrahedron incident to the edge.
    pub tet: u32,
    /// Local indices in `tet` of `vertices[0]` and `vertices[1]`.
    pub local: [usize; 2],
}

impl Triangulation {
    /// Every finite triangle once, with the tetrahedra on both sides.
    pub fn triangles(&self) -> impl Iterator<Item = Triangle> + '_ {
        (0..self.cells.len() as u32).flat_map(move |t| {
            let v = self.cells[t as usize].v;
            let finite = !self.is_infinite(t);
            (0..4).filter_map(move |i| {
                if !finite && v[i] != INFINITE {
                    return None;
                }
                let (n, j) = self.neighbor(t, i);
                if n < t {
                    return None;
                }
                let f = FACE[i];
                Some(Triangle {
                    vertices: [v[f[0]], v[f[1]], v[f[2]]],
                    sides: [(t, i), (n, j)],
                })
            })
        })
    }

    /// Number of finite triangles.
    pub fn num_triangles(&self) -> usize {
        // Each tet has 4 faces, each face is shared by 2 tets; the faces
        // incident to the infinite vertex are 3 per infinite tet.
        (4 * self.cells.len() - 3 * (self.cells.len() - self.num_finite)) / 2
    }

    /// The tetrahedra around the edge `(t.local[0], t.local[1])`, in
    /// rotational order, starting with `e.tet` (infinite ones included when
    /// the edge is on the hull).
    pub fn edge_ring(&self, e: &Edge) -> EdgeRing<'_> {
        EdgeRing {
            tri: self,
            a: e.vertices[0],
            b: e.vertices[1],
            start: e.tet,
            cur: e.tet,
            cross: other_two(e.local[0], e.local[1])[0],
            done: false,
        }
    }

    /// Every finite edge once. Each is reported by the tetrahedron with the
    /// smallest id in its ring.
    pub fn edges(&self) -> impl Iterator<Item = Edge> + '_ {
        (0..self.cells.len() as u32).flat_map(move |t| {
            let v = self.cells[t as usize].v;
            EDGES.iter().filter_map(move |&[i, j]| {
                if v[i] == INFINITE || v[j] == INFINITE {
                    return None;
                }
                let (i, j) = if v[i] < v[j] { (i, j) } else { (j, i) };
                let e = Edge {
                    vertices: [v[i], v[j]],
                    tet: t,
                    local: [i, j],
                };
                if self.edge_ring(&e).all(|u| u >= t) {
                    Some(e)
                } else {
                    None
                }
            })
        })
    }

    /// The convex hull's facets as vertex triples oriented outward
    /// (counter-clockwise seen from outside).
    pub fn hull_facets(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.cells
            .iter()
            .filter(|c| c.v[3] == INFINITE)
            .map(|c| [c.v[0], c.v[1], c.v[2]])
    }

    /// All tetrahedra incident to vertex `v` (infinite ones included for a
    /// hull vertex). Empty when the dimension is below 3.
    pub fn vertex_tets(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        let start = self.vert_tet.get(v as usize).copied().unwrap_or(u32::MAX);
        if start == u32::MAX {
            return out;
        }
        out.push(start);
        let mut k = 0;
        while k < out.len() {
            let t = out[k];
            k += 1;
            let tv = self.cells[t as usize].v;
            for i in 0..4 {
                if tv[i] == v {
                    continue;
                }
                let (n, _) = self.neighbor(t, i);
                if !out.contains(&n) {
                    out.push(n);
                }
            }
        }
        out
    }

    /// Circumcentre and circumradius of finite tetrahedron `t`.
    pub fn tet_circumsphere(&self, t: u32) -> (Point3, f64) {
        let v = self.cells[t as usize].v;
        circum::tet_circumsphere(
            self.point(v[0]),
            self.point(v[1]),
            self.point(v[2]),
            self.point(v[3]),
        )
    }

    /// Circumcentre and radius of the smallest circumsphere of a triangle.
    pub fn triangle_circumsphere(&self, v: [u32; 3]) -> (Point3, f64) {
        circum::tri_circumsphere(self.point(v[0]), self.point(v[1]), self.point(v[2]))
    }

    /// Midpoint and half-length of an edge.
    pub fn edge_circumsphere(&self, v: [u32; 2]) -> (Point3, f64) {
        circum::edge_circumsphere(self.point(v[0]), self.point(v[1]))
    }
}

#[inline]
fn other_two(i: usize, j: usize) -> [usize; 2] {
    let mut o = [0; 2];
    let mut k = 0;
    for x in 0..4 {
        if x != i && x != j {
            o[k] = x;
            k += 1;
        }
    }
    o
}

/// Iterator over the tetrahedra around an edge; see
/// [`Triangulation::edge_ring`].
#[derive(Clone, Debug)]
pub struct EdgeRing<'a> {
    tri: &'a Triangulation,
    a: u32,
    b: u32,
    start: u32,
    cur: u32,
    cross: usize,
    done: bool,
}

impl Iterator for EdgeRing<'_> {
    type Item = u32;
    fn next(&mut self) -> Option<u32> {
        if self.done {
            return None;
        }
        let out = self.cur;
        let (n, m) = self.tri.neighbor(self.cur, self.cross);
        if n == self.start {
            self.done = true;
        } else {
            let nv = self.tri.cells[n as usize].v;
            let ia = nv.iter().position(|&w| w == self.a).unwrap_or(0);
            let ib = nv.iter().position(|&w| w == self.b).unwrap_or(0);
            self.cur = n;
            self.cross = 6 - ia - ib - m;
        }
        Some(out)
    }
}
