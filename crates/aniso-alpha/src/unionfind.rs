//! The crate's one union-find (disjoint sets over `0..n` as `u32`), used
//! by the path filter and connected components ([`crate::detect::filter`]),
//! the grouping of candidates and parts (`detect::assemble`) and the optimal α of
//! [`crate::alpha`].
//!
//! Which root a union keeps matters to callers that number or store
//! things by root, so there are two unions with fixed rules:
//! [`UnionFind::union`] (the larger set's root, the first argument's on a
//! tie) and [`UnionFind::union_min_root`] (the smaller root index). Path
//! compression (halving, in [`UnionFind::find`]) never changes a root.

/// Disjoint sets over `0..n`, with the size of each set.
#[derive(Debug, Clone, Default)]
pub(crate) struct UnionFind {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl UnionFind {
    /// `n` singletons.
    pub(crate) fn new(n: usize) -> Self {
        let mut uf = Self::default();
        uf.reset(n);
        uf
    }

    /// Back to `n` singletons, keeping the allocations.
    pub(crate) fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n as u32);
        self.size.clear();
        self.size.resize(n, 1);
    }

    /// The root of `x`'s set (with path halving).
    #[inline]
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let g = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = g;
            x = g;
        }
        x
    }

    /// Merges the sets of `a` and `b` (union by size): the root of the
    /// larger set stays the root, `a`'s on equal sizes. Whether they were
    /// two sets.
    pub(crate) fn union(&mut self, a: u32, b: u32) -> bool {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        if self.size[ra as usize] < self.size[rb as usize] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.link(rb, ra);
        true
    }

    /// Merges the sets of `a` and `b`, the smaller of the two roots
    /// staying the root (so every root is the smallest member of its set).
    /// Whether they were two sets.
    pub(crate) fn union_min_root(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.link(ra.max(rb), ra.min(rb));
        true
    }

    /// Puts the root `child` under the root `root`.
    #[inline]
    fn link(&mut self, child: u32, root: u32) {
        self.parent[child as usize] = root;
        self.size[root as usize] += self.size[child as usize];
    }

    /// The size of `x`'s set.
    pub(crate) fn size_of(&mut self, x: u32) -> u32 {
        let r = self.find(x) as usize;
        self.size[r]
    }

    /// The sets, indexed by root: the members of each (ascending) at its
    /// root's index, nothing at the other indices.
    pub(crate) fn sets(&mut self) -> Vec<Vec<u32>> {
        let n = self.parent.len();
        let mut sets: Vec<Vec<u32>> = vec![Vec::new(); n];
        for x in 0..n as u32 {
            let r = self.find(x);
            sets[r as usize].push(x);
        }
        sets
    }
}

#[cfg(test)]
mod tests {
    use super::UnionFind;

    #[test]
    fn roots_sizes_and_tie_breaks() {
        let mut uf = UnionFind::new(6);
        assert!(uf.union(3, 1)); // equal sizes: the first argument's root
        assert_eq!(uf.find(1), 3);
        assert!(uf.union(0, 1)); // {0} is smaller: 3 stays the root
        assert_eq!((uf.find(0), uf.size_of(0)), (3, 3));
        assert!(!uf.union(0, 3));
        assert!(uf.union_min_root(5, 4));
        assert_eq!(uf.find(5), 4);
        assert!(uf.union_min_root(4, 0)); // roots 4 and 3: 3 wins
        assert_eq!((uf.find(5), uf.size_of(5)), (3, 5));
        assert_eq!((uf.find(2), uf.size_of(2)), (2, 1));
        assert_eq!(
            uf.sets(),
            [vec![], vec![], vec![2], vec![0, 1, 3, 4, 5], vec![], vec![]]
        );
        uf.reset(2);
        assert_eq!((uf.find(1), uf.size_of(1)), (1, 1));
    }
}
