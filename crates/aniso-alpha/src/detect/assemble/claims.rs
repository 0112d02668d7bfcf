//! Stage 3 of the assembly (docs/method.md §4): the points each candidate
//! claims, the merging of candidates that are one primitive, the
//! resolution of points claimed twice, and the refit.
//!
//! A point within a candidate's claim radius of its primitive and over its
//! footprint claims it; with normals given, a point claims a plane only if
//! its normal agrees with the plane's ([`NORMAL_AGREEMENT_COS`]).
//! Candidates that are one primitive ([`Shape::same`]) and share claimed
//! points merge, until none do (these rounds ask only which candidates
//! claim each point: [`Sharing`], without the distances); a candidate
//! that joins a group merged so far must be one primitive with the group
//! too (the fit of its candidates' seeds, [`SoFar`]), so that a small
//! piece lying where two planes meet (a shallow roof's ridge, within the
//! part angle of both faces) joins one of them and does not chain the two
//! into one; then each point goes to the candidate it is nearest to
//! (parts are disjoint), the candidates are refitted on
//! their members, and claim again. A merged candidate claims with the
//! widest radius of its pieces, except the radius of a piece it absorbed
//! ([`absorbed`]: a coarser piece on its own points), which also links it
//! to nothing else: a piece found at an edge's coarse scale would
//! otherwise widen a wall's radius to take the panes recessed behind it.

use super::super::cloud::Cloud;
use super::super::detection::Primitive;
use super::footprint::for_near_in;
use super::moments::Moments;
use super::same::{absorbed, Piece};
use super::{part_of_candidates, Candidate, Draft, Footprint, Shape};
use crate::par::map_each;
use crate::unionfind::UnionFind;
use std::collections::{HashMap, HashSet};

/// With normals given, a point joins a plane only if |n_p · n| is at least
/// this: 0.8, an angle of 36.9°. It is the default `normal_threshold` of
/// Easy3D's and PolyFit's Efficient RANSAC (Schnabel et al. 2007);
/// CGAL's implementation defaults to 0.9 (25.8°).
///
/// The test only needs to keep out surfaces that run across the plane
/// within its claim radius: window frames, ledges, the edges of walls, all
/// at 60–90°. The looser of the two defaults keeps the points of noisy
/// planes. On CGAL's building scan, whose labels were made with the
/// scan's normals, 10% of each noisy wall's labelled points have normals
/// 20–28° or more off their plane, up to 37–41°.
///
/// Measured on that scan (its own normals): F1 0.907 at 0.8, 0.891 at 0.9.
/// The labels follow 0.8 too, so this choice suits that scan's labelling
/// rule (docs/method.md §4).
pub(crate) const NORMAL_AGREEMENT_COS: f64 = 0.8;

/// The fewest footprint blocks in one slice of a candidate's claims
/// ([`Claims::of`]): 2. A block is 8 × 8 cells or more, a few thousand
/// points of a dense plane, so two are enough work to be worth a task.
/// Slices are longer where the candidates' blocks are many for the
/// threads (about four slices a thread in all): a scan's ground
/// (hundreds of blocks) is cut into a few slices a thread.
const CLAIM_BLOCKS: usize = 2;

/// A claim: (point, candidate, distance to the candidate's primitive).
type Claim = (u32, u32, f64);

/// Every claim of a run's candidates, sorted by point, then candidate (a
/// candidate claims a point at most once).
pub(super) struct Claims(Vec<Claim>);

impl Claims {
    /// The claims of `cands` on the points of `cloud`, gated by the given
    /// `normals` (unit, zero where missing) for planes ([`claim_slices`]);
    /// a point claimed by two slices of one candidate is kept once. The
    /// claims do not depend on the slicing.
    pub(super) fn of(cands: &[Candidate], cloud: &Cloud<'_>, normals: Option<&[[f32; 3]]>) -> Self {
        let all: Vec<u32> = (0..cands.len() as u32).collect();
        let per_slice = claim_slices(cands, &all, cloud, normals, |i, d| (i, d));
        // Each slice reports a point at most once, and two slices of a
        // candidate never the same point ([`for_near_in`]): no duplicate.
        let claims = by_point_then_candidate(
            cloud.points().len(),
            per_slice,
            |c| c.0,
            |c, (i, d)| (i, c, d),
        );
        Claims(claims)
    }

    /// Claims already sorted by point, then candidate.
    #[cfg(test)]
    pub(super) fn from_sorted(claims: Vec<Claim>) -> Self {
        Claims(claims)
    }

    /// The claims of several runs' candidates, the candidates of run i
    /// numbered from `offsets[i]` on.
    pub(super) fn joined(runs: Vec<Claims>, offsets: &[u32]) -> Self {
        let mut all: Vec<Claim> = runs
            .into_iter()
            .zip(offsets)
            .flat_map(|(c, &o)| c.0.into_iter().map(move |(p, c, d)| (p, c + o, d)))
            .collect();
        all.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)));
        Claims(all)
    }

    /// The claims of each claimed point, point after point.
    fn by_point(&self) -> impl Iterator<Item = &[Claim]> {
        self.0.chunk_by(|a, b| a.0 == b.0)
    }

    /// The distinct pairs (a < b) of what `of` maps two candidates claimed
    /// by one point to, sorted; `None` and equal images are left out
    /// ([`shared_pairs`]).
    pub(super) fn shared(&self, of: impl Fn(u32) -> Option<u32>) -> Vec<(u32, u32)> {
        shared_pairs(self.by_point().map(|h| h.iter().map(|c| c.1)), of)
    }

    /// The members of each of `n` candidates: every claimed point goes to
    /// the candidate nearest to it (the smaller index on a tie).
    pub(super) fn resolve(&self, n: usize) -> Vec<Vec<u32>> {
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); n];
        for here in self.by_point() {
            let best = nearest(here.iter()).map_or(0, |c| c.1);
            members[best as usize].push(here[0].0);
        }
        members
    }
}

/// The nearest of `claims` (of one point), the smaller candidate on a tie.
fn nearest<'a>(claims: impl Iterator<Item = &'a Claim>) -> Option<&'a Claim> {
    claims.min_by(|a, b| a.2.total_cmp(&b.2).then(a.1.cmp(&b.1)))
}

/// Which candidates claim each point, without the distances: what the
/// merging rounds of [`settle`] ask (which candidates share a point).
/// Held as the distinct sets of candidates that claim one point, each
/// sorted, and per point the index of its set, found by folding the
/// claims into a trie of candidate sets ([`Sharing::of`]): 4 bytes a point
/// and 16 a distinct set prefix, where a list of (point, candidate) pairs
/// took 8 bytes a claim (11 claims a point on a depth frame, before the
/// merge).
struct Sharing {
    /// The distinct sets (the empty one and sets of one included).
    sets: Sets,
    /// Per point, the index of its set in `sets`.
    at: Vec<u32>,
}

/// Sets of candidates stored one after another in one buffer: a round
/// renumbers them all in one pass, with no allocation per set (a point of
/// a natural terrain's scan has a set of its own: 260,352 sets on PDAL's
/// `lone-star.laz`).
#[derive(Default)]
struct Sets {
    /// Where each set ends in `items`.
    ends: Vec<usize>,
    /// The sets' candidates, set after set.
    items: Vec<u32>,
}

impl Sets {
    /// The number of sets.
    fn len(&self) -> usize {
        self.ends.len()
    }

    /// Set `k`.
    fn get(&self, k: usize) -> &[u32] {
        let from = if k == 0 { 0 } else { self.ends[k - 1] };
        &self.items[from..self.ends[k]]
    }

    /// Every set, in order.
    fn iter(&self) -> impl Iterator<Item = &[u32]> + '_ {
        (0..self.len()).map(|k| self.get(k))
    }

    /// Appends the set of `candidates`.
    fn push(&mut self, candidates: impl IntoIterator<Item = u32>) {
        self.items.extend(candidates);
        self.ends.push(self.items.len());
    }
}

impl Sharing {
    /// The distinct sets of candidates of [`Claims::of`] at a point.
    ///
    /// The claim lists come in candidate order, and a candidate claims a
    /// point at most once, so each point's set grows in increasing
    /// candidate order: a path down a trie whose nodes are sorted sets.
    /// A node caches its child for the candidate being folded (`child`,
    /// stamped with the candidate), so that each claim costs two array
    /// reads, no hashing.
    fn of(cands: &[Candidate], cloud: &Cloud<'_>, normals: Option<&[[f32; 3]]>) -> Self {
        let all: Vec<u32> = (0..cands.len() as u32).collect();
        let per_slice = claim_slices(cands, &all, cloud, normals, |i, _| i);
        let (sets, at) = distinct_sets(cloud.points().len(), per_slice);
        Sharing { sets, at }
    }

    /// The distinct pairs (a < b) of candidates claiming one point, of
    /// which at least one is `changed`, sorted.
    ///
    /// Each changed candidate a gathers the candidates of the sets that
    /// hold it, each once (a stamp per candidate), from an index of the
    /// sets by candidate: the work is the sizes of the sets that hold a
    /// changed candidate, once per changed member, with no list of
    /// repeated pairs to sort (a point's set on a dense depth frame holds
    /// 10–30 candidates, and the pairs of every set were most of a
    /// round's time).
    fn shared(&self, changed: &[bool]) -> Vec<(u32, u32)> {
        let n = changed.len();
        let shared_sets = || self.sets.iter().filter(|s| s.len() > 1);
        let mut start = vec![0usize; n + 1];
        for set in shared_sets() {
            for &c in set.iter() {
                start[c as usize + 1] += 1;
            }
        }
        for c in 0..n {
            start[c + 1] += start[c];
        }
        let mut holds = vec![0u32; start[n]];
        let mut next = start.clone();
        for (k, set) in shared_sets().enumerate() {
            for &c in set.iter() {
                holds[next[c as usize]] = k as u32;
                next[c as usize] += 1;
            }
        }
        drop(next);
        let sets: Vec<&[u32]> = shared_sets().collect();
        let firsts: Vec<u32> = (0..n as u32).filter(|&a| changed[a as usize]).collect();
        let per = crate::par::map_ranges(
            firsts.len(),
            || vec![u32::MAX; n],
            |stamp, i| {
                let a = firsts[i];
                let mut with: Vec<u32> = Vec::new();
                for &k in &holds[start[a as usize]..start[a as usize + 1]] {
                    for &b in sets[k as usize] {
                        // A pair of two changed candidates is the smaller's.
                        let mine = b != a && (b > a || !changed[b as usize]);
                        if mine && stamp[b as usize] != a {
                            stamp[b as usize] = a;
                            with.push(b);
                        }
                    }
                }
                with
            },
        );
        let mut pairs: Vec<(u32, u32)> = firsts
            .iter()
            .zip(per)
            .flat_map(|(&a, with)| with.into_iter().map(move |b| (a.min(b), a.max(b))))
            .collect();
        crate::par::sort_unstable(&mut pairs);
        pairs
    }

    /// The sharing of the candidates `cands` that a round of merging made
    /// from the candidates of `self`: `kept[c]` is the new index of an old
    /// candidate c kept as it was (`None`: merged into another), and
    /// `changed` flags the new candidates made by a merge. A kept
    /// candidate claims what it claimed, so only the changed ones claim
    /// again ([`claim_slices`]); each point's set is its old one renumbered
    /// without the merged candidates, with the changed ones that claim it.
    /// The same sets as [`Sharing::of`] on `cands`.
    fn after(
        self,
        cands: &[Candidate],
        kept: &[Option<u32>],
        changed: &[bool],
        cloud: &Cloud<'_>,
        normals: Option<&[[f32; 3]]>,
    ) -> Self {
        let which: Vec<u32> = (0..cands.len() as u32)
            .filter(|&c| changed[c as usize])
            .collect();
        let mut fresh: Vec<(u32, u32)> = claim_slices(cands, &which, cloud, normals, |i, _| i)
            .into_iter()
            .flat_map(|(c, list)| list.into_iter().map(move |p| (p, c)))
            .collect();
        crate::par::sort_unstable(&mut fresh);
        // The sets some point holds, renumbered: kept candidates keep their
        // order, so each stays sorted (two may become equal, which costs
        // their pairs nothing: [`Sharing::shared`] gives each pair once).
        let mut at = self.at;
        let mut sets = Sets::default();
        sets.items.reserve(self.sets.items.len());
        for k in used_in_order(&mut at, self.sets.len()) {
            let old = self.sets.get(k as usize);
            sets.push(old.iter().filter_map(|&c| kept[c as usize]));
        }
        drop(self.sets);
        // The points the changed candidates claim: their sets, each new set
        // once.
        let mut ids: HashMap<Box<[u32]>, u32> = HashMap::new();
        let mut set: Vec<u32> = Vec::new();
        for here in fresh.chunk_by(|a, b| a.0 == b.0) {
            let p = here[0].0 as usize;
            set.clear();
            set.extend_from_slice(sets.get(at[p] as usize));
            set.extend(here.iter().map(|&(_, c)| c));
            set.sort_unstable();
            at[p] = match ids.get(set.as_slice()) {
                Some(&k) => k,
                None => {
                    let k = sets.len() as u32;
                    sets.push(set.iter().copied());
                    ids.insert(set.as_slice().into(), k);
                    k
                }
            };
        }
        Sharing { sets, at }
    }
}

/// The distinct sets of candidates that claim one of `n` points, each
/// sorted (the empty set and sets of one included), and per point the
/// index of its set, from lists of claimed points in candidate order (a
/// candidate's, or one slice of a candidate's; each point at most once a
/// candidate): [`Sharing::of`]'s trie. Each list is freed once folded.
fn distinct_sets(n: usize, lists: Vec<(u32, Vec<u32>)>) -> (Sets, Vec<u32>) {
    const NONE: u32 = u32::MAX;
    // Node 0 is the empty set; a node is (parent, candidate).
    let mut at = vec![0u32; n];
    let mut nodes: Vec<(u32, u32)> = vec![(NONE, NONE)];
    let mut child: Vec<(u32, u32)> = vec![(NONE, 0)];
    for (c, list) in lists {
        for p in list {
            let cur = at[p as usize] as usize;
            if child[cur].0 != c {
                child[cur] = (c, nodes.len() as u32);
                nodes.push((cur as u32, c));
                child.push((NONE, 0));
            }
            at[p as usize] = child[cur].1;
        }
    }
    drop(child);
    let mut sets = Sets::default();
    let mut set = Vec::new();
    for k in used_in_order(&mut at, nodes.len()) {
        set.clear();
        let mut j = k;
        while j != 0 {
            set.push(nodes[j as usize].1);
            j = nodes[j as usize].0;
        }
        sets.push(set.iter().rev().copied());
    }
    (sets, at)
}

/// The entries of a table of `n` that `at` refers to, ascending, with
/// `at` renumbered to their positions in that list.
fn used_in_order(at: &mut [u32], n: usize) -> Vec<u32> {
    const UNUSED: u32 = u32::MAX;
    let mut index = vec![UNUSED; n];
    for &k in at.iter() {
        index[k as usize] = 0;
    }
    let mut used = Vec::new();
    for (k, i) in index.iter_mut().enumerate() {
        if *i != UNUSED {
            *i = used.len() as u32;
            used.push(k as u32);
        }
    }
    for k in at.iter_mut() {
        *k = index[*k as usize];
    }
    used
}

/// The (candidate, first block, end block) of each slice of the
/// candidates' footprint blocks (`blocks`: how many each has), in order:
/// at least [`CLAIM_BLOCKS`] blocks a slice, longer where the blocks are
/// many for the threads (about four slices a thread in all).
fn slices_of(blocks: &[usize]) -> Vec<(usize, usize, usize)> {
    let total: usize = blocks.iter().sum();
    let size = CLAIM_BLOCKS.max(total.div_ceil(4 * crate::par::threads()));
    blocks
        .iter()
        .enumerate()
        .flat_map(|(ci, &b)| {
            (0..b.max(1))
                .step_by(size)
                .map(move |s| (ci, s, (s + size).min(b)))
        })
        .collect()
}

/// The claims of the candidates `which` (ascending indices into `cands`)
/// slice by slice ([`slices_of`] of their footprint blocks), each claim
/// made by `make(point, distance)`, with the candidate of each slice: in
/// parallel over the slices (so that one large candidate, a scan's
/// ground, is shared between threads), each point once ([`for_near_in`]).
fn claim_slices<T: Send>(
    cands: &[Candidate],
    which: &[u32],
    cloud: &Cloud<'_>,
    normals: Option<&[[f32; 3]]>,
    make: impl Fn(u32, f64) -> T + Sync,
) -> Vec<(u32, Vec<T>)> {
    // Counted first, each slice's boxes made by its own task: the boxes
    // of every candidate at once were the largest buffer of the claims.
    let counts: Vec<usize> = which
        .iter()
        .map(|&c| {
            let c = &cands[c as usize];
            c.foot.near_block_count(c.tau)
        })
        .collect();
    let slices = slices_of(&counts);
    map_each(slices.len(), |k| {
        let (wi, from, to) = slices[k];
        let ci = which[wi] as usize;
        let c = &cands[ci];
        let agrees = normal_agreement(&c.fit, normals);
        let mut claims = Vec::new();
        for_near_in(
            &c.fit,
            &c.foot,
            c.tau,
            cloud.index(),
            &c.foot.near_blocks_in(c.tau, (from, to)),
            &mut |i, d| {
                if agrees(i) {
                    claims.push(make(i, d));
                }
            },
        );
        // Held until every slice is done: no growth slack.
        claims.shrink_to_fit();
        (ci as u32, claims)
    })
}

/// The distinct pairs (a < b) of what `of` maps two candidates of one
/// point's set (`sets`: the candidates claiming each point, point after
/// point) to, sorted; `None` and equal images are left out. Every point
/// of a large plane repeats the same few candidates (11 claims a point on
/// a depth frame, before the merge), so each distinct set of images gives
/// its pairs once, and the list is deduplicated whenever it has doubled:
/// its memory follows the distinct pairs, not the claims.
fn shared_pairs<I: Iterator<Item = u32>>(
    sets: impl Iterator<Item = I>,
    of: impl Fn(u32) -> Option<u32>,
) -> Vec<(u32, u32)> {
    const FIRST_DEDUP: usize = 1 << 12;
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let mut dedup_at = FIRST_DEDUP;
    let mut seen: HashSet<Box<[u32]>> = HashSet::new();
    let mut set: Vec<u32> = Vec::new();
    for here in sets {
        set.clear();
        set.extend(here.filter_map(&of));
        if set.len() < 2 {
            continue;
        }
        set.sort_unstable();
        set.dedup();
        if set.len() < 2 || seen.contains(set.as_slice()) {
            continue;
        }
        seen.insert(set.as_slice().into());
        for (k, &x) in set.iter().enumerate() {
            pairs.extend(set[k + 1..].iter().map(|&y| (x, y)));
        }
        if pairs.len() >= dedup_at {
            pairs.sort_unstable();
            pairs.dedup();
            dedup_at = (2 * pairs.len()).max(FIRST_DEDUP);
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// Lists of claims in candidate order (a candidate's, or one slice of a
/// candidate's, each point at most once a list, each with its candidate)
/// on `n` points, ordered by point (`point_of`), then candidate, each
/// claim written as `out(candidate, claim)`: a counting sort by point,
/// which keeps the lists' order within each point. Each list is freed
/// once placed.
fn by_point_then_candidate<T, U: Copy + Default>(
    n: usize,
    per_cand: Vec<(u32, Vec<T>)>,
    point_of: impl Fn(&T) -> u32,
    out: impl Fn(u32, T) -> U,
) -> Vec<U> {
    let mut start = vec![0usize; n + 1];
    for (_, c) in &per_cand {
        for x in c {
            start[point_of(x) as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut sorted: Vec<U> = vec![U::default(); start[n]];
    for (cand, c) in per_cand {
        for x in c {
            let at = &mut start[point_of(&x) as usize];
            sorted[*at] = out(cand, x);
            *at += 1;
        }
    }
    sorted
}

/// Whether point i's given normal lets it join `fit`: true without
/// normals, for a point whose normal is missing (zero), and for anything
/// but a plane; otherwise |n_i · n| ≥ [`NORMAL_AGREEMENT_COS`].
fn normal_agreement<'a>(
    fit: &Primitive,
    normals: Option<&'a [[f32; 3]]>,
) -> impl Fn(u32) -> bool + 'a {
    let plane = match (fit, normals) {
        (Primitive::Plane(f), Some(n)) => Some((f.normal, n)),
        _ => None,
    };
    let cos = NORMAL_AGREEMENT_COS;
    move |i| {
        plane.is_none_or(|(p, normals)| {
            let n = normals[i as usize];
            n == [0.0; 3]
                || (f64::from(n[0]) * p[0] + f64::from(n[1]) * p[1] + f64::from(n[2]) * p[2]).abs()
                    >= cos
        })
    }
}

/// The claims of `cands` once settled (module doc): the candidates after
/// merging and refit, and their final claims.
pub(super) fn settle<S: Shape>(
    mut cands: Vec<Candidate>,
    cloud: &Cloud<'_>,
    normals: Option<&[[f32; 3]]>,
    angle_deg: f64,
) -> (Vec<Candidate>, Claims) {
    let points = cloud.points();
    cloud.build_index();
    // The merging rounds ask only which candidates share points.
    // A pair of candidates that a round left apart, neither of them
    // changed since, would be left apart again: each round tests only the
    // pairs with a candidate its merges made, and its sharing claims again
    // for those alone.
    let mut sharing = Sharing::of(&cands, cloud, normals);
    let mut changed = vec![true; cands.len()];
    while let Some(groups) = duplicates::<S>(&cands, &sharing, &changed, angle_deg, points) {
        let (next, kept, made) = merged::<S>(cands, &groups, points);
        cands = next;
        changed = made;
        sharing = sharing.after(&cands, &kept, &changed, cloud, normals);
    }
    drop(sharing);
    let members = Claims::of(&cands, cloud, normals).resolve(cands.len());
    refit::<S>(&mut cands, &members, points);
    drop(members);
    let claims = Claims::of(&cands, cloud, normals);
    (cands, claims)
}

/// Groups of candidates to merge: per root, its candidates (empty
/// elsewhere), and per candidate whether another absorbed it.
struct Groups {
    sets: Vec<Vec<u32>>,
    absorbed: Vec<bool>,
}

/// The groups of candidates that are one primitive and share claimed
/// points (of which one at least is `changed`: the others were tested
/// alike before), or `None` when no two are. An absorbed candidate
/// ([`absorbed`]) joins the one that absorbs it and no other. Two candidates of which
/// one is in a group already join only if their groups are one primitive
/// too ([`SoFar`]): the pairwise test alone chains two faces of a shallow
/// roof, 14° apart, through a four-point piece on their ridge whose plane
/// is within the part angle of both.
fn duplicates<S: Shape>(
    cands: &[Candidate],
    sharing: &Sharing,
    changed: &[bool],
    angle_deg: f64,
    points: &[[f64; 3]],
) -> Option<Groups> {
    let mut uf = UnionFind::new(cands.len());
    let mut was_absorbed = vec![false; cands.len()];
    let mut so_far = SoFar::new(cands.len());
    let mut merged = false;
    for (a, b) in sharing.shared(changed) {
        let (ra, rb) = (uf.find(a), uf.find(b));
        if was_absorbed[a as usize] || was_absorbed[b as usize] || ra == rb {
            continue;
        }
        let (pa, pb) = (cands[a as usize].piece(), cands[b as usize].piece());
        let same = S::same(pa, pb, angle_deg, points)
            && (so_far.alone(ra, rb)
                || S::same(
                    so_far.piece(ra, cands),
                    so_far.piece(rb, cands),
                    angle_deg,
                    points,
                ));
        if same {
            if let Some(a_is) = absorbed(pa, pb, points) {
                was_absorbed[if a_is { a } else { b } as usize] = true;
            }
            uf.union_min_root(a, b);
            so_far.join::<S>(ra, rb, uf.find(a), cands, &was_absorbed, points);
            merged = true;
        }
    }
    merged.then(|| Groups {
        sets: uf.sets(),
        absorbed: was_absorbed,
    })
}

/// The groups of two candidates or more merged so far by [`duplicates`],
/// at their roots, each as one piece: its candidates' seeds (a point in
/// two of them twice), the fit of those seeds (from their moments, so
/// that a group grows in O(1) besides its seeds), and the widest claim
/// radius of its candidates not absorbed: the primitive the group would be
/// if merged now, as stage 5 tests its groups of parts.
struct SoFar {
    groups: Vec<Option<Group>>,
}

/// One group of [`SoFar`].
struct Group {
    members: Vec<u32>,
    seeds: Vec<u32>,
    moments: Moments,
    fit: Primitive,
    tau: f64,
}

impl SoFar {
    /// Every candidate alone.
    fn new(n: usize) -> Self {
        SoFar {
            groups: (0..n).map(|_| None).collect(),
        }
    }

    /// Whether the roots `a` and `b` are candidates alone.
    fn alone(&self, a: u32, b: u32) -> bool {
        self.groups[a as usize].is_none() && self.groups[b as usize].is_none()
    }

    /// The group at root `r` as a piece (a candidate alone: itself).
    fn piece<'a>(&'a self, r: u32, cands: &'a [Candidate]) -> Piece<'a> {
        match &self.groups[r as usize] {
            Some(g) => Piece {
                fit: &g.fit,
                tau: g.tau,
                seeds: &g.seeds,
            },
            None => cands[r as usize].piece(),
        }
    }

    /// The group at root `r` taken out (a candidate alone made a group).
    fn take(&mut self, r: u32, cands: &[Candidate], points: &[[f64; 3]]) -> Group {
        self.groups[r as usize].take().unwrap_or_else(|| {
            let c = &cands[r as usize];
            Group {
                members: vec![r],
                seeds: c.seeds.clone(),
                moments: Moments::of(&c.seeds, points),
                fit: c.fit.clone(),
                tau: c.tau,
            }
        })
    }

    /// The groups at roots `a` and `b` joined at `root`.
    fn join<S: Shape>(
        &mut self,
        a: u32,
        b: u32,
        root: u32,
        cands: &[Candidate],
        absorbed: &[bool],
        points: &[[f64; 3]],
    ) {
        let (ga, gb) = (self.take(a, cands, points), self.take(b, cands, points));
        let (mut big, small) = if ga.seeds.len() >= gb.seeds.len() {
            (ga, gb)
        } else {
            (gb, ga)
        };
        big.members.extend(small.members);
        big.seeds.extend(small.seeds);
        big.moments = big.moments.join(&small.moments);
        let joint = if S::K == 1 {
            big.moments.line()
        } else {
            big.moments.plane()
        };
        if !matches!(joint, Primitive::None) {
            big.fit = joint;
        }
        big.tau = big
            .members
            .iter()
            .filter(|&&c| !absorbed[c as usize])
            .map(|&c| cands[c as usize].tau)
            .fold(0.0, f64::max);
        self.groups[root as usize] = Some(big);
    }
}

/// One candidate per group: a group of one keeps its candidate; a larger
/// one becomes the fit of its seeds with the largest claim radius and
/// cell of the candidates not absorbed (dropped if it has no footprint).
/// With the new candidates: the new index of each old candidate kept as
/// it was (`None` for those merged), and which new ones a merge made.
fn merged<S: Shape>(
    cands: Vec<Candidate>,
    groups: &Groups,
    points: &[[f64; 3]],
) -> (Vec<Candidate>, Vec<Option<u32>>, Vec<bool>) {
    let n_old = cands.len();
    let mut old: Vec<Option<Candidate>> = cands.into_iter().map(Some).collect();
    let sets: Vec<Vec<(Candidate, bool)>> = groups
        .sets
        .iter()
        .filter(|g| !g.is_empty())
        .map(|g| {
            g.iter()
                .filter_map(|&c| {
                    old[c as usize]
                        .take()
                        .map(|x| (x, groups.absorbed[c as usize]))
                })
                .collect()
        })
        .collect();
    drop(old);
    let alone: Vec<Option<u32>> = groups
        .sets
        .iter()
        .filter(|g| !g.is_empty())
        .map(|g| (g.len() == 1).then_some(g[0]))
        .collect();
    // Groups are independent: on the pool's threads, in order.
    let made = crate::par::map_owned(sets, |mut group| {
        if group.len() == 1 {
            return group.pop().map(|(c, _)| c);
        }
        let mut seeds: Vec<u32> = group
            .iter()
            .flat_map(|(c, _)| c.seeds.iter().copied())
            .collect();
        crate::par::sort_unstable(&mut seeds);
        seeds.dedup();
        let widest = |of: fn(&Candidate) -> f64| {
            group
                .iter()
                .filter(|(_, absorbed)| !absorbed)
                .map(|(c, _)| of(c))
                .fold(0.0, f64::max)
        };
        let (tau, cell) = (widest(|c| c.tau), widest(|c| c.cell));
        drop(group);
        let fit = S::fit(points, &seeds);
        let foot = Footprint::new(&fit, points, &seeds, cell)?;
        Some(Candidate {
            fit,
            tau,
            cell,
            seeds,
            foot,
        })
    });
    let mut kept = vec![None; n_old];
    let mut changed = Vec::with_capacity(made.len());
    let mut out = Vec::with_capacity(made.len());
    for (cand, alone) in made.into_iter().zip(alone) {
        let Some(cand) = cand else { continue };
        if let Some(c) = alone {
            kept[c as usize] = Some(out.len() as u32);
        }
        changed.push(alone.is_none());
        out.push(cand);
    }
    (out, kept, changed)
}

/// Refits each candidate with more than k members on them (its footprint
/// too; a failed fit or footprint leaves the candidate as it was).
fn refit<S: Shape>(cands: &mut [Candidate], members: &[Vec<u32>], points: &[[f64; 3]]) {
    for (c, m) in cands.iter_mut().zip(members) {
        if m.len() > S::K {
            let refit = S::fit(points, m);
            if !matches!(refit, Primitive::None) {
                if let Some(foot) = Footprint::new(&refit, points, m, c.cell) {
                    c.fit = refit;
                    c.foot = foot;
                }
            }
        }
    }
}

/// The parts of the settled `claims` on `n` candidates: each candidate's
/// members with at least `min_vertices` (and k + 1) of them, refitted.
pub(super) fn parts<S: Shape>(
    claims: &Claims,
    n: usize,
    points: &[[f64; 3]],
    min_vertices: usize,
) -> Vec<Draft> {
    claims
        .resolve(n)
        .into_iter()
        .enumerate()
        .filter(|(_, m)| m.len() >= min_vertices.max(S::K + 1))
        .filter_map(|(cand, members)| {
            let fit = S::fit(points, &members);
            (!matches!(fit, Primitive::None)).then_some(Draft {
                members,
                fit,
                cand,
                pieces: Vec::new(),
                log10_nfa: f64::NEG_INFINITY,
            })
        })
        .collect()
}

/// The points left out of every part that a kept part's candidate claims
/// join the nearest such candidate's part (the rule of
/// [`Claims::resolve`], over the kept parts' candidates and pieces); the
/// parts that gain points are refitted. A point goes to its nearest
/// claimer, and that candidate may make no part (too few members), or
/// make one that goes (not significant, out of proportion, taken at
/// another level): the point is then still within the claim radius of a
/// kept primitive and over its footprint, as every member is. The number
/// of points that joined a part.
pub(super) fn reclaim<S: Shape>(
    parts: &mut [Draft],
    claims: &Claims,
    n_cands: usize,
    points: &[[f64; 3]],
) -> usize {
    let part_of_cand = part_of_candidates(parts, n_cands);
    let mut taken = vec![false; points.len()];
    for &i in parts.iter().flat_map(|p| &p.members) {
        taken[i as usize] = true;
    }
    let mut gained: Vec<Vec<u32>> = vec![Vec::new(); parts.len()];
    for here in claims.by_point() {
        let point = here[0].0;
        if taken[point as usize] {
            continue;
        }
        let kept = here
            .iter()
            .filter(|c| part_of_cand[c.1 as usize] != u32::MAX);
        if let Some(c) = nearest(kept) {
            gained[part_of_cand[c.1 as usize] as usize].push(point);
        }
    }
    let mut joined = 0;
    for (part, gain) in parts.iter_mut().zip(gained) {
        if gain.is_empty() {
            continue;
        }
        joined += gain.len();
        part.members.extend(gain);
        part.members.sort_unstable();
        let fit = S::fit(points, &part.members);
        if !matches!(fit, Primitive::None) {
            part.fit = fit;
        }
    }
    joined
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::assemble::same::same_primitive;
    use crate::detect::cloud::Copies;
    use crate::detect::fit::{fit_line_indices, fit_plane_indices};

    /// A candidate of the primitive `fit` of `seeds`, with the claim
    /// radius `tau` and footprint cells of side `cell`.
    fn candidate(
        fit: Primitive,
        pts: &[[f64; 3]],
        seeds: Vec<u32>,
        tau: f64,
        cell: f64,
    ) -> Candidate {
        let foot = Footprint::new(&fit, pts, &seeds, cell).unwrap();
        Candidate {
            fit,
            tau,
            cell,
            seeds,
            foot,
        }
    }

    /// A plane candidate fitted to `seeds`, with the claim radius `tau`
    /// and footprint cells of side 2.
    fn plane_candidate(pts: &[[f64; 3]], seeds: Vec<u32>, tau: f64) -> Candidate {
        let fit = Primitive::Plane(fit_plane_indices(pts, &seeds).unwrap());
        candidate(fit, pts, seeds, tau, 2.0)
    }

    /// Claims of three candidates on five points.
    fn claims() -> Claims {
        Claims(vec![
            (0, 0, 0.5),
            (1, 0, 0.3),
            (1, 1, 0.2),
            (1, 2, 0.2),
            (3, 1, 0.1),
            (3, 2, 0.4),
            (4, 2, 0.0),
        ])
    }

    #[test]
    fn a_point_goes_to_its_nearest_claim() {
        // Point 1: candidates 1 and 2 tie at 0.2, the smaller one wins.
        assert_eq!(claims().resolve(3), [vec![0], vec![1, 3], vec![4]]);
    }

    #[test]
    fn the_counting_sort_orders_claims_as_a_sort_does() {
        // 30 candidates claiming random subsets of 200 points (fixed seed),
        // each point at most once per candidate, in scrambled order.
        let mut rng = crate::rng::SplitMix64::new(0xc1a1);
        let mut per_cand: Vec<Vec<Claim>> = vec![Vec::new(); 30];
        for (c, v) in (0..).zip(per_cand.iter_mut()) {
            for p in (0..200u32).rev() {
                if rng.uniform() < 0.3 {
                    v.push((p, c, rng.uniform()));
                }
            }
        }
        let mut want: Vec<Claim> = per_cand.iter().flatten().copied().collect();
        want.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)));
        let lists: Vec<(u32, Vec<Claim>)> = (0..).zip(per_cand).collect();
        assert_eq!(by_point_then_candidate(200, lists, |c| c.0, |_, c| c), want);
    }

    #[test]
    fn the_trie_finds_each_points_set_of_candidates() {
        // 40 candidates claiming random subsets of 300 points (fixed seed),
        // a candidate's claims cut in two lists at a random place, points
        // in descending order; against the sets by brute force.
        let mut rng = crate::rng::SplitMix64::new(0x7e1e);
        let mut lists: Vec<(u32, Vec<u32>)> = Vec::new();
        let mut sets: Vec<Vec<u32>> = vec![Vec::new(); 300];
        for c in 0..40u32 {
            let p_claim = if c % 5 == 0 { 0.6 } else { 0.05 };
            let mut mine: Vec<u32> = (0..300u32)
                .rev()
                .filter(|_| rng.uniform() < p_claim)
                .collect();
            for &p in &mine {
                sets[p as usize].push(c);
            }
            let cut = (rng.uniform() * mine.len() as f64) as usize;
            let rest = mine.split_off(cut);
            lists.push((c, mine));
            lists.push((c, rest));
        }
        let (got_sets, at) = distinct_sets(300, lists);
        for (p, set) in sets.iter().enumerate() {
            assert_eq!(got_sets.get(at[p] as usize), set.as_slice(), "point {p}");
        }
        let mut want: Vec<Box<[u32]>> = sets.into_iter().map(Vec::into_boxed_slice).collect();
        want.sort_unstable();
        want.dedup();
        assert!(want.len() > 20, "{}", want.len());
        let mut got: Vec<Box<[u32]>> = got_sets.iter().map(Box::from).collect();
        let distinct = got.len();
        got.sort_unstable();
        got.dedup();
        assert_eq!(got.len(), distinct, "a set given twice");
        assert_eq!(got, want);
    }

    #[test]
    fn points_with_the_same_candidates_give_their_pairs_once() {
        // Many points claimed by candidates 0, 1 and 2; one by 2 and 3.
        let mut v: Vec<Claim> = (0..50)
            .flat_map(|p| (0..3).map(move |c| (p, c, 0.0)))
            .collect();
        v.extend([(50, 2, 0.0), (50, 3, 0.0)]);
        let c = Claims(v);
        assert_eq!(c.shared(Some), [(0, 1), (0, 2), (1, 2), (2, 3)]);
        // Mapped: 0 and 1 are one, 3 is none.
        assert_eq!(c.shared(|x| (x != 3).then_some(x.max(1))), [(1, 2)]);
    }

    #[test]
    fn points_whose_nearest_claimer_made_no_part_join_a_kept_part() {
        // Points 0..=20 along x, all claimed by candidate 0; points 5..=8
        // nearer to candidate 1, which with point 21 (claimed by it
        // alone) has 5 members, too few for a part of 6; point 22 is
        // claimed by none.
        let mut pts: Vec<[f64; 3]> = (0..21).map(|i| [f64::from(i), 0.0, 0.0]).collect();
        pts.extend([[6.5, 0.15, 0.0], [9.0, 5.0, 0.0]]);
        let mut v: Vec<Claim> = Vec::new();
        for p in 0..21u32 {
            v.push((p, 0, 0.01));
            if (5..=8).contains(&p) {
                v.push((p, 1, 0.0));
            }
        }
        v.push((21, 1, 0.09));
        let claims = Claims(v);
        let mut found = parts::<[u32; 2]>(&claims, 2, &pts, 6);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].members.len(), 17);
        assert_eq!(reclaim::<[u32; 2]>(&mut found, &claims, 2, &pts), 4);
        assert_eq!(found[0].members, (0..21).collect::<Vec<u32>>());
        // The refit runs through every member.
        let Primitive::Line(f) = &found[0].fit else {
            unreachable!()
        };
        assert!((f.centroid[0] - 10.0).abs() < 1e-9, "{:?}", f.centroid);
        // Nothing left to take.
        assert_eq!(reclaim::<[u32; 2]>(&mut found, &claims, 2, &pts), 0);
    }

    #[test]
    fn shared_pairs_are_distinct_and_mapped() {
        let c = claims();
        assert_eq!(c.shared(Some), [(0, 1), (0, 2), (1, 2)]);
        // Candidates 1 and 2 are one part, candidate 0 none.
        assert_eq!(c.shared(|x| (x > 0).then_some(7)), []);
        assert_eq!(c.shared(|x| Some(x.min(1))), [(0, 1)]);
    }

    #[test]
    fn two_pieces_of_a_line_merge_and_a_crossing_line_stays() {
        // Points 0..=20 along x, split in two candidates sharing point 10;
        // a third candidate along y through x = 10 shares it too.
        let mut pts: Vec<[f64; 3]> = (0..21).map(|i| [i as f64, 0.0, 0.0]).collect();
        pts.extend((1..8).map(|i| [10.0, i as f64, 0.0]));
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        let cand = |seeds: Vec<u32>| {
            let fit = Primitive::Line(fit_line_indices(&pts, &seeds).unwrap());
            candidate(fit, &pts, seeds, 0.1, 2.0)
        };
        let up: Vec<u32> = std::iter::once(10).chain(21..28).collect();
        let cands = vec![cand((0..11).collect()), cand((10..21).collect()), cand(up)];
        let (cands, claims) = settle::<[u32; 2]>(cands, &cloud, None, 10.0);
        assert_eq!(cands.len(), 2);
        assert_eq!(cands[0].seeds, (0..21).collect::<Vec<u32>>());
        let found = parts::<[u32; 2]>(&claims, cands.len(), &pts, 5);
        // Point 10 is on both lines; the tie goes to the first.
        assert_eq!(found[0].members.len(), 21);
        assert_eq!(found[1].members, (21..28).collect::<Vec<u32>>());
        // Too few members: no part.
        assert_eq!(parts::<[u32; 2]>(&claims, cands.len(), &pts, 8).len(), 1);
    }

    #[test]
    fn a_piece_on_a_ridge_does_not_chain_the_two_faces() {
        // A shallow gable: face A (x in 0..=20) and face B (x in -12..=0)
        // falling 7° from the ridge x = 0 (14° apart, τ 0.1), and a
        // four-point piece lying flat across the ridge at x = ±0.25: its
        // plane is 7° from each face and its points within τ of both, so
        // that it is one primitive with each face; the faces are not one.
        let t = 7f64.to_radians().tan();
        let mut pts: Vec<[f64; 3]> = Vec::new();
        let mut face = |xs: std::ops::RangeInclusive<i32>| -> Vec<u32> {
            xs.flat_map(|i| (0..=10).map(move |j| (i, j)))
                .map(|(i, j)| {
                    pts.push([f64::from(i), f64::from(j), -f64::from(i).abs() * t]);
                    (pts.len() - 1) as u32
                })
                .collect()
        };
        let a = face(0..=20);
        let b = face(-12..=0);
        let ridge: Vec<u32> = [(-0.25, 4.0), (0.25, 4.0), (-0.25, 5.0), (0.25, 5.0)]
            .iter()
            .map(|&(x, y)| {
                pts.push([x, y, -0.25 * t]);
                (pts.len() - 1) as u32
            })
            .collect();
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        let cand = |seeds: Vec<u32>| plane_candidate(&pts, seeds, 0.1);
        let (pa, pb, pr) = (cand(a.clone()), cand(b.clone()), cand(ridge.clone()));
        // The pairwise tests that would chain them.
        assert!(same_primitive(pa.piece(), pr.piece(), 10.0, &pts));
        assert!(same_primitive(pb.piece(), pr.piece(), 10.0, &pts));
        assert!(!same_primitive(pa.piece(), pb.piece(), 10.0, &pts));
        let (cands, _) = settle::<[u32; 3]>(vec![pa, pb, pr], &cloud, None, 10.0);
        assert_eq!(cands.len(), 2);
        let normals: Vec<[f64; 3]> = cands
            .iter()
            .map(|c| match &c.fit {
                Primitive::Plane(f) => f.normal,
                _ => unreachable!(),
            })
            .collect();
        let cos = normals[0]
            .iter()
            .zip(&normals[1])
            .map(|(x, y)| x * y)
            .sum::<f64>();
        assert!(cos.abs() < 14f64.to_radians().cos() + 1e-3, "{normals:?}");
        // Each face's points stay with the candidate of that face.
        assert!(a.iter().all(|v| cands[0].seeds.contains(v)));
        assert!(b.iter().all(|v| cands[1].seeds.contains(v)));
    }

    #[test]
    fn the_merging_rounds_see_the_claims_without_their_distances() {
        // Three overlapping planes over a 30 × 30 grid (two tilted), with
        // normals that keep some points out of the tilted ones: Sharing
        // holds the distinct sets of candidates of the claims' points, and
        // gives the same shared pairs.
        let pts: Vec<[f64; 3]> = (0..900)
            .map(|k| {
                let (i, j) = (f64::from(k % 30), f64::from(k / 30));
                [i, j, 0.02 * ((i * 7.0 + j * 3.0) % 5.0)]
            })
            .collect();
        let normals: Vec<[f32; 3]> = (0..900)
            .map(|k| {
                if k % 7 == 0 {
                    [1.0, 0.0, 0.0]
                } else {
                    [0.0, 0.0, 1.0]
                }
            })
            .collect();
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        let cand = |seeds: Vec<u32>, tau: f64| plane_candidate(&pts, seeds, tau);
        let cands = vec![
            cand((0..600).collect(), 0.1),
            cand((300..900).collect(), 0.05),
            cand((0..900).filter(|k| k % 30 < 12).collect(), 0.2),
        ];
        for normals in [None, Some(normals.as_slice())] {
            let claims = Claims::of(&cands, &cloud, normals);
            let sharing = Sharing::of(&cands, &cloud, normals);
            // The distinct sets of two candidates or more at a point.
            let mut sets: Vec<Box<[u32]>> = claims
                .by_point()
                .filter(|h| h.len() > 1)
                .map(|h| h.iter().map(|c| c.1).collect())
                .collect();
            sets.sort_unstable();
            sets.dedup();
            assert!(sets.len() > 1, "{sets:?}");
            let mut got: Vec<Box<[u32]>> = sharing
                .sets
                .iter()
                .filter(|s| s.len() > 1)
                .map(Box::from)
                .collect();
            got.sort_unstable();
            assert_eq!(got, sets);
            let all = [true; 3];
            assert_eq!(sharing.shared(&all), claims.shared(Some));
            assert_eq!(sharing.shared(&all), [(0, 1), (0, 2), (1, 2)]);
            // Pairs without a changed candidate are left out.
            assert_eq!(sharing.shared(&[false, false, true]), [(0, 2), (1, 2)]);
        }
    }

    #[test]
    fn the_shared_pairs_of_changed_candidates_match_every_pair_of_every_set() {
        // Random sets of up to 12 of 40 candidates, some repeated, some of
        // one candidate; random changed flags (none, some, all): the
        // indexed pairs are the brute-force pairs of each set with a
        // changed member, distinct and sorted.
        let mut rng = crate::rng::SplitMix64::new(0x5e75);
        let n = 40usize;
        for trial in 0..200 {
            let mut sets: Vec<Box<[u32]>> = vec![Box::new([])];
            for _ in 0..(trial % 30) {
                let len = 1 + (rng.uniform() * 12.0) as usize;
                let mut set: Vec<u32> = (0..len)
                    .map(|_| (rng.uniform() * n as f64) as u32)
                    .collect();
                set.sort_unstable();
                set.dedup();
                sets.push(set.into());
                if rng.uniform() < 0.2 {
                    sets.push(sets[sets.len() - 1].clone());
                }
            }
            let p_changed = [0.0, 0.1, 0.5, 1.0][trial % 4];
            let changed: Vec<bool> = (0..n).map(|_| rng.uniform() < p_changed).collect();
            let mut flat = Sets::default();
            for set in &sets {
                flat.push(set.iter().copied());
            }
            let sharing = Sharing {
                at: vec![0; sets.len()],
                sets: flat,
            };
            let mut want: Vec<(u32, u32)> = Vec::new();
            for set in sharing.sets.iter() {
                for (k, &a) in set.iter().enumerate() {
                    for &b in &set[k + 1..] {
                        if changed[a as usize] || changed[b as usize] {
                            want.push((a, b));
                        }
                    }
                }
            }
            want.sort_unstable();
            want.dedup();
            assert_eq!(sharing.shared(&changed), want, "trial {trial}");
        }
    }

    #[test]
    fn the_sharing_after_a_merge_is_the_sharing_of_the_merged_candidates() {
        // A floor of 30 × 30 points and a wall of 30 × 10 along x = 10:
        // two overlapping pieces of the floor (one primitive: they merge),
        // a third piece of it apart from both (kept until the merged one
        // reaches it) and the wall (across the floor: kept). The update
        // of the sharing after each round must give every point the set a
        // fresh sharing of the new candidates gives it, and the rounds
        // must end where testing every pair each round ends.
        let mut pts: Vec<[f64; 3]> = (0..900)
            .map(|k| {
                let (i, j) = (f64::from(k % 30), f64::from(k / 30));
                [i, j, 0.02 * ((i * 7.0 + j * 3.0) % 5.0)]
            })
            .collect();
        pts.extend((0..300).map(|k| [10.0, f64::from(k % 30), 1.0 + f64::from(k / 30)]));
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        cloud.build_index();
        let cand = |seeds: Vec<u32>, tau: f64| plane_candidate(&pts, seeds, tau);
        let mut cands = vec![
            cand((0..450).collect(), 0.1),
            cand((300..700).collect(), 0.1),
            cand((750..900).collect(), 0.1),
            cand((900..1200).collect(), 0.1),
        ];
        let mut sharing = Sharing::of(&cands, &cloud, None);
        let mut changed = vec![true; cands.len()];
        let mut rounds = 0;
        while let Some(groups) = duplicates::<[u32; 3]>(&cands, &sharing, &changed, 10.0, &pts) {
            let (next, kept, made) = merged::<[u32; 3]>(cands, &groups, &pts);
            assert!(
                made.iter().any(|&m| m),
                "a round that merges makes a candidate"
            );
            cands = next;
            changed = made;
            sharing = sharing.after(&cands, &kept, &changed, &cloud, None);
            let fresh = Sharing::of(&cands, &cloud, None);
            for p in 0..pts.len() {
                assert_eq!(
                    sharing.sets.get(sharing.at[p] as usize),
                    fresh.sets.get(fresh.at[p] as usize),
                    "round {rounds}, point {p}"
                );
            }
            rounds += 1;
        }
        assert!(rounds >= 1);
        // The floor is one candidate, the wall another.
        assert_eq!(cands.len(), 2, "{rounds} rounds");
        let all = vec![true; cands.len()];
        assert!(duplicates::<[u32; 3]>(
            &cands,
            &Sharing::of(&cands, &cloud, None),
            &all,
            10.0,
            &pts
        )
        .is_none());
    }

    #[test]
    fn a_coarse_piece_on_a_plane_neither_widens_it_nor_links_it() {
        // A plane z = 0 (21 × 21 points, τ 0.1); a 16-point piece of it
        // found at a coarse scale (τ 1); a piece tilted 5° from x = 10
        // to x = 14 (τ 1), one primitive with the coarse piece but not
        // with the plane (rising to 0.35 above it).
        let mut pts: Vec<[f64; 3]> = (0..21)
            .flat_map(|i| (0..21).map(move |j| [i as f64, j as f64, 0.0]))
            .collect();
        let tilted: Vec<u32> = (0..5)
            .flat_map(|i| (0..5).map(move |j| (i, j)))
            .map(|(i, j)| {
                let x = 10.0 + i as f64;
                pts.push([x, 8.0 + j as f64, (x - 10.0) * 5f64.to_radians().tan()]);
                (pts.len() - 1) as u32
            })
            .collect();
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        let cand = |seeds: Vec<u32>, tau: f64| plane_candidate(&pts, seeds, tau);
        let coarse: Vec<u32> = (8..12)
            .flat_map(|i| (8..12).map(move |j| i * 21 + j))
            .collect();
        let cands = vec![
            cand((0..441).collect(), 0.1),
            cand(coarse, 1.0),
            cand(tilted.clone(), 1.0),
        ];
        let (cands, _) = settle::<[u32; 3]>(cands, &cloud, None, 10.0);
        // The plane absorbed the coarse piece and kept its own radius; the
        // tilted piece stays apart (with the widest radius it took both).
        assert_eq!(cands.len(), 2);
        assert_eq!(cands[0].tau, 0.1);
        assert_eq!(cands[1].tau, 1.0);
        assert!(tilted.iter().all(|v| cands[1].seeds.contains(v)));
    }

    #[test]
    fn a_large_candidate_claimed_in_slices_claims_each_point_once() {
        // A plane of 120 × 120 points, every third 0.3 off it (outside τ
        // 0.1), and a second, small candidate on a corner of it: the large
        // one's footprint has far more than CLAIM_BLOCKS blocks.
        let pts: Vec<[f64; 3]> = (0..120)
            .flat_map(|i| (0..120).map(move |j| (i, j)))
            .map(|(i, j)| {
                let z = if (i * 7 + j) % 3 == 0 {
                    0.3
                } else {
                    0.01 * ((i + j) % 5) as f64
                };
                [i as f64, j as f64, z]
            })
            .collect();
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        let cand = |seeds: Vec<u32>| {
            let fit = Primitive::Plane(fit_plane_indices(&pts, &seeds).unwrap());
            candidate(fit, &pts, seeds, 0.1, 1.0)
        };
        let on: Vec<u32> = (0..pts.len() as u32)
            .filter(|&i| pts[i as usize][2] < 0.1)
            .collect();
        let corner: Vec<u32> = on
            .iter()
            .copied()
            .filter(|&i| i < 10 * 120 && i % 120 < 10)
            .collect();
        let cands = vec![cand(on.clone()), cand(corner.clone())];
        assert!(cands[0].foot.near_blocks(0.1).len() > 10 * CLAIM_BLOCKS);
        let got = Claims::of(&cands, &cloud, None).0;
        // Each point within τ of a candidate's plane and over its footprint,
        // by point, then candidate.
        let mut want: Vec<Claim> = Vec::new();
        for i in 0..pts.len() as u32 {
            for (ci, c) in cands.iter().enumerate() {
                let d = c.fit.distance(&pts[i as usize]);
                if d <= c.tau && c.foot.contains(&pts[i as usize]) {
                    want.push((i, ci as u32, d));
                }
            }
        }
        assert_eq!(got.len(), want.len());
        assert!(got == want);
        assert_eq!(got.iter().filter(|c| c.1 == 0).count(), on.len());
        assert!(got.iter().filter(|c| c.1 == 1).count() >= corner.len());
    }

    #[test]
    fn normals_across_a_plane_keep_their_points_out() {
        let plane = Primitive::Plane(
            crate::detect::fit::fit_plane(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]).unwrap(),
        );
        let normals = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0; 3], [0.0, 0.6, 0.8]];
        let agrees = normal_agreement(&plane, Some(&normals));
        assert_eq!(
            (0..4).map(&agrees).collect::<Vec<_>>(),
            [true, false, true, true]
        );
        let line =
            Primitive::Line(fit_line_indices(&[[0.0; 3], [1.0, 0.0, 0.0]], &[0, 1]).unwrap());
        assert!(normal_agreement(&line, Some(&normals))(1));
        assert!(normal_agreement(&plane, None)(1));
    }
}
