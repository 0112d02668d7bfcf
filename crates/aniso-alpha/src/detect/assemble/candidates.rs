//! Stages 1 and 2 of the assembly (docs/method.md §4): candidate
//! primitives, component by component within each group (the simplices
//! found by one mode's orientations), at that group's scale, each with its
//! footprint. Per group, because a component of the whole union can join
//! a noisy wall (large α) to a clean roof (small α) along their common
//! edge.

use super::super::detection::Primitive;
use super::super::filter::{components, FilterError};
use super::super::regime::Regime;
use super::super::scan::{Face, LINE_SCAN_MIN};
use super::moments::Moments;
use super::same::{mostly_within, Piece};
use super::shape::Shape;
use super::{Candidate, Footprint, Settings};
use crate::par::{map_each, map_ranges};

/// At most this many pieces of a component (the largest) give a
/// candidate besides the whole component's fit.
const MAX_PIECES: usize = 64;

/// The candidates of the cleaned union `kept`, whose simplices were found
/// by the groups `group`: per component of each group, the greedy
/// extraction ([`extract`]) at the group's scale, with footprints.
pub(super) fn find<S: Shape>(
    points: &[[f64; 3]],
    kept: &[S],
    group: &[u32],
    settings: &Settings,
    regime: &Regime,
) -> Result<Vec<Candidate>, FilterError> {
    let comps = group_components(kept, group, settings.scales.len())?;
    // Short lines start from the scan's shortest pieces (three points);
    // a part still needs min_vertices points once its claims have joined
    // its pieces.
    let seed_min = if regime.keeps_short_lines() {
        settings.min_vertices.min(LINE_SCAN_MIN as usize + 1)
    } else {
        settings.min_vertices
    };
    // Components are independent: extracted in parallel, in order.
    let per_component = map_each(comps.len(), |k| {
        let (g, ss) = &comps[k];
        let scale = settings.scales[*g as usize];
        let local: Vec<S> = ss.iter().map(|&s| kept[s as usize]).collect();
        let extracted = extract(points, &local, scale.tau, seed_min, settings.part_angle_deg);
        let footprint = |k: usize| {
            let (seeds, fit) = &extracted[k];
            Footprint::new(fit, points, seeds, scale.cell)
        };
        // A large component's footprints on the pool's threads too (the
        // ground of an airborne tile and what it touches: dozens of
        // candidates of thousands of points).
        let seeds: usize = extracted.iter().map(|e| e.0.len()).sum();
        let feet = if seeds < CHUNKED_VERTICES {
            (0..extracted.len()).map(footprint).collect()
        } else {
            map_each(extracted.len(), footprint)
        };
        extracted
            .into_iter()
            .zip(feet)
            .filter_map(|((seeds, fit), foot)| {
                Some(Candidate {
                    fit,
                    tau: scale.tau,
                    cell: scale.cell,
                    seeds,
                    foot: foot?,
                })
            })
            .collect::<Vec<Candidate>>()
    });
    Ok(per_component.into_iter().flatten().collect())
}

/// The connected components of each group's simplices: (group, indices
/// into `kept`), group by group, components in the order
/// [`components`] numbers them. Groups on the pool's threads.
fn group_components<S: Face>(
    kept: &[S],
    group: &[u32],
    n_groups: usize,
) -> Result<Vec<(u32, Vec<u32>)>, FilterError> {
    let mut by_group: Vec<Vec<u32>> = vec![Vec::new(); n_groups];
    for (s, &g) in group.iter().enumerate() {
        by_group[g as usize].push(s as u32);
    }
    let per_group = map_each(n_groups, |g| -> Result<Vec<(u32, Vec<u32>)>, FilterError> {
        let ss = &by_group[g];
        if ss.is_empty() {
            return Ok(Vec::new());
        }
        let local: Vec<S> = ss.iter().map(|&s| kept[s as usize]).collect();
        let comp = components(&local)?;
        let n_comp = comp.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
        let mut parts: Vec<Vec<u32>> = vec![Vec::new(); n_comp];
        for (k, &c) in comp.iter().enumerate() {
            parts[c as usize].push(ss[k]);
        }
        Ok(parts.into_iter().map(|p| (g as u32, p)).collect())
    });
    let mut out = Vec::new();
    for g in per_group {
        out.extend(g?);
    }
    Ok(out)
}

/// Greedy extraction of straight/flat primitives from one connected
/// component `local` (module doc of `assemble`, step 1): their inlier
/// vertices (within `tol`) and fits, while the best candidate covers at
/// least `min_vertices` new vertices; then from the pieces of what none
/// of them covers ([`pieces_of_the_rest`]), the same way, until those
/// give nothing.
fn extract<S: Shape>(
    points: &[[f64; 3]],
    local: &[S],
    tol: f64,
    min_vertices: usize,
    angle: f64,
) -> Vec<(Vec<u32>, Primitive)> {
    let mut out: Vec<Extracted> = Vec::new();
    let parts = || S::parts(points, local, angle).unwrap_or_else(|_| vec![0; local.len()]);
    // A large component's vertices are listed while its simplices are
    // split into pieces (the pieces' growth runs on one thread); a small
    // one's first, which may leave nothing to split.
    let (verts, part) = if local.len() >= CHUNKED_VERTICES {
        let (verts, part) = crate::par::join(|| vertices_of(points.len(), local), parts);
        (verts, Some(part))
    } else {
        (vertices_of(points.len(), local), None)
    };
    if verts.len() < min_vertices {
        return Vec::new();
    }
    let part = part.unwrap_or_else(parts);
    let mut cands = piece_fits(points, local, &part, &verts);
    drop(part);
    let inside = |c: &Primitive, v: u32| c.distance(&points[v as usize]) <= tol;
    let inliers = |fit: &Primitive| -> Vec<u32> { filter_chunks(&verts, |v| inside(fit, v)) };
    // Each candidate's count of uncovered vertices within `tol`, counted
    // once and then lowered by the vertices each extraction covers: the
    // counts a recount over the uncovered vertices would give, at the
    // cost of one pass over the vertices per candidate in all.
    let mut new_count: Vec<usize> = count_each(&cands, &vec![true; cands.len()], &verts, &inside);
    let mut covered = vec![false; verts.len()];
    let mut taken_since_split = 0usize;
    loop {
        // The first candidate with the most new inliers.
        let mut best: Option<(usize, usize)> = None; // (new inliers, candidate)
        for (ci, &new) in new_count.iter().enumerate() {
            if best.is_none_or(|b| new > b.0) {
                best = Some((new, ci));
            }
        }
        let exhausted = best.is_none_or(|(new, _)| new < min_vertices);
        if exhausted {
            // What no candidate covers: its own pieces are candidates, as
            // the component's were (a piece grown by angle alone over
            // undulating ground is wider than one slab of τ).
            if taken_since_split == 0 {
                break;
            }
            taken_since_split = 0;
            let rest =
                pieces_of_the_rest::<S>(points, local, &verts, &covered, min_vertices, angle);
            if rest.is_empty() {
                break;
            }
            let uncovered: Vec<u32> = verts
                .iter()
                .zip(&covered)
                .filter_map(|(&v, &c)| (!c).then_some(v))
                .collect();
            new_count.extend(count_each(
                &rest,
                &vec![true; rest.len()],
                &uncovered,
                &inside,
            ));
            cands.extend(rest);
            continue;
        }
        let Some((_, ci)) = best else { break };
        taken_since_split += 1;
        new_count.swap_remove(ci);
        let mut fit = cands.swap_remove(ci);
        for _ in 0..2 {
            let refit = S::fit(points, &inliers(&fit));
            if matches!(refit, Primitive::None) {
                break;
            }
            fit = refit;
        }
        let inl = inliers(&fit);
        // `inl` is a sorted subset of the sorted `verts`: one walk.
        let mut gained: Vec<u32> = Vec::new();
        let mut next = inl.iter().peekable();
        for (k, &v) in verts.iter().enumerate() {
            if next.next_if_eq(&&v).is_some() && !covered[k] {
                covered[k] = true;
                gained.push(v);
            }
        }
        // A candidate below `min_vertices` can no longer be taken (counts
        // only fall, and one above it always outranks it): not recounted.
        let live: Vec<bool> = new_count.iter().map(|&c| c >= min_vertices).collect();
        for (count, lost) in new_count
            .iter_mut()
            .zip(count_each(&cands, &live, &gained, &inside))
        {
            *count -= lost;
        }
        let gained = gained.len();
        if gained < min_vertices || inl.len() < min_vertices {
            break;
        }
        // An earlier candidate found again (most of this one's inliers
        // within τ of its primitive, the two one primitive): the merge the
        // claims would make of the two (stage 3), made now.
        match out
            .iter()
            .position(|e| e.found_again::<S>(&fit, &inl, tol, angle, points))
        {
            Some(k) => out[k].join::<S>(&inl, points),
            None => out.push(Extracted {
                seeds: inl,
                fit,
                joined: None,
            }),
        }
    }
    out.into_iter().map(|e| e.finish::<S>(points)).collect()
}

/// The fits of the pieces of the simplices of `local` none of whose
/// vertices is `covered` (flags over the sorted `verts`), and of all of
/// them together ([`piece_fits`]); none where those vertices are fewer
/// than `min_vertices`.
fn pieces_of_the_rest<S: Shape>(
    points: &[[f64; 3]],
    local: &[S],
    verts: &[u32],
    covered: &[bool],
    min_vertices: usize,
    angle: f64,
) -> Vec<Primitive> {
    let open = |v: u32| verts.binary_search(&v).is_ok_and(|k| !covered[k]);
    let rest: Vec<S> = local
        .iter()
        .filter(|s| s.as_ref().iter().all(|&v| open(v)))
        .copied()
        .collect();
    let rest_verts = vertices_of(points.len(), &rest);
    if rest_verts.len() < min_vertices {
        return Vec::new();
    }
    let part = S::parts(points, &rest, angle).unwrap_or_else(|_| vec![0; rest.len()]);
    piece_fits(points, &rest, &part, &rest_verts)
}

/// A candidate extracted from a component ([`extract`]): its inliers and
/// fit, and once later extractions have joined it, the moments of its
/// inliers (its fit is then theirs, fitted again from the points at the
/// end).
struct Extracted {
    seeds: Vec<u32>,
    fit: Primitive,
    joined: Option<Moments>,
}

impl Extracted {
    /// Whether the primitive `fit` with the inliers `inl` is this
    /// candidate found again: one primitive with it ([`Shape::same`] at
    /// the component's τ), most of `inl` ([`mostly_within`]) within τ of
    /// its primitive, and some of them its own.
    fn found_again<S: Shape>(
        &self,
        fit: &Primitive,
        inl: &[u32],
        tau: f64,
        angle: f64,
        points: &[[f64; 3]],
    ) -> bool {
        let piece = |fit, seeds| Piece { fit, tau, seeds };
        let (this, other) = (piece(&self.fit, &self.seeds), piece(fit, inl));
        S::same(this, other, angle, points)
            && mostly_within(other, this, points)
            && shares(&self.seeds, inl)
    }

    /// The inliers `inl` joined to this candidate; its fit becomes that of
    /// the moments of the union.
    fn join<S: Shape>(&mut self, inl: &[u32], points: &[[f64; 3]]) {
        let (seeds, new) = union(&self.seeds, inl);
        let moments = self
            .joined
            .unwrap_or_else(|| Moments::of(&self.seeds, points))
            .join(&Moments::of(&new, points));
        let joint = if S::K == 1 {
            moments.line()
        } else {
            moments.plane()
        };
        if !matches!(joint, Primitive::None) {
            self.fit = joint;
        }
        self.seeds = seeds;
        self.joined = Some(moments);
    }

    /// The inliers and the fit: a joined candidate fitted again on its
    /// points (the fit every candidate has, extent included).
    fn finish<S: Shape>(self, points: &[[f64; 3]]) -> (Vec<u32>, Primitive) {
        let fit = match self.joined {
            Some(_) => match S::fit(points, &self.seeds) {
                Primitive::None => self.fit,
                joint => joint,
            },
            None => self.fit,
        };
        (self.seeds, fit)
    }
}

/// Whether the sorted lists `a` and `b` have an element in common.
fn shares(a: &[u32], b: &[u32]) -> bool {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => return true,
        }
    }
    false
}

/// The union of the sorted, distinct lists `a` and `b`, sorted and
/// distinct, and the elements of `b` not in `a`.
fn union(a: &[u32], b: &[u32]) -> (Vec<u32>, Vec<u32>) {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let mut new = Vec::new();
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => {
                out.push(a[i]);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                out.push(b[j]);
                new.push(b[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                out.push(a[i]);
                i += 1;
                j += 1;
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    new.extend_from_slice(&b[j..]);
    (out, new)
}

/// Vertices from which one component's passes over its vertices are cut
/// into chunks for the threads: 2^15. A scan's ground is one component of
/// hundreds of thousands of vertices, extracted alone while the small
/// components are done; below this a pass is a few microseconds' work.
const CHUNKED_VERTICES: usize = 1 << 15;

/// The vertices of the sorted `verts` for which `keep` holds, in order; in
/// chunks on the pool's threads from [`CHUNKED_VERTICES`] vertices.
fn filter_chunks(verts: &[u32], keep: impl Fn(u32) -> bool + Sync) -> Vec<u32> {
    if verts.len() < CHUNKED_VERTICES {
        return verts.iter().copied().filter(|&v| keep(v)).collect();
    }
    let chunk = CHUNKED_VERTICES / 4;
    map_ranges(
        verts.len().div_ceil(chunk),
        || (),
        |_, k| {
            verts[k * chunk..((k + 1) * chunk).min(verts.len())]
                .iter()
                .copied()
                .filter(|&v| keep(v))
                .collect::<Vec<u32>>()
        },
    )
    .concat()
}

/// For each candidate counted (`counted`), how many of `verts` lie within
/// its tolerance (`inside`), 0 for the others; the candidates on the
/// pool's threads when there are [`CHUNKED_VERTICES`] vertices or more.
fn count_each(
    cands: &[Primitive],
    counted: &[bool],
    verts: &[u32],
    inside: &(impl Fn(&Primitive, u32) -> bool + Sync),
) -> Vec<usize> {
    let count = |ci: usize| match counted[ci] {
        true => verts.iter().filter(|&&v| inside(&cands[ci], v)).count(),
        false => 0,
    };
    if verts.len() < CHUNKED_VERTICES {
        return (0..cands.len()).map(count).collect();
    }
    map_each(cands.len(), count)
}

/// The distinct vertices of the simplices `local` (of a cloud of
/// `n_points`), ascending: marked in a bitset of the cloud's points where
/// the simplices list more vertices than the set has words, sorted
/// otherwise.
fn vertices_of<S: AsRef<[u32]>>(n_points: usize, local: &[S]) -> Vec<u32> {
    let listed: usize = local.iter().map(|s| s.as_ref().len()).sum();
    let words = n_points.div_ceil(64);
    let mut verts: Vec<u32>;
    if listed >= words {
        let mut bits = vec![0u64; words];
        for &v in local.iter().flat_map(|s| s.as_ref()) {
            bits[v as usize / 64] |= 1 << (v % 64);
        }
        verts = Vec::with_capacity(bits.iter().map(|w| w.count_ones() as usize).sum());
        for (k, &w) in bits.iter().enumerate() {
            let mut w = w;
            while w != 0 {
                verts.push((k * 64) as u32 + w.trailing_zeros());
                w &= w - 1;
            }
        }
    } else {
        verts = local
            .iter()
            .flat_map(|s| s.as_ref().iter().copied())
            .collect();
        crate::par::sort_unstable(&mut verts);
        verts.dedup();
        // Held through the extraction: a vertex is in about six triangles.
        verts.shrink_to_fit();
    }
    verts
}

/// The candidate primitives of a component with the simplices `local`,
/// split into the pieces `part` of like-oriented simplices
/// ([`Face::parts`]; all in one where that failed, which needs a NaN
/// point), and the vertices `verts`: the fits of the pieces with at least
/// two simplices' worth of points, the largest [`MAX_PIECES`], and the fit
/// of the whole component.
fn piece_fits<S: Face>(
    points: &[[f64; 3]],
    local: &[S],
    part: &[u32],
    verts: &[u32],
) -> Vec<Primitive> {
    let n_parts = part.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    let pv = part_vertices(points.len(), local, part, n_parts, verts.len());
    let mut by_size: Vec<(usize, usize)> = pv.iter().map(Vec::len).zip(0..).collect();
    by_size.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let fitted: Vec<usize> = by_size
        .iter()
        .take(MAX_PIECES)
        .filter(|&&(sz, _)| sz >= S::K + 2)
        .map(|&(_, i)| i)
        .collect();
    let mut cands: Vec<Primitive> = if verts.len() < CHUNKED_VERTICES {
        fitted.iter().map(|&i| S::fit(points, &pv[i])).collect()
    } else {
        map_each(fitted.len(), |k| S::fit(points, &pv[fitted[k]]))
    };
    cands.push(S::fit(points, verts));
    cands
}

/// The vertices of each of the `n_parts` parts (`part`: each simplex's)
/// of a component's simplices `local`, sorted and distinct. A large
/// component (`n_verts` vertices) on the pool's threads: a vertex is in
/// about six triangles, mostly of one part, and a stamp of the last part
/// that listed it (one per point of the cloud's `n_points`) leaves few
/// repeats to sort away.
fn part_vertices<S: AsRef<[u32]>>(
    n_points: usize,
    local: &[S],
    part: &[u32],
    n_parts: usize,
    n_verts: usize,
) -> Vec<Vec<u32>> {
    let mut pv: Vec<Vec<u32>> = vec![Vec::new(); n_parts];
    if n_verts < CHUNKED_VERTICES {
        for (s, &p) in local.iter().zip(part) {
            pv[p as usize].extend_from_slice(s.as_ref());
        }
        for v in &mut pv {
            v.sort_unstable();
            v.dedup();
        }
        return pv;
    }
    let mut last = vec![u32::MAX; n_points];
    for (s, &p) in local.iter().zip(part) {
        for &v in s.as_ref() {
            if last[v as usize] != p {
                last[v as usize] = p;
                pv[p as usize].push(v);
            }
        }
    }
    drop(last);
    crate::par::for_each_mut(pv.iter_mut().collect(), |v| {
        crate::par::sort_unstable(v);
        v.dedup();
    });
    pv
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::assemble::Scale;
    use crate::detect::fit::fit_plane_indices;
    use crate::detect::StructureKind;
    use crate::geometry::dot;

    /// Edges along two perpendicular lines meeting at the origin (an L),
    /// eleven points each, and a separate chain of four points far away.
    fn l_shape() -> (Vec<[f64; 3]>, Vec<[u32; 2]>) {
        let mut pts: Vec<[f64; 3]> = (0..11).map(|i| [i as f64, 0.0, 0.0]).collect();
        pts.extend((1..11).map(|i| [0.0, i as f64, 0.0]));
        pts.extend((0..4).map(|i| [50.0 + i as f64, 50.0, 0.0]));
        let mut edges: Vec<[u32; 2]> = (0..10).map(|i| [i, i + 1]).collect();
        edges.push([0, 11]);
        edges.extend((11..20).map(|i| [i, i + 1]));
        edges.extend((21..24).map(|i| [i, i + 1]));
        (pts, edges)
    }

    #[test]
    fn an_l_gives_its_two_legs() {
        let (pts, edges) = l_shape();
        let legs = extract(&pts, &edges[..20], 0.1, 5, 10.0);
        assert_eq!(legs.len(), 2);
        // Each leg's inliers: its eleven points (the corner in both).
        let mut sizes: Vec<usize> = legs.iter().map(|(s, _)| s.len()).collect();
        sizes.sort_unstable();
        assert_eq!(sizes, [11, 11]);
        assert!(legs.iter().all(|(_, f)| f.rms() < 1e-9));
        // Too few vertices: nothing.
        assert!(extract(&pts, &edges[..3], 0.1, 5, 10.0).is_empty());
    }

    #[test]
    fn candidates_come_per_component_and_group_at_their_scale() {
        let (pts, edges) = l_shape();
        // The L in group 0, the far chain in group 1.
        let group: Vec<u32> = (0..edges.len()).map(|i| u32::from(i >= 20)).collect();
        let settings = Settings {
            part_angle_deg: 10.0,
            outlines: true,
            min_vertices: 4,
            scales: vec![
                Scale {
                    tau: 0.1,
                    cell: 2.0,
                },
                Scale {
                    tau: 0.2,
                    cell: 3.0,
                },
            ],
            clock: Default::default(),
        };
        let regime = Regime::new(StructureKind::Lines, None, false, None);
        let cands = find(&pts, &edges, &group, &settings, &regime).unwrap();
        assert_eq!(cands.len(), 3);
        assert_eq!(cands[2].seeds, [21, 22, 23, 24]);
        assert_eq!((cands[2].tau, cands[2].cell), (0.2, 3.0));
        assert!(cands[..2].iter().all(|c| c.tau == 0.1 && c.cell == 2.0));
        // Short lines under the test start from three points: the chain's
        // first three edges alone are a candidate then, not otherwise.
        let short = Regime::new(StructureKind::Lines, Some(1.0), false, None);
        let three = [[21, 22], [22, 23]];
        assert_eq!(
            find(&pts, &three, &[1, 1], &settings, &short)
                .unwrap()
                .len(),
            1
        );
        assert!(find(&pts, &three, &[1, 1], &settings, &regime)
            .unwrap()
            .is_empty());
    }

    /// Triangles of `m` folded sheets, each a strip of squares whose
    /// halves alternate between two planes 40° apart (planar parts of
    /// 10°), jittered: several components of several parts each, in one
    /// group, listed sorted as the union lists them.
    fn folded_sheets(m: u32, seed: u64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut rng = crate::rng::SplitMix64::new(seed);
        let mut pts = Vec::new();
        let mut tris = Vec::new();
        for sheet in 0..m {
            let base = pts.len() as u32;
            let n = 6 + sheet * 3;
            for i in 0..=n {
                for j in 0..=3u32 {
                    let x = f64::from(i);
                    let fold = if (i / 3) % 2 == 0 { 0.0 } else { 0.8 };
                    let z = fold * f64::from(j) + 0.01 * rng.uniform();
                    pts.push([x + 100.0 * f64::from(sheet), f64::from(j), z]);
                }
            }
            let id = |i: u32, j: u32| base + i * 4 + j;
            for i in 0..n {
                for j in 0..3 {
                    tris.push(<[u32; 3]>::sorted(
                        [id(i, j), id(i + 1, j), id(i + 1, j + 1)].into_iter(),
                    ));
                    tris.push(<[u32; 3]>::sorted(
                        [id(i, j), id(i + 1, j + 1), id(i, j + 1)].into_iter(),
                    ));
                }
            }
        }
        tris.sort_unstable();
        (pts, tris)
    }

    /// A component's vertices, sorted and distinct, by the bitset (many
    /// simplices in a small cloud) and by the sort (few in a large one),
    /// against a set; the oracle tells a repeat kept apart.
    #[test]
    fn vertices_of_are_the_sorted_distinct_vertices() {
        let mut rng = crate::rng::SplitMix64::new(5);
        for (n_points, n_simplices) in [(1000, 400), (100_000, 50), (130, 0), (64, 64)] {
            let mut local: Vec<[u32; 3]> = (0..n_simplices)
                .map(|_| [0, 1, 2].map(|_| (rng.uniform() * n_points as f64) as u32))
                .collect();
            // A simplex listed twice, as components' neighbours share
            // vertices.
            if let Some(&first) = local.first() {
                local.push(first);
            }
            let want: Vec<u32> = local
                .iter()
                .flatten()
                .copied()
                .collect::<std::collections::BTreeSet<u32>>()
                .into_iter()
                .collect();
            assert_eq!(
                vertices_of(n_points, &local),
                want,
                "{n_points} {n_simplices}"
            );
            let listed: Vec<u32> = local.iter().flatten().copied().collect();
            if n_simplices > 0 {
                assert_ne!(listed.len(), want.len(), "the oracle must see repeats");
            }
        }
    }

    #[test]
    fn part_vertices_are_each_parts_sorted_distinct_vertices() {
        let (pts, tris) = folded_sheets(3, 9);
        let part = <[u32; 3]>::parts(&pts, &tris, 10.0).unwrap();
        let n_parts = part.iter().map(|&p| p as usize + 1).max().unwrap();
        let mut want: Vec<Vec<u32>> = vec![Vec::new(); n_parts];
        for (t, &p) in tris.iter().zip(&part) {
            want[p as usize].extend_from_slice(t);
        }
        for w in &mut want {
            w.sort_unstable();
            w.dedup();
        }
        // Both ways: the plain lists, and the stamped ones of a large
        // component.
        for n_verts in [0, CHUNKED_VERTICES] {
            let got = part_vertices(pts.len(), &tris, &part, n_parts, n_verts);
            assert_eq!(got, want, "{n_verts}");
        }
    }

    /// A noisy sheet (41 × 11 points, 0.5 apart, heights Gaussian of
    /// σ = 0.015) and a flat strip 0.6 above it, joined to it along one
    /// side: one component, whose sheet no plane holds within τ = 0.02.
    fn noisy_sheet_and_shelf() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut rng = crate::rng::SplitMix64::new(5);
        let mut pts = Vec::new();
        let (nx, ny) = (41u32, 11u32);
        for i in 0..nx {
            for j in 0..ny {
                let x = 0.5 * f64::from(i) - 10.0;
                let (u, v) = (rng.uniform().max(1e-12), rng.uniform());
                let gauss = (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos();
                pts.push([x, 0.5 * f64::from(j), 0.015 * gauss]);
            }
        }
        let shelf = pts.len() as u32;
        for i in 0..nx {
            for j in 0..4u32 {
                pts.push([0.5 * f64::from(i) - 10.0, 5.0 + 0.5 * f64::from(j), 0.6]);
            }
        }
        let mut tris = Vec::new();
        let sheet = |i: u32, j: u32| i * ny + j;
        let top = |i: u32, j: u32| shelf + i * 4 + j;
        for i in 0..nx - 1 {
            for j in 0..ny - 1 {
                tris.push([sheet(i, j), sheet(i + 1, j), sheet(i + 1, j + 1)]);
                tris.push([sheet(i, j), sheet(i + 1, j + 1), sheet(i, j + 1)]);
            }
            for j in 0..3 {
                tris.push([top(i, j), top(i + 1, j), top(i + 1, j + 1)]);
                tris.push([top(i, j), top(i + 1, j + 1), top(i, j + 1)]);
            }
            // The bridge between the sheet's last row and the shelf.
            tris.push([sheet(i, ny - 1), sheet(i + 1, ny - 1), top(i + 1, 0)]);
            tris.push([sheet(i, ny - 1), top(i + 1, 0), top(i, 0)]);
        }
        let mut tris: Vec<[u32; 3]> = tris
            .into_iter()
            .map(|t| <[u32; 3]>::sorted(t.into_iter()))
            .collect();
        tris.sort_unstable();
        (pts, tris)
    }

    #[test]
    fn a_candidate_found_again_joins_the_first_and_a_parallel_shelf_does_not() {
        let (pts, tris) = noisy_sheet_and_shelf();
        let cands = extract(&pts, &tris, 0.02, 4, 10.0);
        let on_sheet = |c: &(Vec<u32>, Primitive)| c.0.iter().all(|&v| v < 41 * 11);
        // The sheet's slabs, the later ones mostly the first one's points,
        // are one candidate (two without the rule); the shelf, parallel
        // to it and 0.6 above, is another.
        let sizes: Vec<usize> = cands.iter().map(|c| c.0.len()).collect();
        let sheets: Vec<&(Vec<u32>, Primitive)> = cands.iter().filter(|c| on_sheet(c)).collect();
        assert_eq!(sheets.len(), 1, "{sizes:?}");
        assert!(sheets[0].0.len() > 41 * 11 * 2 / 3, "{sizes:?}");
        assert!(cands
            .iter()
            .any(|c| c.0.len() == 41 * 4 && c.0.iter().all(|&v| v >= 41 * 11)));
        // Its fit is the plane of all its points.
        let Primitive::Plane(joint) = &sheets[0].1 else {
            panic!("not a plane")
        };
        let all = fit_plane_indices(&pts, &sheets[0].0).unwrap();
        assert!((dot(joint.normal, all.normal).abs() - 1.0).abs() < 1e-12);
        assert!((joint.rms_residual - all.rms_residual).abs() < 1e-12);
    }
}
