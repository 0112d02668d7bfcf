//! `F_{k,α}` at one α, straight from a triangulation.
//!
//! The detector needs the edges or triangles of `F_α` for a single α per
//! orientation, not every interval. With SPEC §1's definitions, for a
//! simplex σ with smallest-circumsphere radius ρ(σ):
//!
//! * `α_min(σ) ≥ ρ(σ)` always (every sphere through σ is at least that
//!   large), so σ with `ρ(σ) > α` is out at once;
//! * `α_max(σ)` is the largest circumradius of the incident tets (∞ on the
//!   hull), so σ with `α > α_max` is out;
//! * a triangle with an incident tet of circumradius `≤ α` has
//!   `α_min ≤ α` whether or not it is Gabriel, so the exact Gabriel test is
//!   only needed when `ρ ≤ α <` the smallest incident circumradius.
//!
//! This is the same membership as [`crate::alpha::AlphaComplex`]'s
//! `edges_at` / `triangles_at`, bit for bit (same radius arithmetic, exact
//! Gabriel predicates; checked in tests at every critical value), for far
//! less work: most exact Gabriel tests are skipped.

use crate::alpha::exact::{edge_diametral_side, tet_radius2, triangle_diametral_side};
use crate::alpha::triangle_rho_sorted;
use crate::delaunay::{Triangulation, INFINITE};

/// Circumradius of every cell (`+∞` for infinite cells), with the same
/// arithmetic as [`crate::alpha::AlphaComplex`].
fn cell_radii(tri: &Triangulation) -> Vec<f64> {
    let pts = tri.points();
    (0..tri.num_tets() as u32)
        .map(|t| {
            let v = tri.tet(t);
            if v[3] == INFINITE {
                f64::INFINITY
            } else {
                let p = |k: usize| &pts[v[k] as usize];
                tet_radius2([p(0), p(1), p(2), p(3)]).sqrt()
            }
        })
        .collect()
}

/// Whether the triangle `f` (vertex ids) is Gabriel with respect to the
/// apexes of its two cells ([`INFINITE`] for none): exact.
fn triangle_gabriel(tri: &Triangulation, f: [u32; 3], apexes: [u32; 2]) -> bool {
    let [a, b, c] = f.map(|w| tri.point(w));
    apexes
        .iter()
        .filter(|&&w| w != INFINITE)
        .all(|&w| !triangle_diametral_side(a, b, c, tri.point(w)).is_negative())
}

use crate::delaunay::FACE;

/// Whether a triangle with these sides (tet, face) is in F_α. `r` are
/// the tets' circumradii. Radii and the Gabriel test are computed exactly as
/// in [`crate::alpha::AlphaComplex`], so membership agrees even at the
/// interval endpoints.
fn triangle_in(tri: &Triangulation, r: &[f64], sides: [(u32, usize); 2], alpha: f64) -> bool {
    let (t, i) = sides[0];
    let (n, j) = sides[1];
    let (r0, r1) = (r[t as usize], r[n as usize]);
    let amax = r0.max(r1); // ∞ if one side is infinite
    if alpha > amax {
        return false;
    }
    let v = tri.tet(t);
    let f = FACE[i].map(|k| v[k]);
    if triangle_rho_sorted(tri.points(), f) > alpha {
        return false;
    }
    r0.min(r1) <= alpha || triangle_gabriel(tri, f, [v[i], tri.tet(n)[j]])
}

/// The triangles of `F_{2,α}`: input-index triples, ascending within each.
pub fn triangles_at(tri: &Triangulation, alpha: f64) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    if tri.dimension() < 3 {
        return out;
    }
    let r = cell_radii(tri);
    for t in tri.triangles() {
        if triangle_in(tri, &r, t.sides, alpha) {
            let mut f = t.vertices.map(|w| tri.input_index(w));
            f.sort_unstable();
            out.push(f);
        }
    }
    out
}

/// The edges of `F_{1,α}`: input-index pairs, ascending within each.
pub fn edges_at(tri: &Triangulation, alpha: f64) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    if tri.dimension() < 3 {
        return out;
    }
    let r = cell_radii(tri);
    let mut ring: Vec<u32> = Vec::new();
    for e in tri.edges() {
        let [a, b] = e.vertices;
        let (pa, pb) = (tri.point(a), tri.point(b));
        let d = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
        let rho = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if rho > alpha {
            continue;
        }
        ring.clear();
        ring.extend(tri.edge_ring(&e));
        let amax = ring.iter().map(|&t| r[t as usize]).fold(0.0, f64::max);
        if alpha > amax {
            continue;
        }
        // Gabriel: no vertex of an incident tet strictly inside the
        // diametral sphere.
        let gabriel = ring.iter().all(|&t| {
            tri.tet(t)
                .iter()
                .filter(|&&w| w != a && w != b && w != INFINITE)
                .all(|&w| !edge_diametral_side(pa, pb, tri.point(w)).is_negative())
        });
        let inside = gabriel || {
            // α_min = min over incident triangles of their α_min: the
            // triangle between consecutive ring tets.
            (0..ring.len()).any(|k| {
                let t = ring[k];
                let n = ring[(k + 1) % ring.len()];
                let v = tri.tet(t);
                // The face of t shared with n: opposite the vertex of t not
                // in n.
                let Some(i) = (0..4).find(|&i| {
                    tri.neighbor(t, i).0 == n && {
                        let o = v[i];
                        o != a && o != b
                    }
                }) else {
                    return false;
                };
                let (nn, j) = tri.neighbor(t, i);
                if FACE[i].iter().any(|&k| v[k] == INFINITE) {
                    return false;
                }
                // α_min(triangle) ≤ α: an incident tet of radius ≤ α, or
                // Gabriel with ρ ≤ α (then `triangle_in`'s α_max condition
                // holds too: α < both radii here).
                let (r0, r1) = (r[t as usize], r[nn as usize]);
                if r0.min(r1) <= alpha {
                    return true;
                }
                // The face as seen from the smaller tet id, as the interval
                // complex numbers it (the rounding of ρ depends on the order).
                let sides = if t < nn {
                    [(t, i), (nn, j)]
                } else {
                    [(nn, j), (t, i)]
                };
                triangle_in(tri, &r, sides, alpha)
            })
        };
        if inside {
            let mut s = [tri.input_index(a), tri.input_index(b)];
            s.sort_unstable();
            out.push(s);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::alpha::AlphaComplex;

    fn rnd_points(seed: u64, n: usize, grid: bool) -> Vec<[f64; 3]> {
        let mut s = seed;
        let mut next = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                if grid {
                    [
                        (next() * 5.0).floor(),
                        (next() * 5.0).floor(),
                        (next() * 3.0).floor(),
                    ]
                } else {
                    [next() * 4.0, next() * 4.0, next() * 0.5]
                }
            })
            .collect()
    }

    #[test]
    fn same_as_the_interval_complex() {
        for seed in 0..20u64 {
            let pts = rnd_points(seed, 20 + 5 * seed as usize, seed % 3 == 0);
            let tri = Triangulation::new(&pts).unwrap();
            let ac = AlphaComplex::new(tri.clone());
            let mut spectrum = ac.spectrum();
            spectrum.extend(spectrum.clone().windows(2).map(|w| 0.5 * (w[0] + w[1])));
            for &alpha in spectrum.iter().step_by(3) {
                let mut a: Vec<[u32; 3]> = ac.triangles_at(alpha).collect();
                a.sort_unstable();
                let mut b = triangles_at(&tri, alpha);
                b.sort_unstable();
                assert_eq!(a, b, "triangles, seed {seed}, alpha {alpha}");
                let mut a: Vec<[u32; 2]> = ac.edges_at(alpha).collect();
                a.sort_unstable();
                let mut b = edges_at(&tri, alpha);
                b.sort_unstable();
                assert_eq!(a, b, "edges, seed {seed}, alpha {alpha}");
            }
        }
    }
}
