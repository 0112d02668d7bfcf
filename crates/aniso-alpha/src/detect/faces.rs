//! `F_{k,α}` at one α, straight from a triangulation.
//!
//! The detector needs the edges or triangles of `F_α` for a single α per
//! orientation, not every interval. With docs/method.md §1's definitions, for a
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
use crate::geometry::{cross, cross_permanent, dot, sub};

/// Relative error bound used to certify the side of α on which a cell's
/// circumradius lies from its plain floating-point evaluation: 1e-12 of
/// the permanents, four orders of magnitude above the rounding of the
/// differences, products and sums involved (under 10ε ≈ 2.2e-15).
const CERTIFY: f64 = 1e-12;

/// The circumradius of a cell, or a value on the same side of α as it
/// (strictly), when the floating-point evaluation with its error bound
/// certifies the side; the careful radius of [`crate::alpha::AlphaComplex`]
/// otherwise. Membership only compares radii with α (`r ≤ α`, `α > r`),
/// so it is the same either way; the exact fallback, which flat slivers
/// (everywhere in a flattened scan) needed nearly always, is left for the
/// cells whose radius is within the bound of α.
fn cell_radius(p: [&[f64; 3]; 4], alpha: f64) -> f64 {
    let [a, b, c, d] = p;
    let (u, v, w) = (sub(*b, *a), sub(*c, *a), sub(*d, *a));
    let (cvw, cwu, cuv) = (cross(v, w), cross(w, u), cross(u, v));
    let (pvw, pwu, puv) = (
        cross_permanent(v, w),
        cross_permanent(w, u),
        cross_permanent(u, v),
    );
    let (uu, vv, ww) = (dot(u, u), dot(v, v), dot(w, w));
    let det = dot(u, cvw);
    let pdet = u[0].abs() * pvw[0] + u[1].abs() * pvw[1] + u[2].abs() * pvw[2];
    let n: [f64; 3] = std::array::from_fn(|k| uu * cvw[k] + vv * cwu[k] + ww * cuv[k]);
    let pn: [f64; 3] = std::array::from_fn(|k| uu * pvw[k] + vv * pwu[k] + ww * puv[k]);
    let nn = dot(n, n).sqrt();
    let dn = CERTIFY * dot(pn, pn).sqrt();
    let dd = CERTIFY * pdet;
    let a2 = alpha * alpha;
    if nn.is_finite() && pdet.is_finite() && pdet > 0.0 {
        // Lower and upper bounds of r² = |n|² / (4 det²).
        let lo = (nn - dn).max(0.0).powi(2) / (4.0 * (det.abs() + dd).powi(2));
        if lo > a2 {
            return lo.sqrt();
        }
        if det.abs() > dd {
            let hi = (nn + dn).powi(2) / (4.0 * (det.abs() - dd).powi(2));
            if hi < a2 {
                return hi.sqrt();
            }
        }
    }
    // A flat sliver of nearly collinear points (every cell of a line
    // mapped by Q) leaves both |n| and det at the level of their rounding:
    // no bound above. But the cell's circumsphere holds each face's
    // circumcircle, so r ≥ R_face = |e1|·|e2|·|e3| / (2·|e1 × e2|), and
    // for such a face |e1 × e2| is tiny even with its error bound: the
    // cell is certified out of F_α without the exact radius (whose
    // expansion arithmetic takes 60% of a detection of lines on exactly
    // collinear points).
    let lo = [(b, c), (c, d), (d, b)]
        .iter()
        .map(|&(x, y)| circumradius_lower(a, x, y))
        .fold(0.0, f64::max);
    if lo > alpha && lo.is_finite() {
        return lo;
    }
    tet_radius2(p).sqrt()
}

/// A lower bound of the circumradius |ab|·|bc|·|ca| / (2·|(b − a) × (c − a)|)
/// of the triangle `abc`, certified by the same relative margin
/// [`CERTIFY`] (on the lengths below, on the cross product above, with its
/// permanent): 0 when the bound says nothing. Nearly collinear triangles,
/// whose exact ρ needs expansion arithmetic, get a bound far above any α.
fn circumradius_lower(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
    let (u, v, e) = (sub(*b, *a), sub(*c, *a), sub(*c, *b));
    let (n, perm) = (cross(u, v), cross_permanent(u, v));
    let lengths = (dot(u, u) * dot(v, v) * dot(e, e)).sqrt() * (1.0 - CERTIFY);
    let cross = dot(n, n).sqrt() + CERTIFY * dot(perm, perm).sqrt();
    let r = lengths / (2.0 * cross);
    if r.is_finite() {
        r
    } else {
        0.0
    }
}

/// Circumradius of every cell (`+∞` for infinite cells), or a value on the
/// same side of α ([`cell_radius`]).
fn cell_radii(tri: &Triangulation, alpha: f64) -> Vec<f64> {
    let pts = tri.points();
    (0..tri.num_tets() as u32)
        .map(|t| {
            let v = tri.tet(t);
            if v[3] == INFINITE {
                f64::INFINITY
            } else {
                let p = |k: usize| &pts[v[k] as usize];
                cell_radius([p(0), p(1), p(2), p(3)], alpha)
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
    let [a, b, c] = f.map(|w| tri.point(w));
    if circumradius_lower(a, b, c) > alpha || triangle_rho_sorted(tri.points(), f) > alpha {
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
    let r = cell_radii(tri, alpha);
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
    edges_at_levels(tri, &[alpha]).pop().unwrap_or_default()
}

/// [`edges_at`] at each α of `alphas`, in one pass over the edges: an
/// edge's ring of tets and its Gabriel test do not depend on α.
pub(crate) fn edges_at_levels(tri: &Triangulation, alphas: &[f64]) -> Vec<Vec<[u32; 2]>> {
    let mut out = vec![Vec::new(); alphas.len()];
    if tri.dimension() < 3 {
        return out;
    }
    let top = alphas.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let radii: Vec<Vec<f64>> = alphas.iter().map(|&a| cell_radii(tri, a)).collect();
    let mut ring: Vec<u32> = Vec::new();
    for e in tri.edges() {
        let [a, b] = e.vertices;
        let (pa, pb) = (tri.point(a), tri.point(b));
        let d = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
        let rho = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if rho > top {
            continue;
        }
        ring.clear();
        ring.extend(tri.edge_ring(&e));
        let mut gabriel: Option<bool> = None;
        for (l, (&alpha, r)) in alphas.iter().zip(&radii).enumerate() {
            if rho > alpha {
                continue;
            }
            let amax = ring.iter().map(|&t| r[t as usize]).fold(0.0, f64::max);
            if alpha > amax {
                continue;
            }
            // Gabriel: no vertex of an incident tet strictly inside the
            // diametral sphere.
            let g = *gabriel.get_or_insert_with(|| edge_gabriel(tri, &ring, a, b));
            if g || smallest_triangle_in(tri, r, &ring, a, b, alpha) {
                let mut s = [tri.input_index(a), tri.input_index(b)];
                s.sort_unstable();
                out[l].push(s);
            }
        }
    }
    out
}

/// Whether the edge `ab` is Gabriel: no vertex of a tet of its `ring`
/// strictly inside its diametral sphere (exact).
fn edge_gabriel(tri: &Triangulation, ring: &[u32], a: u32, b: u32) -> bool {
    let (pa, pb) = (tri.point(a), tri.point(b));
    ring.iter().all(|&t| {
        tri.tet(t)
            .iter()
            .filter(|&&w| w != a && w != b && w != INFINITE)
            .all(|&w| !edge_diametral_side(pa, pb, tri.point(w)).is_negative())
    })
}

/// Whether a triangle incident to the edge `ab` (between consecutive tets
/// of its `ring`) is in F_α: then the edge's α_min, the smallest α_min of
/// its triangles when it is not Gabriel, is at most α.
fn smallest_triangle_in(
    tri: &Triangulation,
    r: &[f64],
    ring: &[u32],
    a: u32,
    b: u32,
    alpha: f64,
) -> bool {
    (0..ring.len()).any(|k| {
        let t = ring[k];
        let n = ring[(k + 1) % ring.len()];
        let v = tri.tet(t);
        // The face of t shared with n: opposite the vertex of t not in n.
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
        // α_min(triangle) ≤ α: an incident tet of radius ≤ α, or Gabriel
        // with ρ ≤ α (then `triangle_in`'s α_max condition holds too: α <
        // both radii here).
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
        triangle_in(tri, r, sides, alpha)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::alpha::AlphaComplex;
    use crate::rng::SplitMix64;

    fn rnd_points(seed: u64, n: usize, grid: bool) -> Vec<[f64; 3]> {
        let mut rng = SplitMix64::new(seed);
        let mut next = move || rng.uniform();
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

    /// `triangles_at` and `edges_at` give the interval complex's faces.
    fn same_faces(ac: &AlphaComplex, tri: &Triangulation, alpha: f64, seed: u64) {
        let mut a: Vec<[u32; 3]> = ac.triangles_at(alpha).collect();
        a.sort_unstable();
        let mut b = triangles_at(tri, alpha);
        b.sort_unstable();
        assert_eq!(a, b, "triangles, seed {seed}, alpha {alpha}");
        let mut a: Vec<[u32; 2]> = ac.edges_at(alpha).collect();
        a.sort_unstable();
        let mut b = edges_at(tri, alpha);
        b.sort_unstable();
        assert_eq!(a, b, "edges, seed {seed}, alpha {alpha}");
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
                same_faces(&ac, &tri, alpha, seed);
            }
            // Every α at once gives each α's edges.
            let alphas: Vec<f64> = spectrum.iter().copied().step_by(5).collect();
            let at_once = edges_at_levels(&tri, &alphas);
            for (&alpha, edges) in alphas.iter().zip(&at_once) {
                assert_eq!(edges, &edges_at(&tri, alpha), "seed {seed}, alpha {alpha}");
            }
        }
    }

    #[test]
    fn certified_radius_is_on_the_side_of_alpha_of_the_careful_one() {
        // Regular, flat (sliver) and nearly flat tets, α near and far from
        // their radius.
        let mut rng = SplitMix64::new(9);
        let mut next = move || rng.uniform();
        let mut exact_needed = 0;
        for t in 0..20_000 {
            let flat = match t % 4 {
                0 => 1.0,
                1 => 1e-9,
                _ => 0.0,
            };
            let p: Vec<[f64; 3]> = if t % 4 == 3 {
                // Nearly collinear: on a line of a random direction, each
                // point rounded (a line mapped by Q).
                let (o, d) = ([next(), next(), next()], [next(), next(), next()]);
                (0..4)
                    .map(|_| {
                        let s = 3.0 * next();
                        [o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]]
                    })
                    .collect()
            } else {
                (0..4)
                    .map(|_| {
                        [
                            next(),
                            next(),
                            flat * next() + if t % 7 == 0 { 0.5 } else { 0.0 },
                        ]
                    })
                    .collect()
            };
            let pr = [&p[0], &p[1], &p[2], &p[3]];
            let careful = tet_radius2(pr).sqrt();
            for alpha in [
                careful,
                careful * (1.0 + 1e-13),
                careful * 0.5,
                careful * 2.0,
                0.3,
                1e6,
            ] {
                if !alpha.is_finite() {
                    continue;
                }
                let got = cell_radius(pr, alpha);
                assert_eq!(
                    got <= alpha,
                    careful <= alpha,
                    "tet {t} alpha {alpha}: {got} vs {careful}"
                );
                assert_eq!(alpha > got, alpha > careful, "tet {t} alpha {alpha}");
                exact_needed += usize::from(got == careful);
            }
        }
        // The check is not vacuous: some radii were certified by bounds
        // (not equal to the careful value).
        assert!(exact_needed < 120_000);
    }

    #[test]
    fn circumradius_lower_bound_is_below_the_careful_radius() {
        let mut rng = SplitMix64::new(11);
        let mut next = move || rng.uniform();
        let mut far = 0;
        for t in 0..20_000 {
            let p: Vec<[f64; 3]> = if t % 2 == 0 {
                (0..3).map(|_| [next(), next(), next()]).collect()
            } else {
                let (o, d) = ([next(), next(), next()], [next(), next(), next()]);
                (0..3)
                    .map(|_| {
                        let s = 3.0 * next();
                        [o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]]
                    })
                    .collect()
            };
            let lo = circumradius_lower(&p[0], &p[1], &p[2]);
            let careful = triangle_rho_sorted(&p, [0, 1, 2]);
            assert!(lo <= careful, "triangle {t}: {lo} > {careful}");
            far += usize::from(t % 2 == 1 && lo > 1e6);
        }
        // The bound settles nearly collinear triangles (the reason it
        // exists): most of them are certified far beyond any α.
        assert!(far > 9_000, "{far}");
    }

    #[test]
    fn same_as_the_interval_complex_on_a_mapped_line() {
        // A line mapped by a rotation and a stretch, as a scan's orientation
        // maps the points of an exactly collinear cloud: every cell a flat
        // sliver.
        for seed in 0..3u64 {
            let mut rng = SplitMix64::new(100 + seed);
            let d = [0.37, 0.52 + 0.01 * seed as f64, 8.1];
            let pts: Vec<[f64; 3]> = (0..30)
                .map(|_| {
                    let s = 10.0 * rng.uniform();
                    [1.0 + s * d[0], -2.0 + s * d[1], 0.5 + s * d[2]]
                })
                .collect();
            let tri = Triangulation::new(&pts).unwrap();
            if tri.dimension() < 3 {
                continue;
            }
            let ac = AlphaComplex::new(tri.clone());
            let mut spectrum = ac.spectrum();
            spectrum.extend(spectrum.clone().windows(2).map(|w| 0.5 * (w[0] + w[1])));
            spectrum.extend([0.5, 1.0, 4.0]);
            for &alpha in spectrum.iter().step_by(7) {
                same_faces(&ac, &tri, alpha, seed);
            }
        }
    }
}
