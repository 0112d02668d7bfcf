//! Stage 7 of the assembly (docs/method.md §4): structures from the parts,
//! and the detection. Parts that share claimed points (where two facets
//! meet) and do not cross each other (crossing lines, planes cutting
//! through each other, a T-junction) are facets of one structure.
//! Structures are numbered by size (points), largest first, parts likewise
//! within each; each part gets its outline and mesh, or its segment
//! ([`Shape::outline`]); the union's simplices are kept with the structure
//! (and part) that holds all their vertices; every point gets the label of
//! its first occurrence.

use super::super::cloud::Cloud;
use super::super::detection::{Detection, Part, RunStats, Simplices, Structure};
use super::super::StructureKind;
use super::claims::Claims;
use super::shape::crosses;
use super::{part_of_candidates, Candidate, Draft, Shape};
use crate::par::map_each;
use crate::unionfind::UnionFind;

/// The detection of `parts` (module doc), lines or planes by the shape
/// `S`, the plane parts with their outlines and meshes if `outlines`;
/// `claims` are the candidates' final claims, `kept` the cleaned union.
/// What the outlines do not need (the claims, the candidates but their
/// cells, the union) is dropped before they are drawn, the parts' members
/// move into the detection, and the union's simplices are listed after: a
/// large part's 2D triangulation is the last peak of a run's memory.
pub(super) fn detection<S: Shape>(
    cloud: &Cloud<'_>,
    outlines: bool,
    parts: Vec<Draft>,
    cands: Vec<Candidate>,
    claims: Claims,
    kept: Vec<S>,
    mut stats: RunStats,
) -> Detection {
    let points = cloud.points();
    let groups = group_parts::<S>(&parts, cands.len(), &claims, points);
    drop(claims);
    // Each part's cell (its candidate's), in the order they are numbered.
    let cells: Vec<f64> = groups
        .iter()
        .flatten()
        .map(|&pi| cands[parts[pi as usize].cand].cell)
        .collect();
    drop(cands);
    let (mut structures, vstruct, vpart) = number::<S>(parts, groups, points);
    // Each part's outline and mesh (unless the run draws none), or
    // segment, the parts in parallel; then the union's simplices into the
    // structures.
    let numbered: Vec<&Part> = structures.iter().flat_map(|st| &st.parts).collect();
    let shapes = map_each(numbered.len(), |k| {
        if S::K == 2 && !outlines {
            return Default::default();
        }
        S::outline(
            &numbered[k].primitive,
            &numbered[k].vertices,
            cells[k],
            points,
        )
    });
    let parts = structures.iter_mut().flat_map(|st| st.parts.iter_mut());
    for (part, (outline, mesh)) in parts.zip(shapes) {
        (part.outline, part.mesh) = (outline, mesh);
    }
    let (simplices, simplex_structure) = simplices(&mut structures, &kept, &vstruct, &vpart);
    drop(kept);
    stats.structure_simplices = simplices.len();
    let first = cloud.copies().first().to_vec();
    let labels: Vec<i64> = first
        .iter()
        .map(|&f| match vstruct[f as usize] {
            u32::MAX => -1,
            s => i64::from(s),
        })
        .collect();
    Detection {
        kind: if S::K == 1 {
            StructureKind::Lines
        } else {
            StructureKind::Planes
        },
        simplices,
        simplex_structure,
        structures,
        labels,
        first_occurrence: first,
        stats,
    }
}

/// The parts of each structure: parts sharing claims and not crossing,
/// grouped; structures largest first (points; the first point on a tie),
/// parts within each likewise.
fn group_parts<S: Shape>(
    parts: &[Draft],
    n_cands: usize,
    claims: &Claims,
    points: &[[f64; 3]],
) -> Vec<Vec<u32>> {
    let part_of_cand = part_of_candidates(parts, n_cands);
    let mut uf = UnionFind::new(parts.len());
    let part_of = |c: u32| Some(part_of_cand[c as usize]).filter(|&p| p != u32::MAX);
    for (a, b) in claims.shared(part_of) {
        let (pa, pb) = (&parts[a as usize], &parts[b as usize]);
        if !crosses::<S>(&pa.fit, &pb.members, points)
            && !crosses::<S>(&pb.fit, &pa.members, points)
        {
            uf.union_min_root(a, b);
        }
    }
    let size = |p: u32| parts[p as usize].members.len();
    let first = |p: u32| parts[p as usize].members[0];
    let mut groups: Vec<(usize, u32, Vec<u32>)> = uf
        .sets()
        .into_iter()
        .filter(|g| !g.is_empty())
        .map(|g| {
            let total: usize = g.iter().map(|&p| size(p)).sum();
            let lowest = g.iter().map(|&p| first(p)).min().unwrap_or(u32::MAX);
            (total, lowest, g)
        })
        .collect();
    groups.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    groups
        .into_iter()
        .map(|(_, _, mut g)| {
            g.sort_by(|&a, &b| size(b).cmp(&size(a)).then(first(a).cmp(&first(b))));
            g
        })
        .collect()
}

/// The structures of `groups` (their parts, in order; outlines and
/// meshes not yet drawn), and per point its structure and its global part
/// number (as in the report), `u32::MAX` for none.
fn number<S: Shape>(
    parts: Vec<Draft>,
    groups: Vec<Vec<u32>>,
    points: &[[f64; 3]],
) -> (Vec<Structure>, Vec<u32>, Vec<u32>) {
    let mut vstruct = vec![u32::MAX; points.len()];
    let mut vpart = vec![u32::MAX; points.len()];
    let mut structures: Vec<Structure> = Vec::with_capacity(groups.len());
    let mut part_base = 0u32;
    let mut parts: Vec<Option<Draft>> = parts.into_iter().map(Some).collect();
    for (id, ps) in groups.into_iter().enumerate() {
        let sparts: Vec<Part> = ps
            .iter()
            .filter_map(|&pi| parts[pi as usize].take())
            .map(|p| Part {
                simplices: Vec::new(),
                vertices: p.members,
                primitive: p.fit,
                outline: Vec::new(),
                mesh: Vec::new(),
                log10_nfa: p.log10_nfa,
            })
            .collect();
        let mut v: Vec<u32> = sparts
            .iter()
            .flat_map(|p| p.vertices.iter().copied())
            .collect();
        v.sort_unstable();
        for (k, p) in sparts.iter().enumerate() {
            for &x in &p.vertices {
                vstruct[x as usize] = id as u32;
                vpart[x as usize] = part_base + k as u32;
            }
        }
        part_base += sparts.len() as u32;
        let log10_nfa = sparts
            .iter()
            .map(|p| p.log10_nfa)
            .fold(f64::INFINITY, f64::min);
        structures.push(Structure {
            id: id as u32,
            simplices: Vec::new(),
            primitive: S::fit(points, &v),
            vertices: v,
            parts: sparts,
            log10_nfa,
        });
    }
    (structures, vstruct, vpart)
}

/// The simplices of the union `kept` with all their vertices in one
/// structure (and the structure of each), each listed in its structure
/// and, when all its vertices are in one part, in that part.
fn simplices<S: Shape>(
    structures: &mut [Structure],
    kept: &[S],
    vstruct: &[u32],
    vpart: &[u32],
) -> (Simplices, Vec<u32>) {
    let part_index: Vec<(u32, u32)> = structures
        .iter()
        .enumerate()
        .flat_map(|(s, st)| (0..st.parts.len() as u32).map(move |p| (s as u32, p)))
        .collect();
    let structure_of = |vs: &[u32]| -> Option<u32> {
        let st = vstruct[vs[0] as usize];
        (st != u32::MAX && vs.iter().all(|&v| vstruct[v as usize] == st)).then_some(st)
    };
    // Counted first, so that the lists hold no spare capacity.
    let count = kept
        .iter()
        .filter(|s| structure_of(s.as_ref()).is_some())
        .count();
    let mut flat: Vec<u32> = Vec::with_capacity(count * (S::K + 1));
    let mut simplex_structure: Vec<u32> = Vec::with_capacity(count);
    for s in kept {
        let vs = s.as_ref();
        let Some(st) = structure_of(vs) else {
            continue;
        };
        let idx = simplex_structure.len() as u32;
        let gp = vpart[vs[0] as usize];
        if vs.iter().all(|&v| vpart[v as usize] == gp) {
            let (_, p) = part_index[gp as usize];
            structures[st as usize].parts[p as usize]
                .simplices
                .push(idx);
        }
        structures[st as usize].simplices.push(idx);
        flat.extend_from_slice(vs);
        simplex_structure.push(st);
    }
    for st in structures.iter_mut() {
        st.simplices.shrink_to_fit();
        st.parts
            .iter_mut()
            .for_each(|p| p.simplices.shrink_to_fit());
    }
    let simplices = Simplices::from_flat(S::K + 1, flat);
    (simplices, simplex_structure)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::cloud::Copies;

    /// A part on the points `members`, fitted as a line, and its
    /// candidate (number `cand`).
    fn part(pts: &[[f64; 3]], members: Vec<u32>, cand: usize) -> (Draft, Candidate) {
        Draft::line(pts, members, cand, (0.1, 1.0))
    }

    #[test]
    fn a_polyline_is_one_structure_and_a_crossing_line_another() {
        // A polyline: x axis 0..=10 then up x = 10 to y = 6 (sharing the
        // corner's claims); a line along y through x = 5 crossing the
        // first leg (sharing the crossing point's claims); a copy of
        // point 3 at the end.
        let mut pts: Vec<[f64; 3]> = (0..11).map(|i| [i as f64, 0.0, 0.0]).collect();
        pts.extend((1..7).map(|i| [10.0, i as f64, 0.0]));
        pts.extend((-4..5).filter(|&i| i != 0).map(|i| [5.0, i as f64, 0.0]));
        pts.push(pts[3]);
        let (parts, cands): (Vec<Draft>, Vec<Candidate>) = [
            part(&pts, (0..11).collect(), 0),
            part(&pts, (11..17).collect(), 1),
            part(&pts, (17..25).collect(), 2),
        ]
        .into_iter()
        .unzip();
        // Claims: the corner (10) by candidates 0 and 1, the crossing
        // point (5) by 0 and 2.
        let claims =
            Claims::from_sorted(vec![(5, 0, 0.0), (5, 2, 0.0), (10, 0, 0.0), (10, 1, 0.0)]);
        let copies = Copies::of(&pts);
        let cloud = Cloud::new(&pts, &copies);
        let kept: Vec<[u32; 2]> = vec![[0, 1], [9, 10], [10, 11], [17, 18], [3, 20]];
        let det = detection::<[u32; 2]>(
            &cloud,
            true,
            parts,
            cands,
            claims,
            kept,
            RunStats::default(),
        );
        assert_eq!(det.structures.len(), 2);
        let (poly, cross) = (&det.structures[0], &det.structures[1]);
        assert_eq!(poly.kind_name(), "polyline");
        assert_eq!(poly.vertices.len(), 17);
        assert_eq!(poly.parts[0].vertices.len(), 11);
        assert_eq!(poly.log10_nfa, -1.0);
        assert_eq!(cross.kind_name(), "line");
        // Segments: a part's extreme points.
        let seg = poly.parts[1].segment().unwrap();
        assert!((seg[0][1] - 1.0).abs() < 1e-9 || (seg[1][1] - 1.0).abs() < 1e-9);
        // Simplices: within a part, across the corner (structure only),
        // and not across structures.
        assert_eq!(
            det.simplices,
            Simplices::from_flat(2, vec![0, 1, 9, 10, 10, 11, 17, 18])
        );
        assert_eq!(det.simplex_structure, [0, 0, 0, 1]);
        assert_eq!(poly.simplices, [0, 1, 2]);
        assert_eq!(poly.parts[0].simplices, [0, 1]);
        assert_eq!(det.stats.structure_simplices, 4);
        // Labels: the copy of point 3 has its label.
        assert_eq!(det.labels[3], 0);
        assert_eq!(det.labels[25], 0);
        assert_eq!(det.labels[17], 1);
        assert_eq!(det.first_occurrence[25], 3);
    }
}
