//! Tests of the path filter: paper Fig. 7 cases and a naive oracle.

use super::*;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::collections::{BTreeMap, BTreeSet};

fn chain(from: u32, edges: u32) -> Vec<[u32; 2]> {
    (from..from + edges).map(|i| [i, i + 1]).collect()
}

fn n_paths<S: Simplex>(s: &[S]) -> usize {
    paths(s).unwrap().into_iter().collect::<BTreeSet<_>>().len()
}

#[test]
fn fig7_a_one_edge_spur_goes_and_chain_rejoins() {
    let mut s = chain(0, 10);
    s.push([5, 20]);
    assert_eq!(n_paths(&s), 3);
    for nb_c in [2, 3, 6, 7] {
        // nb_c = 6, 7: the halves (5 edges each) would go if the chain
        // did not rejoin after the spur is deleted at l = 1.
        let kept = filter(&s, nb_c).unwrap();
        assert_eq!(kept, chain(0, 10), "nb_c = {nb_c}");
        assert_eq!(n_paths(&kept), 1);
    }
    assert_eq!(filter(&s, 1).unwrap(), s);
    assert_eq!(filter(&s, 0).unwrap(), s);
    assert!(filter(&s, 11).unwrap().is_empty());
}

#[test]
fn fig7_b_two_edge_spur() {
    let mut s = chain(0, 10);
    s.extend([[5, 20], [20, 21]]);
    assert_eq!(filter(&s, 2).unwrap(), s);
    let kept = filter(&s, 3).unwrap();
    assert_eq!(kept, chain(0, 10));
    assert_eq!(n_paths(&kept), 1);
}

#[test]
fn fig7_c_two_spurs() {
    let mut s = chain(0, 12);
    s.extend([[3, 30], [8, 40], [40, 41]]);
    assert_eq!(n_paths(&s), 5);
    let kept = filter(&s, 3).unwrap();
    assert_eq!(kept, chain(0, 12));
    assert_eq!(n_paths(&kept), 1);
    // nb_c = 2 only removes the one-edge spur.
    assert_eq!(filter(&s, 2).unwrap().len(), 14);
}

#[test]
fn fig7_d_isolated_piece() {
    let mut s = chain(0, 10);
    s.extend(chain(100, 2));
    assert_eq!(filter(&s, 3).unwrap(), chain(0, 10));
    assert_eq!(filter(&s, 2).unwrap(), s);
    // A loop of 3 edges is one path of length 3.
    let tri = [[50, 51], [51, 52], [50, 52]];
    assert_eq!(n_paths(&tri), 1);
    assert_eq!(filter(&tri, 3).unwrap().len(), 3);
    assert!(filter(&tri, 4).unwrap().is_empty());
}

/// The triangles of an nx × ny grid of squares on vertices
/// v(i, j) = base + i + j·(nx + 1).
fn patch(nx: u32, ny: u32, base: u32) -> Vec<[u32; 3]> {
    let mut t = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let v = |i: u32, j: u32| base + i + j * (nx + 1);
            t.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            t.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    t
}

#[test]
fn fig7_e_fin_on_inner_edge() {
    let p = patch(3, 3, 0);
    assert_eq!(p.len(), 18);
    assert_eq!(n_paths(&p), 1);
    let mut s = p.clone();
    s.push([5, 10, 999]); // 5-10 is the inner diagonal of the middle square
    assert_eq!(n_paths(&s), 2);
    let kept = filter(&s, 2).unwrap();
    assert_eq!(kept, p);
    assert_eq!(n_paths(&kept), 1);
    // Two fins on the same edge: each is still a path of length 1.
    s.push([5, 10, 998]);
    assert_eq!(filter(&s, 2).unwrap(), p);
    // A two-triangle flap goes at nb_c = 3, not 2.
    let mut f = p.clone();
    f.extend([[5, 10, 999], [5, 999, 1000]]);
    assert_eq!(filter(&f, 2).unwrap().len(), 20);
    assert_eq!(filter(&f, 3).unwrap(), p);
}

#[test]
fn fig7_f_small_patch() {
    let p = patch(3, 3, 0);
    let mut s = p.clone();
    s.extend(patch(1, 1, 500)); // 2 triangles
    assert_eq!(filter(&s, 3).unwrap(), p);
    assert_eq!(filter(&s, 2).unwrap(), s);
    assert_eq!(components(&s).unwrap()[18..], [1, 1]);
    assert_eq!(
        component_size_mask(&s, 3).unwrap(),
        [vec![true; 18], vec![false; 2]].concat()
    );
}

#[test]
fn duplicates_and_errors() {
    let s = [[1, 0], [0, 1], [1, 2]];
    assert_eq!(paths(&s).unwrap(), vec![0, 0, 0]);
    assert_eq!(filter_mask(&s, 3).unwrap(), vec![false; 3]);
    assert_eq!(filter_mask(&s, 2).unwrap(), vec![true; 3]);
    assert_eq!(
        filter_mask(&[[0, 1], [2, 2]], 2),
        Err(FilterError::RepeatedVertex { index: 1 })
    );
    assert_eq!(
        components(&[[0, 1, 2], [3, 4, 3]]),
        Err(FilterError::RepeatedVertex { index: 1 })
    );
    let empty: [[u32; 3]; 0] = [];
    assert!(filter(&empty, 5).unwrap().is_empty());
    // Vertex ids at the top of the u32 range.
    let big = [
        [u32::MAX - 2, u32::MAX - 1, u32::MAX],
        [u32::MAX - 3, u32::MAX - 1, u32::MAX],
    ];
    assert_eq!(paths(&big).unwrap(), vec![0, 0]);
    assert_eq!(component_size_mask(&big, 3).unwrap(), vec![false, false]);
    assert_eq!(component_size_mask(&big, 2).unwrap(), vec![true, true]);
}

// ---- A deliberately naive oracle, straight from docs/method.md §3. ----

fn faces_naive(s: &[u32]) -> Vec<Vec<u32>> {
    (0..s.len())
        .map(|skip| {
            let mut f: Vec<u32> = s
                .iter()
                .enumerate()
                .filter(|&(i, _)| i != skip)
                .map(|(_, &v)| v)
                .collect();
            f.sort();
            f
        })
        .collect()
}

/// The surviving set of (sorted) simplices: for l in 1..nb_c, repeat
/// { degrees, BFS paths, delete paths ≤ l } until nothing is deleted.
fn oracle(input: &[Vec<u32>], nb_c: u32) -> BTreeSet<Vec<u32>> {
    let mut set: BTreeSet<Vec<u32>> = input
        .iter()
        .map(|s| {
            let mut s = s.clone();
            s.sort();
            s
        })
        .collect();
    for l in 1..nb_c.max(1) {
        loop {
            let list: Vec<Vec<u32>> = set.iter().cloned().collect();
            let mut incident: BTreeMap<Vec<u32>, Vec<usize>> = BTreeMap::new();
            for (i, s) in list.iter().enumerate() {
                for f in faces_naive(s) {
                    incident.entry(f).or_default().push(i);
                }
            }
            let mut comp = vec![usize::MAX; list.len()];
            let mut sizes = Vec::new();
            for start in 0..list.len() {
                if comp[start] != usize::MAX {
                    continue;
                }
                let c = sizes.len();
                let mut stack = vec![start];
                comp[start] = c;
                let mut size = 0;
                while let Some(x) = stack.pop() {
                    size += 1;
                    for f in faces_naive(&list[x]) {
                        let inc = &incident[&f];
                        if inc.len() == 2 {
                            for &y in inc {
                                if comp[y] == usize::MAX {
                                    comp[y] = c;
                                    stack.push(y);
                                }
                            }
                        }
                    }
                }
                sizes.push(size);
            }
            let doomed: BTreeSet<Vec<u32>> = list
                .iter()
                .enumerate()
                .filter(|&(i, _)| sizes[comp[i]] <= l as usize)
                .map(|(_, s)| s.clone())
                .collect();
            if doomed.is_empty() {
                break;
            }
            set = set.difference(&doomed).cloned().collect();
        }
    }
    set
}

fn runner() -> TestRunner {
    let config = Config {
        cases: 400,
        failure_persistence: None,
        ..Config::default()
    };
    let seed = [7u8; 32];
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed))
}

fn check_against_oracle<S: Simplex + std::fmt::Debug>(
    simplices: &[S],
    as_vec: impl Fn(&S) -> Vec<u32>,
    nb_c: u32,
) -> Result<(), TestCaseError> {
    let mask = filter_mask(simplices, nb_c).unwrap();
    let want = oracle(&simplices.iter().map(&as_vec).collect::<Vec<_>>(), nb_c);
    for (s, keep) in simplices.iter().zip(&mask) {
        let mut v = as_vec(s);
        v.sort();
        prop_assert_eq!(*keep, want.contains(&v), "{:?} nb_c={}", s, nb_c);
    }
    Ok(())
}

#[test]
fn edges_match_oracle() {
    let strategy = (
        proptest::collection::vec((0u32..12, 0u32..12), 0..30),
        1u32..8,
    );
    runner()
        .run(&strategy, |(pairs, nb_c)| {
            let s: Vec<[u32; 2]> = pairs
                .into_iter()
                .filter(|(a, b)| a != b)
                .map(|(a, b)| [a * 1000, b * 1000]) // sparse ids
                .collect();
            check_against_oracle(&s, |e| e.to_vec(), nb_c)
        })
        .unwrap();
}

#[test]
fn triangles_match_oracle() {
    let strategy = (
        proptest::collection::vec((0u32..9, 0u32..9, 0u32..9), 0..40),
        1u32..10,
    );
    runner()
        .run(&strategy, |(triples, nb_c)| {
            let s: Vec<[u32; 3]> = triples
                .into_iter()
                .filter(|(a, b, c)| a != b && b != c && a != c)
                .map(|(a, b, c)| [a, b, c])
                .collect();
            check_against_oracle(&s, |t| t.to_vec(), nb_c)
        })
        .unwrap();
}

#[test]
fn grid_patches_match_oracle() {
    // Structured inputs: patches with holes and fins, where paths merge.
    let strategy = (
        proptest::collection::vec(any::<bool>(), 32),
        proptest::collection::vec((0u32..25, 0u32..25), 0..6),
        1u32..25,
    );
    runner()
        .run(&strategy, |(keep, fins, nb_c)| {
            let mut s: Vec<[u32; 3]> = patch(4, 4, 0)
                .into_iter()
                .zip(keep)
                .filter_map(|(t, k)| k.then_some(t))
                .collect();
            for (i, (a, b)) in fins.into_iter().enumerate() {
                if a != b {
                    s.push([a, b, 100 + i as u32]);
                }
            }
            check_against_oracle(&s, |t| t.to_vec(), nb_c)
        })
        .unwrap();
}

/// The half-faces of `s` sorted by (face key, h) with the (key, h) pairs
/// themselves: the oracle of [`half_faces_by_key`].
fn half_faces_naive<S: Simplex>(s: &[S]) -> Vec<u32> {
    let k = S::VERTICES;
    let mut pairs: Vec<(u64, u32)> = (0..s.len() * k)
        .map(|h| (s[h / k].face_key(h % k), h as u32))
        .collect();
    pairs.sort_unstable();
    pairs.into_iter().map(|(_, h)| h).collect()
}

/// Random canonical simplices over `n` vertices numbered from `base`.
fn random_simplices<S: Simplex>(
    rng: &mut crate::rng::SplitMix64,
    count: usize,
    n: u64,
    base: u32,
    make: impl Fn([u32; 3]) -> Option<S>,
) -> Vec<S> {
    let mut out = Vec::new();
    while out.len() < count {
        let v = [0, 1, 2].map(|_| base + rng.below(n) as u32);
        if let Some(s) = make(v) {
            out.push(s);
        }
    }
    out
}

/// The counting sort by leading vertex (dense vertex ids) and the pairs'
/// sort (ids far apart) give the oracle's order, edges and triangles;
/// and a wrong order is told apart.
#[test]
fn half_faces_sorted_by_key_dense_and_sparse() {
    let mut rng = crate::rng::SplitMix64::new(91);
    for (n, base) in [(40u64, 0u32), (400, 0), (2000, 0), (40, 3_000_000_000)] {
        let tris = random_simplices(&mut rng, 500, n, base, <[u32; 3] as Simplex>::canonical);
        let edges = random_simplices(&mut rng, 500, n, base, |v| {
            <[u32; 2] as Simplex>::canonical([v[0], v[1]])
        });
        assert_eq!(half_faces_by_key(&tris), half_faces_naive(&tris));
        assert_eq!(half_faces_by_key(&edges), half_faces_naive(&edges));
    }
    // The oracle can fail: the half-faces in their own order are not it.
    let tris = random_simplices(&mut rng, 50, 20, 0, <[u32; 3] as Simplex>::canonical);
    let identity: Vec<u32> = (0..150).collect();
    assert_ne!(identity, half_faces_naive(&tris));
}

/// From `PARALLEL_HALF_FACES` half-faces the vertices' lists are sorted
/// in chunks on the threads: the same order as the oracle's, on four
/// threads and on one.
#[test]
fn half_faces_sorted_in_parallel_chunks() {
    let mut rng = crate::rng::SplitMix64::new(17);
    let count = super::PARALLEL_HALF_FACES / 3 + 1000;
    let tris = random_simplices(&mut rng, count, 20_000, 0, <[u32; 3] as Simplex>::canonical);
    let want = half_faces_naive(&tris);
    for threads in [1, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        assert_eq!(pool.install(|| half_faces_by_key(&tris)), want, "{threads}");
    }
}

/// Sorted distinct simplices skip the merge's sort and its maps (the
/// identity); unsorted ones with repeats are merged: the same incidence
/// either way.
#[test]
fn an_incidence_of_sorted_simplices_is_that_of_any_order() {
    let mut rng = crate::rng::SplitMix64::new(23);
    let mut tris = random_simplices(&mut rng, 3000, 400, 0, <[u32; 3] as Simplex>::canonical);
    tris.sort_unstable();
    tris.dedup();
    let sorted = Incidence::new(&tris).unwrap();
    let mut shuffled = tris.clone();
    shuffled.reverse();
    shuffled.push(shuffled[0]);
    let other = Incidence::new(&shuffled).unwrap();
    assert_eq!(sorted.n, other.n);
    assert_eq!(sorted.num_faces(), other.num_faces());
    for u in 0..sorted.n {
        let faces = |inc: &Incidence, u: usize| -> Vec<Vec<u32>> {
            inc.faces_of(u)
                .iter()
                .map(|&f| inc.face(f as usize).to_vec())
                .collect()
        };
        assert_eq!(faces(&sorted, u), faces(&other, u));
    }
    assert!(sorted.maps.is_none());
    assert!(
        (0..tris.len()).all(|i| sorted.input_of(i) == i as u32 && sorted.unique_of(i) == i as u32)
    );
    // The shuffled list with a repeat maps each input to its unique
    // simplex, and each unique simplex to its first input.
    assert!(other.maps.is_some());
    for i in 0..shuffled.len() {
        let u = other.unique_of(i) as usize;
        assert_eq!(
            shuffled[i].canonical(),
            shuffled[other.input_of(u) as usize].canonical()
        );
        assert!(other.input_of(u) as usize <= i);
    }
}

/// The union of sets each filtered at nb_c has no component of fewer than
/// nb_c simplices (a survivor lies on a path of at least nb_c simplices,
/// inside its component, and a union only joins components): the
/// detection's cleaning of the union would drop nothing, and is not
/// recomputed. The union of the unfiltered sets has such components in
/// some cases, so the check can fail.
#[test]
fn a_union_of_filtered_sets_has_no_small_component() {
    let strategy = (
        proptest::collection::vec((0u32..9, 0u32..9, 0u32..9, 0u8..3), 0..60),
        1u32..8,
    );
    let small_unfiltered = std::cell::Cell::new(0);
    runner()
        .run(&strategy, |(triples, nb_c)| {
            let jobs: Vec<Vec<[u32; 3]>> = (0..3)
                .map(|j| {
                    triples
                        .iter()
                        .filter(|&&(a, b, c, job)| a != b && b != c && a != c && job == j)
                        .map(|&(a, b, c, _)| [a, b, c])
                        .collect()
                })
                .collect();
            let union = |sets: Vec<Vec<[u32; 3]>>| {
                let mut all: Vec<[u32; 3]> = sets
                    .into_iter()
                    .flatten()
                    .map(|t| t.canonical().unwrap())
                    .collect();
                all.sort_unstable();
                all.dedup();
                all
            };
            let filtered = union(jobs.iter().map(|s| filter(s, nb_c).unwrap()).collect());
            let mask = component_size_mask(&filtered, nb_c).unwrap();
            prop_assert!(mask.iter().all(|&k| k), "nb_c {}: {:?}", nb_c, filtered);
            let raw = union(jobs);
            if !component_size_mask(&raw, nb_c).unwrap().iter().all(|&k| k) {
                small_unfiltered.set(small_unfiltered.get() + 1);
            }
            Ok(())
        })
        .unwrap();
    assert!(
        small_unfiltered.get() > 0,
        "no case had a small component to drop"
    );
}
