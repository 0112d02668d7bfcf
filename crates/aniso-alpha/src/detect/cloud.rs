//! What a run knows of its cloud, worked out once and shared by every step
//! that needs it: which points are copies of an earlier one ([`Copies`]),
//! the bounding volume against which the background density is measured
//! (the scan's thresholds, the significance test, the claims' widening)
//! and the kd-tree of the distinct points (the assembly's claims).

use super::detection::position_key;
use crate::geometry::kdtree::KdTree;
use std::sync::OnceLock;

/// Which points are exact copies of an earlier point (−0 and 0 are one
/// position). A copy is one point to every step: the triangulation keeps
/// one vertex per position, and the assembly labels first occurrences.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Copies {
    /// Per point, the index of the first point at its position (itself
    /// when no earlier point is there).
    first: Vec<u32>,
    /// The first occurrences, ascending.
    distinct: Vec<u32>,
}

impl Copies {
    /// The copies among `points` (one sort of the point indices).
    pub(crate) fn of(points: &[[f64; 3]]) -> Self {
        let key = |i: u32| position_key(&points[i as usize]);
        let mut order: Vec<u32> = (0..points.len() as u32).collect();
        order.sort_unstable_by(|&a, &b| key(a).cmp(&key(b)).then(a.cmp(&b)));
        let mut first: Vec<u32> = (0..points.len() as u32).collect();
        for w in order.windows(2) {
            if key(w[0]) == key(w[1]) {
                first[w[1] as usize] = first[w[0] as usize];
            }
        }
        let distinct = (0..points.len() as u32)
            .filter(|&i| first[i as usize] == i)
            .collect();
        Copies { first, distinct }
    }

    /// `n` points known to be distinct.
    pub(crate) fn none(n: usize) -> Self {
        let first: Vec<u32> = (0..n as u32).collect();
        Copies {
            distinct: first.clone(),
            first,
        }
    }

    /// Per point, its first occurrence.
    pub(crate) fn first(&self) -> &[u32] {
        &self.first
    }

    /// The first occurrences, ascending.
    pub(crate) fn distinct(&self) -> &[u32] {
        &self.distinct
    }

    /// Whether some point is a copy.
    pub(crate) fn any(&self) -> bool {
        self.distinct.len() != self.first.len()
    }

    /// Whether point `i` is a first occurrence (true for an index past the
    /// points these copies were worked out for).
    pub(crate) fn is_first(&self, i: usize) -> bool {
        self.first.get(i).is_none_or(|&f| f as usize == i)
    }

    /// The map from each point to its first occurrence.
    pub(crate) fn into_first(self) -> Vec<u32> {
        self.first
    }
}

/// The cloud of one run with what every step shares about it.
pub(crate) struct Cloud<'a> {
    points: &'a [[f64; 3]],
    copies: &'a Copies,
    volume: f64,
    index: OnceLock<KdTree>,
    /// Set by [`Self::release_index`]: a query after it is a bug (the
    /// tree would be built twice), caught in debug builds.
    released: bool,
}

impl<'a> Cloud<'a> {
    /// `points` with their `copies`.
    pub(crate) fn new(points: &'a [[f64; 3]], copies: &'a Copies) -> Self {
        let (lo, hi) = crate::geometry::bounding_box(points);
        Cloud {
            points,
            copies,
            volume: (0..3).map(|k| (hi[k] - lo[k]).max(1e-300)).product(),
            index: OnceLock::new(),
            released: false,
        }
    }

    /// The points.
    pub(crate) fn points(&self) -> &'a [[f64; 3]] {
        self.points
    }

    /// Which of them are copies.
    pub(crate) fn copies(&self) -> &'a Copies {
        self.copies
    }

    /// The number of distinct positions.
    pub(crate) fn distinct_count(&self) -> usize {
        self.copies.distinct.len()
    }

    /// The volume of the bounding box (each side at least 1e-300): the
    /// region over which a uniform background is spread.
    pub(crate) fn volume(&self) -> f64 {
        self.volume
    }

    /// A kd-tree of the distinct points (built on the first call).
    pub(crate) fn index(&self) -> &KdTree {
        debug_assert!(!self.released, "the kd-tree queried after its release");
        self.index
            .get_or_init(|| KdTree::new(self.points, Some(self.copies.distinct.clone())))
    }

    /// Builds the kd-tree now, if it is not built yet. Called before the
    /// tasks that query it: built inside one task, the tree's own build
    /// would run on that task's thread alone, the pool's other threads
    /// waiting on it (a depth frame's widening, the first to query it,
    /// 3–4 ms shorter of 25 on two threads).
    pub(crate) fn build_index(&self) {
        self.index();
    }

    /// Frees the kd-tree (a copy of the points and their order, 36 bytes
    /// a point): the assembly's last stages, where a large part's outline
    /// peaks, do not query it (debug builds assert that nothing does).
    pub(crate) fn release_index(&mut self) {
        self.index = OnceLock::new();
        self.released = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_point_to_their_first_occurrence() {
        let pts = [
            [1.0, 2.0, 3.0],
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
            [-0.0, 0.0, -0.0],
            [5.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
        ];
        let c = Copies::of(&pts);
        assert_eq!(c.first(), &[0, 1, 0, 1, 4, 0]);
        assert_eq!(c.distinct(), &[0, 1, 4]);
        assert!(c.any());
        assert!(c.is_first(4) && !c.is_first(5) && c.is_first(9));
        let none = Copies::of(&pts[..2]);
        assert!(!none.any());
        assert_eq!(none, Copies::none(2));
        let cloud = Cloud::new(&pts, &c);
        assert_eq!(cloud.distinct_count(), 3);
        assert_eq!(cloud.volume(), 5.0 * 2.0 * 3.0);
        // The kd-tree holds first occurrences only.
        let mut near = Vec::new();
        cloud
            .index()
            .within(&[1.0, 2.0, 3.0], 0.1, |i| near.push(i));
        assert_eq!(near, [0]);
    }
}
