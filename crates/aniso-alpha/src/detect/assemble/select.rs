//! The parts kept across the levels of a scale ladder (docs/method.md §8,
//! "Sparse structures"): every level was assembled apart, and its parts
//! passed the significance test at their own scale. The same structure is
//! usually found at several levels, as parts that share most of their
//! points; chance parts of a coarse level can also take in the points of
//! true structures with background around them. So the parts are taken
//! most significant first (lowest log₁₀ NFA; then larger, then by first
//! point), each keeping the points no earlier part took (the exclusion
//! principle of a-contrario detection, Desolneux, Moisan & Morel, 2008):
//!
//! * a part none of whose points is taken stays as it is;
//! * a part more than half of whose points are taken is the same
//!   detection as the earlier parts (a majority), and goes;
//! * otherwise the part keeps its other points, is refitted on them, and
//!   stays only if it has at least `min_vertices` of them and, with the
//!   significance test on, is still significant on its own: what is left
//!   of a chance part that crossed a true structure is background.

use super::super::cloud::Cloud;
use super::super::detection::Primitive;
use super::super::regime::Regime;
use super::claims::Claims;
use super::significance;
use super::{Draft, Level, Shape};

/// The levels' candidates, claims and unions joined, and their parts kept
/// by the exclusion principle (module doc).
pub(super) fn across_levels<S: Shape>(
    levels: Vec<Level<S>>,
    cloud: &Cloud<'_>,
    regime: &Regime,
    min_vertices: usize,
) -> Level<S> {
    let mut cands = Vec::new();
    let mut claims = Vec::new();
    let mut offsets = Vec::new();
    let mut parts: Vec<Draft> = Vec::new();
    let mut kept: Vec<S> = Vec::new();
    for l in levels {
        let o = cands.len();
        offsets.push(o as u32);
        parts.extend(l.parts.into_iter().map(|mut p| {
            p.cand += o;
            p.pieces.iter_mut().for_each(|c| *c += o);
            p
        }));
        cands.extend(l.cands);
        claims.push(l.claims);
        kept.extend(l.kept);
    }
    kept.sort_unstable();
    kept.dedup();
    let claims = Claims::joined(claims, &offsets);
    let parts = exclusion::<S>(parts, &cands, cloud, regime, min_vertices);
    Level {
        cands,
        claims,
        parts,
        kept,
    }
}

/// The parts kept by the exclusion principle (module doc), in the order
/// they were taken.
fn exclusion<S: Shape>(
    mut parts: Vec<Draft>,
    cands: &[super::Candidate],
    cloud: &Cloud<'_>,
    regime: &Regime,
    min_vertices: usize,
) -> Vec<Draft> {
    let points = cloud.points();
    parts.sort_by(|a, b| {
        a.log10_nfa
            .total_cmp(&b.log10_nfa)
            .then(b.members.len().cmp(&a.members.len()))
            .then(a.members[0].cmp(&b.members[0]))
    });
    let mut taken = vec![false; points.len()];
    let mut out: Vec<Draft> = Vec::with_capacity(parts.len());
    for p in parts {
        let left: Vec<u32> = p
            .members
            .iter()
            .copied()
            .filter(|&v| !taken[v as usize])
            .collect();
        let kept = if left.len() == p.members.len() {
            Some(p)
        } else if 2 * left.len() < p.members.len() || left.len() < min_vertices.max(S::K + 1) {
            None
        } else {
            rest_of::<S>(p, left, cands, cloud, regime)
        };
        if let Some(p) = kept {
            for &v in &p.members {
                taken[v as usize] = true;
            }
            out.push(p);
        }
    }
    out
}

/// Part `p` reduced to its points `left`, refitted, if it is still
/// significant (with the test on).
fn rest_of<S: Shape>(
    p: Draft,
    left: Vec<u32>,
    cands: &[super::Candidate],
    cloud: &Cloud<'_>,
    regime: &Regime,
) -> Option<Draft> {
    let fit = S::fit(cloud.points(), &left);
    if matches!(fit, Primitive::None) {
        return None;
    }
    let mut one = vec![Draft {
        members: left,
        fit,
        ..p
    }];
    if let Some(log10_epsilon) = regime.significance() {
        significance::reject::<S>(&mut one, cands, cloud, log10_epsilon);
    }
    one.pop()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::cloud::Copies;
    use crate::detect::StructureKind;

    /// A part of the points `members` fitted as a line, its candidate
    /// numbered `cand` (τ 0.5, cell 5), with log₁₀ NFA `nfa`.
    fn line_part(
        pts: &[[f64; 3]],
        members: Vec<u32>,
        cand: usize,
        nfa: f64,
    ) -> (Draft, super::super::Candidate) {
        let (mut d, c) = Draft::line(pts, members, cand, (0.5, 5.0));
        d.log10_nfa = nfa;
        (d, c)
    }

    #[test]
    fn the_most_significant_part_wins_and_what_a_chance_part_keeps_is_tested_again() {
        // 2,000 background points in a 100-unit cube and 30 aligned points.
        let (pts, n) = super::super::cube_with_a_line(5);
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        let regime = Regime::new(StructureKind::Lines, Some(1.0), false, None);
        let line: Vec<u32> = (n..n + 30).collect();
        // The line, found at a fine level.
        let (a, ca) = line_part(&pts, line.clone(), 0, -40.0);
        // The same line at a coarser level, less significant, with two of
        // its points missing: a majority is taken, it goes.
        let (b, cb) = line_part(&pts, line[2..].to_vec(), 1, -30.0);
        // A chance part of a coarse level that crossed the line: 12 of
        // its points and 12 background ones. What it keeps is background,
        // not significant on its own: it goes too.
        let mut mixed: Vec<u32> = line[..12].to_vec();
        mixed.extend(0..12u32);
        mixed.sort_unstable();
        let (c, cc) = line_part(&pts, mixed, 2, -5.0);
        let parts = exclusion::<[u32; 2]>(vec![c, b, a], &[ca, cb, cc], &cloud, &regime, 5);
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].members, line);
        assert_eq!(parts[0].cand, 0);
        // Without the test, the chance part's rest stays (it is checked
        // only for its size).
        let (a, ca) = line_part(&pts, line.clone(), 0, -40.0);
        let mut mixed: Vec<u32> = line[..12].to_vec();
        mixed.extend(0..12u32);
        mixed.sort_unstable();
        let (c, cc) = line_part(&pts, mixed, 1, -5.0);
        let paper = Regime::new(StructureKind::Lines, None, false, None);
        let parts = exclusion::<[u32; 2]>(vec![c, a], &[ca, cc], &cloud, &paper, 5);
        assert_eq!(parts.len(), 2);
        assert_eq!(parts[1].members, (0..12).collect::<Vec<u32>>());
    }
}
