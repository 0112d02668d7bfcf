//! The path filter of non-significant structures (paper §4.2, docs/method.md §3) and
//! plain connected components.
//!
//! Works on k-simplices given as vertex-index arrays: edges `[u32; 2]`
//! (k = 1, faces = vertices) or triangles `[u32; 3]` (k = 2, faces =
//! edges). Vertex ids are arbitrary `u32`; the vertex order inside a simplex
//! does not matter. The input is a *set*: an entry repeated (in any vertex
//! order) is one simplex, and every copy gets its verdict.
//!
//! * The **degree** of a face is the number of simplices containing it; a
//!   face of degree ≥ 3 is a *ramification*.
//! * Two simplices are **joined** when they share a face of degree exactly 2.
//! * A **path** is a connected component of "joined"; its length is its
//!   number of simplices.
//! * [`filter_mask`]`(S, nb_c)`: for l = 1 … nb_c − 1, delete every path of
//!   length ≤ l, recompute degrees and paths, repeat at the same l until no
//!   path of length ≤ l remains, then go on to l + 1.
//!
//! Deleting a simplex only lowers face degrees, so a join between two
//! survivors is never broken (their shared face had degree 2 without the
//! deleted one) and a ramification can turn into a join: paths only merge.
//! Hence once no path of length ≤ l remains none ever reappears, and the
//! levels l at which nothing would be deleted can be skipped: the
//! implementation jumps straight to the shortest remaining path length.
//! (The naive reading is compared with this one in the tests.)
//!
//! Storage is flat: the (face key, simplex) incidences are sorted once
//! (a face key is the vertex id for k = 1, `(a << 32) | b` with a < b for
//! k = 2) into a face → simplices adjacency in CSR form; each round is a
//! union-find pass over the faces of degree 2. No hash map is used.
//!
//! ```
//! use aniso_alpha::detect::filter::{filter, paths};
//! // A chain 0-1-2-3-4-5 with a one-edge spur 2-9 at vertex 2.
//! let s = [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [2, 9]];
//! assert_eq!(paths(&s).unwrap(), vec![0, 0, 1, 1, 1, 2]); // cut at vertex 2
//! let kept = filter(&s, 2).unwrap();
//! assert_eq!(kept, vec![[0, 1], [1, 2], [2, 3], [3, 4], [4, 5]]);
//! assert_eq!(paths(&kept).unwrap(), vec![0; 5]); // one path again
//! ```

use std::fmt;

use crate::unionfind::UnionFind;

mod sealed {
    pub trait Sealed {}
    impl Sealed for [u32; 2] {}
    impl Sealed for [u32; 3] {}
}

/// An edge `[u32; 2]` or a triangle `[u32; 3]`. Sealed.
pub trait Simplex: Copy + Ord + Send + Sync + sealed::Sealed {
    /// Number of vertices (= number of faces): 2 or 3.
    const VERTICES: usize;
    /// The simplex with its vertices sorted ascending, or `None` if a vertex
    /// is repeated.
    fn canonical(self) -> Option<Self>;
    /// Key of face `i` (0 ≤ i < VERTICES) of a canonical simplex: the
    /// vertex for an edge, `(a << 32) | b` (a < b) for a triangle's edge.
    fn face_key(&self, i: usize) -> u64;
    /// `face_key >> LEAD_SHIFT` is the face's smallest vertex, and the
    /// bits below it (at most 32) the rest of the face.
    const LEAD_SHIFT: u32;
}

impl Simplex for [u32; 2] {
    const VERTICES: usize = 2;
    const LEAD_SHIFT: u32 = 0;
    fn canonical(self) -> Option<Self> {
        let [a, b] = self;
        match a.cmp(&b) {
            std::cmp::Ordering::Less => Some([a, b]),
            std::cmp::Ordering::Greater => Some([b, a]),
            std::cmp::Ordering::Equal => None,
        }
    }
    fn face_key(&self, i: usize) -> u64 {
        u64::from(self[i])
    }
}

impl Simplex for [u32; 3] {
    const VERTICES: usize = 3;
    const LEAD_SHIFT: u32 = 32;
    fn canonical(self) -> Option<Self> {
        let mut s = self;
        s.sort_unstable();
        if s[0] == s[1] || s[1] == s[2] {
            None
        } else {
            Some(s)
        }
    }
    fn face_key(&self, i: usize) -> u64 {
        let (a, b) = match i {
            0 => (self[1], self[2]),
            1 => (self[0], self[2]),
            _ => (self[0], self[1]),
        };
        (u64::from(a) << 32) | u64::from(b)
    }
}

/// Bad input to the filter.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FilterError {
    /// Simplex `index` has a repeated vertex.
    RepeatedVertex {
        /// Position in the input.
        index: usize,
    },
    /// More than `u32::MAX − 1` simplices.
    TooManySimplices(usize),
}

impl fmt::Display for FilterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::RepeatedVertex { index } => {
                write!(f, "simplex {index} has a repeated vertex")
            }
            Self::TooManySimplices(n) => write!(f, "{n} simplices: at most 2^32 − 2"),
        }
    }
}

impl std::error::Error for FilterError {}

/// Flat incidence structure of a simplex set.
pub(crate) struct Incidence {
    /// Input position → unique simplex, and unique simplex → its first
    /// input position; `None` where the input is sorted and distinct (as
    /// the union and its subsets are): both are the identity then, and
    /// the 8 bytes a simplex are not spent.
    maps: Option<(Vec<u32>, Vec<u32>)>,
    /// Number of unique simplices.
    pub(crate) n: usize,
    /// Faces of unique simplex s: `simplex_faces[s*K .. s*K+K]`.
    simplex_faces: Vec<u32>,
    /// CSR: simplices of face f are `face_simplices[face_start[f]..face_start[f+1]]`.
    face_start: Vec<u32>,
    face_simplices: Vec<u32>,
    k: usize,
}

/// The half-faces h = s·k + i (face i of simplex s) of canonical
/// simplices, sorted by (face key, h): each face's simplices in ascending
/// order. Where the keys' leading vertices are dense (fewer than the
/// half-faces), a counting sort by that vertex, then each vertex's few
/// half-faces by key: 4 bytes a half-face and a count a vertex. Elsewhere
/// (a small piece of a large cloud), (key, h) pairs sorted: 16 bytes a
/// half-face. The two orders are the same.
fn half_faces_by_key<S: Simplex>(unique: &[S]) -> Vec<u32> {
    let k = S::VERTICES;
    let m = unique.len() * k;
    let key = |h: usize| unique[h / k].face_key(h % k);
    let lead: Vec<u32> = (0..m).map(|h| (key(h) >> S::LEAD_SHIFT) as u32).collect();
    let top = lead.iter().copied().max().unwrap_or(0) as usize;
    if top >= m {
        drop(lead);
        let mut pairs: Vec<(u64, u32)> = (0..m).map(|h| (key(h), h as u32)).collect();
        pairs.sort_unstable();
        return pairs.into_iter().map(|(_, h)| h).collect();
    }
    let mut start = vec![0u32; top + 2];
    for &v in &lead {
        start[v as usize + 1] += 1;
    }
    for v in 0..=top {
        start[v + 1] += start[v];
    }
    let mut half = vec![0u32; m];
    let mut next = start.clone();
    for (h, &v) in lead.iter().enumerate() {
        let slot = &mut next[v as usize];
        half[*slot as usize] = h as u32;
        *slot += 1;
    }
    drop(next);
    drop(lead);
    // Each vertex's list is in half-face order; its key's lead part is
    // the vertex. With no other part (edges) the list is sorted by key.
    if S::LEAD_SHIFT == 0 {
        return half;
    }
    // Each vertex's few half-faces by the rest of their key, then their
    // index: packed in one u64 each (the rest of the key above, the index
    // below) and sorted as integers, each key read once rather than at
    // every comparison. In chunks of whole vertices on the pool's threads
    // when they are many.
    let rest = (1u64 << S::LEAD_SHIFT) - 1;
    let sort_vertices = |half: &mut [u32], from: usize, to: usize| {
        let base = start[from] as usize;
        let mut packed: Vec<u64> = Vec::new();
        for w in start[from..=to].windows(2) {
            let list = &mut half[w[0] as usize - base..w[1] as usize - base];
            if list.len() < 2 {
                continue;
            }
            packed.clear();
            packed.extend(
                list.iter()
                    .map(|&h| ((key(h as usize) & rest) << 32) | u64::from(h)),
            );
            packed.sort_unstable();
            for (h, p) in list.iter_mut().zip(&packed) {
                *h = *p as u32;
            }
        }
    };
    sort_by_vertex_chunks(&mut half, &start, top + 1, &sort_vertices);
    half
}

/// Half-faces from which [`half_faces_by_key`] sorts its vertices' lists
/// on the pool's threads: 2^16.
const PARALLEL_HALF_FACES: usize = 1 << 16;

/// `sort(chunk, from, to)` over chunks of `half` holding the lists of
/// vertices `from..to` (`start`: each vertex's first half-face, and the
/// end), about four chunks a thread from [`PARALLEL_HALF_FACES`].
fn sort_by_vertex_chunks(
    half: &mut [u32],
    start: &[u32],
    vertices: usize,
    sort: &(dyn Fn(&mut [u32], usize, usize) + Sync),
) {
    let threads = crate::par::threads();
    if half.len() < PARALLEL_HALF_FACES || threads < 2 {
        sort(half, 0, vertices);
        return;
    }
    // Vertex bounds of about equal numbers of half-faces.
    let pieces = 4 * threads;
    let mut bounds = vec![0usize];
    for p in 1..pieces {
        let target = (half.len() * p / pieces) as u32;
        let v = start.partition_point(|&s| s < target).min(vertices);
        if v > *bounds.last().unwrap_or(&0) {
            bounds.push(v);
        }
    }
    bounds.push(vertices);
    bounds.dedup();
    let mut chunks: Vec<(&mut [u32], usize, usize)> = Vec::new();
    let mut rest = half;
    for w in bounds.windows(2) {
        let len = (start[w[1]] - start[w[0]]) as usize;
        let (mine, tail) = rest.split_at_mut(len);
        rest = tail;
        chunks.push((mine, w[0], w[1]));
    }
    crate::par::for_each_mut(chunks, |(chunk, from, to)| sort(chunk, from, to));
}

impl Incidence {
    pub(crate) fn new<S: Simplex>(simplices: &[S]) -> Result<Self, FilterError> {
        // Incidence counts (3 per triangle) must fit u32 as well.
        if simplices.len() >= (u32::MAX / 3) as usize {
            return Err(FilterError::TooManySimplices(simplices.len()));
        }
        // Merge repeated simplices. The lists the detection passes (the
        // union and its subsets) are canonical, sorted and distinct
        // already: they are their own unique simplices, without a copy, a
        // sort or maps.
        let own: Vec<S>;
        let (unique, maps): (&[S], _) = if simplices.windows(2).all(|w| w[0] < w[1])
            && simplices.iter().all(|&s| s.canonical() == Some(s))
        {
            (simplices, None)
        } else {
            let mut canon = Vec::with_capacity(simplices.len());
            for (index, &s) in simplices.iter().enumerate() {
                canon.push(s.canonical().ok_or(FilterError::RepeatedVertex { index })?);
            }
            let mut order: Vec<u32> = (0..canon.len() as u32).collect();
            order.sort_unstable_by(|&a, &b| {
                canon[a as usize].cmp(&canon[b as usize]).then(a.cmp(&b))
            });
            let mut input_to_unique = vec![0u32; canon.len()];
            let mut unique_to_input: Vec<u32> = Vec::with_capacity(canon.len());
            let mut last: Option<S> = None;
            for &i in &order {
                let s = canon[i as usize];
                if last != Some(s) {
                    last = Some(s);
                    unique_to_input.push(i);
                }
                input_to_unique[i as usize] = (unique_to_input.len() - 1) as u32;
            }
            drop(order);
            unique_to_input.shrink_to_fit();
            own = unique_to_input.iter().map(|&i| canon[i as usize]).collect();
            drop(canon);
            (&own, Some((input_to_unique, unique_to_input)))
        };
        let k = S::VERTICES;
        let n = unique.len();
        let key = |h: u32| unique[h as usize / k].face_key(h as usize % k);
        let mut half = half_faces_by_key(unique);
        let mut simplex_faces = vec![0u32; n * k];
        let mut fill = vec![0u8; n];
        let mut face_start: Vec<u32> = Vec::with_capacity(half.len() / 2 + 2);
        let mut last_key = None;
        for (idx, h) in half.iter_mut().enumerate() {
            let key = key(*h);
            if last_key != Some(key) {
                face_start.push(idx as u32);
                last_key = Some(key);
            }
            let f = (face_start.len() - 1) as u32;
            let s = *h as usize / k;
            let slot = &mut fill[s];
            simplex_faces[s * k + *slot as usize] = f;
            *slot += 1;
            // The half-face becomes its simplex: the faces' CSR list.
            *h = s as u32;
        }
        face_start.push(half.len() as u32);
        face_start.shrink_to_fit();
        let face_simplices = half;
        Ok(Self {
            maps,
            n,
            simplex_faces,
            face_start,
            face_simplices,
            k,
        })
    }

    /// The unique simplex of input position `i`.
    #[cfg(test)]
    pub(crate) fn unique_of(&self, i: usize) -> u32 {
        self.maps.as_ref().map_or(i as u32, |m| m.0[i])
    }

    /// The first input position of unique simplex `u`.
    pub(crate) fn input_of(&self, u: usize) -> u32 {
        self.maps.as_ref().map_or(u as u32, |m| m.1[u])
    }

    /// `f(unique simplex)` for each input position, in input order.
    pub(crate) fn per_input<T>(&self, f: impl FnMut(u32) -> T) -> Vec<T> {
        match &self.maps {
            Some((to_unique, _)) => to_unique.iter().copied().map(f).collect(),
            None => (0..self.n as u32).map(f).collect(),
        }
    }

    pub(crate) fn num_faces(&self) -> usize {
        self.face_start.len() - 1
    }

    pub(crate) fn face(&self, f: usize) -> &[u32] {
        &self.face_simplices[self.face_start[f] as usize..self.face_start[f + 1] as usize]
    }

    pub(crate) fn faces_of(&self, s: usize) -> &[u32] {
        &self.simplex_faces[s * self.k..(s + 1) * self.k]
    }

    fn degrees(&self) -> Vec<u32> {
        (0..self.num_faces())
            .map(|f| self.face(f).len() as u32)
            .collect()
    }

    /// Union-find over alive simplices: joined through faces of degree 2
    /// (`only_degree_two`) or through any shared face.
    fn unite(&self, alive: &[bool], degree: &[u32], only_degree_two: bool, uf: &mut UnionFind) {
        uf.reset(self.n);
        for (f, w) in self.face_start.windows(2).enumerate() {
            if only_degree_two && degree[f] != 2 {
                continue;
            }
            let mut first = None;
            for &s in &self.face_simplices[w[0] as usize..w[1] as usize] {
                if alive[s as usize] {
                    match first {
                        None => first = Some(s),
                        Some(a) => {
                            uf.union(a, s);
                        }
                    }
                }
            }
        }
    }

    /// Maps input positions to compact component ids (in order of first
    /// appearance in the input).
    fn label_input(&self, uf: &mut UnionFind) -> Vec<u32> {
        let mut id_of_root = vec![u32::MAX; self.n];
        let mut next = 0u32;
        self.per_input(|u| {
            let r = uf.find(u) as usize;
            if id_of_root[r] == u32::MAX {
                id_of_root[r] = next;
                next += 1;
            }
            id_of_root[r]
        })
    }
}

/// The path filter's verdict per input simplex (true = kept); see the
/// module doc for the definition.
///
/// Near-linear in the number of simplices, whatever `nb_c` is. The naive
/// reading recomputes every path at every level l = 1 … nb_c − 1; here:
/// * all paths of length ≤ l are deleted at once, as the definition says,
///   and then the faces whose degree dropped to exactly 2 join their two
///   surviving simplices (union-find, paths only merge);
/// * a merged path is longer than each of the paths it joins, and those
///   survived level l, so it is longer than l: the repeat "at the same l"
///   never deletes anything, and each level is one round;
/// * paths are kept in buckets by length (below nb_c); level l deletes
///   bucket l (entries that are still a live root of that length), so a
///   level costs the simplices it deletes, not a pass over all of them.
///
/// Total: one sort to build the incidences, then O((n + nb_c)·α(n)).
///
/// # Errors
/// A simplex with a repeated vertex, or too many simplices.
pub fn filter_mask<S: Simplex>(simplices: &[S], nb_c: u32) -> Result<Vec<bool>, FilterError> {
    let inc = Incidence::new(simplices)?;
    let n = inc.n;
    let mut alive = vec![true; n];
    let mut degree = inc.degrees();
    let mut uf = UnionFind::new(0);
    inc.unite(&alive, &degree, true, &mut uf);
    if nb_c <= 1 || n == 0 {
        return Ok(inc.per_input(|u| alive[u as usize]));
    }
    let top = nb_c as usize; // lengths 1 ..= nb_c − 1 can be deleted
                             // Members of each path (linked lists through `next`, by root).
    let mut tail: Vec<u32> = (0..n as u32).collect();
    let mut next: Vec<u32> = vec![u32::MAX; n];
    let mut bucket: Vec<Vec<u32>> = vec![Vec::new(); top];
    for s in 0..n as u32 {
        let r = uf.find(s);
        if r != s {
            // Append s to r's list.
            next[tail[r as usize] as usize] = s;
            tail[r as usize] = s;
        }
    }
    for s in 0..n as u32 {
        if uf.find(s) == s {
            let len = uf.size_of(s) as usize;
            if len < top {
                bucket[len].push(s);
            }
        }
    }
    let mut doomed: Vec<u32> = Vec::new();
    let mut touched: Vec<u32> = Vec::new();
    for l in 1..top {
        // The live paths of length exactly l (shorter ones went before).
        let roots = std::mem::take(&mut bucket[l]);
        doomed.clear();
        for r in roots {
            if alive[r as usize] && uf.find(r) == r && uf.size_of(r) as usize == l {
                let mut s = r;
                loop {
                    doomed.push(s);
                    if next[s as usize] == u32::MAX {
                        break;
                    }
                    s = next[s as usize];
                }
            }
        }
        if doomed.is_empty() {
            continue;
        }
        // Delete them all at once, then join across the faces left with
        // degree 2.
        touched.clear();
        for &s in &doomed {
            alive[s as usize] = false;
            for &f in inc.faces_of(s as usize) {
                degree[f as usize] -= 1;
                if degree[f as usize] == 2 {
                    touched.push(f);
                }
            }
        }
        for &f in &touched {
            if degree[f as usize] != 2 {
                continue;
            }
            let mut pair = inc
                .face(f as usize)
                .iter()
                .copied()
                .filter(|&s| alive[s as usize]);
            let (Some(a), Some(b)) = (pair.next(), pair.next()) else {
                continue;
            };
            let (ra, rb) = (uf.find(a), uf.find(b));
            if ra == rb {
                continue;
            }
            uf.union(ra, rb);
            let root = uf.find(ra);
            let other = if root == ra { rb } else { ra };
            // Concatenate the member lists under the new root.
            next[tail[root as usize] as usize] = other;
            tail[root as usize] = tail[other as usize];
            let len = uf.size_of(root) as usize;
            if len < top {
                bucket[len].push(root);
            }
        }
    }
    Ok(inc.per_input(|u| alive[u as usize]))
}

/// The simplices kept by [`filter_mask`], in input order.
pub fn filter<S: Simplex>(simplices: &[S], nb_c: u32) -> Result<Vec<S>, FilterError> {
    let mask = filter_mask(simplices, nb_c)?;
    Ok(simplices
        .iter()
        .zip(mask)
        .filter_map(|(&s, keep)| keep.then_some(s))
        .collect())
}

/// Path id of each input simplex (components of "joined": sharing a face
/// of degree exactly 2), ids 0, 1, … in order of first appearance.
pub fn paths<S: Simplex>(simplices: &[S]) -> Result<Vec<u32>, FilterError> {
    let inc = Incidence::new(simplices)?;
    let alive = vec![true; inc.n];
    let degree = inc.degrees();
    let mut uf = UnionFind::new(0);
    inc.unite(&alive, &degree, true, &mut uf);
    Ok(inc.label_input(&mut uf))
}

/// Plain connected components (triangles joined by any shared edge, edges
/// by any shared vertex), ids 0, 1, … in order of first appearance.
///
/// ```
/// use aniso_alpha::detect::filter::components;
/// let s = [[0, 1, 2], [5, 6, 7], [1, 2, 3], [1, 2, 4]];
/// assert_eq!(components(&s).unwrap(), vec![0, 1, 0, 0]);
/// ```
pub fn components<S: Simplex>(simplices: &[S]) -> Result<Vec<u32>, FilterError> {
    let inc = Incidence::new(simplices)?;
    let alive = vec![true; inc.n];
    let mut uf = UnionFind::new(0);
    inc.unite(&alive, &[], false, &mut uf);
    Ok(inc.label_input(&mut uf))
}

/// Keeps the simplices of connected components ([`components`]) holding at
/// least `min_size` distinct simplices: the final clean-up of the union of
/// all orientations (docs/method.md §4), which must not use the path filter.
///
/// ```
/// use aniso_alpha::detect::filter::component_size_mask;
/// let s = [[0, 1], [1, 2], [5, 6]];
/// assert_eq!(component_size_mask(&s, 2).unwrap(), vec![true, true, false]);
/// ```
pub fn component_size_mask<S: Simplex>(
    simplices: &[S],
    min_size: u32,
) -> Result<Vec<bool>, FilterError> {
    let inc = Incidence::new(simplices)?;
    let alive = vec![true; inc.n];
    let mut uf = UnionFind::new(0);
    inc.unite(&alive, &[], false, &mut uf);
    Ok(inc.per_input(|u| uf.size_of(u) >= min_size))
}

#[cfg(test)]
mod tests;
