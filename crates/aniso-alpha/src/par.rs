//! Order-preserving parallel maps, a parallel sort and loop: rayon with
//! the `parallel` feature, a plain loop (or sort) without. The result
//! never depends on the thread count.

/// `f(state, i)` for `i` in `0..n`, collected in order. The indices are cut
/// into contiguous ranges of at least n/(4·threads) indices, and each range
/// runs on one worker with one state from `init` (a scratch buffer): at
/// most about 4·threads states are made, one a thread at a time, so a
/// state may be as large as the input. The results are written in place
/// into the one output vector (no per-range vectors joined after).
pub(crate) fn map_ranges<T: Send, S>(
    n: usize,
    init: impl Fn() -> S + Sync,
    f: impl Fn(&mut S, usize) -> T + Sync,
) -> Vec<T> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        let ranges = 4 * rayon::current_num_threads().max(1);
        let size = n.div_ceil(ranges).max(1);
        (0..n)
            .into_par_iter()
            .with_min_len(size)
            .map_init(&init, |state, i| f(state, i))
            .collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        let mut state = init();
        (0..n).map(|i| f(&mut state, i)).collect()
    }
}

/// `f(i)` for `i` in `0..n`, collected in order, each index a task of its
/// own that any thread may take: for items of very unequal cost (the
/// components, candidates or parts of a detection, where one, a scan's
/// ground, can outweigh all the others), which [`map_ranges`]' fixed
/// ranges would leave to the thread that drew the large one together
/// with its neighbours.
pub(crate) fn map_each<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..n).into_par_iter().map(&f).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..n).map(f).collect()
    }
}

/// `f(item)` for each of `items`, collected in order, each item a task of
/// its own (as [`map_each`]) that owns its item.
pub(crate) fn map_owned<T: Send, U: Send>(items: Vec<T>, f: impl Fn(T) -> U + Sync) -> Vec<U> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        items.into_par_iter().map(&f).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        items.into_iter().map(f).collect()
    }
}

/// Sorts `v` (unstable), on the pool's threads from 2^16 elements. The
/// result is the same for any thread count when equal elements are
/// indistinguishable (a total order on whole values, as on tuples).
pub(crate) fn sort_unstable<T: Ord + Send>(v: &mut [T]) {
    sort_unstable_by(v, T::cmp);
}

/// Sorts `v` (unstable) by `cmp`, on the pool's threads from 2^16
/// elements: the same order for any thread count when `cmp` is a total
/// order in which no two elements are equal (ties broken by a unique key).
pub(crate) fn sort_unstable_by<T: Send>(
    v: &mut [T],
    cmp: impl Fn(&T, &T) -> std::cmp::Ordering + Sync,
) {
    #[cfg(feature = "parallel")]
    if v.len() >= 1 << 16 {
        use rayon::slice::ParallelSliceMut;
        v.par_sort_unstable_by(cmp);
        return;
    }
    v.sort_unstable_by(cmp);
}

/// `a()` and `b()`, on two of the pool's threads when they are free (one
/// after the other without the `parallel` feature).
pub(crate) fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    #[cfg(feature = "parallel")]
    {
        rayon::join(a, b)
    }
    #[cfg(not(feature = "parallel"))]
    {
        (a(), b())
    }
}

/// `f(item)` for each item, on the pool's threads (items that own
/// disjoint parts of a buffer).
pub(crate) fn for_each_mut<T: Send>(items: Vec<T>, f: impl Fn(T) + Sync) {
    map_owned(items, f);
}

/// The threads of the current pool (1 without the `parallel` feature).
pub(crate) fn threads() -> usize {
    #[cfg(feature = "parallel")]
    {
        rayon::current_num_threads().max(1)
    }
    #[cfg(not(feature = "parallel"))]
    {
        1
    }
}

/// `worker()` as `copies` tasks on the current pool, returning when every
/// one has returned (without the `parallel` feature, once on this thread:
/// a worker that takes items from a shared queue until it is empty then
/// does all the work).
pub(crate) fn spawn_workers(copies: usize, worker: impl Fn() + Sync) {
    #[cfg(feature = "parallel")]
    {
        let worker = &worker;
        rayon::scope(|s| {
            for _ in 0..copies.max(1) {
                s.spawn(move |_| worker());
            }
        });
    }
    #[cfg(not(feature = "parallel"))]
    {
        let _ = copies;
        worker();
    }
}

#[cfg(test)]
mod tests {
    use super::{for_each_mut, map_each, map_ranges, sort_unstable, sort_unstable_by};

    #[test]
    fn map_each_sort_and_loop_do_not_depend_on_the_threads() {
        let mut rng = crate::rng::SplitMix64::new(5);
        let values: Vec<(u32, u32)> = (0..100_000)
            .map(|_| (rng.below(1000) as u32, rng.below(7) as u32))
            .collect();
        let mut want = values.clone();
        want.sort_unstable();
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                for n in [0, 1, 7, 1001] {
                    assert_eq!(
                        map_each(n, |i| i * i),
                        (0..n).map(|i| i * i).collect::<Vec<_>>()
                    );
                }
                let mut got = values.clone();
                sort_unstable(&mut got);
                assert_eq!(got, want);
                // By a comparator: descending, ties by position (unique).
                let mut by: Vec<u32> = (0..values.len() as u32).collect();
                sort_unstable_by(&mut by, |&a, &b| {
                    values[b as usize].cmp(&values[a as usize]).then(a.cmp(&b))
                });
                let mut stable: Vec<u32> = (0..values.len() as u32).collect();
                stable.sort_by(|&a, &b| values[b as usize].cmp(&values[a as usize]));
                assert_eq!(by, stable);
                let mut buf = vec![0u32; 1000];
                let chunks: Vec<(usize, &mut [u32])> = buf.chunks_mut(100).enumerate().collect();
                for_each_mut(chunks, |(k, c)| c.iter_mut().for_each(|x| *x = k as u32));
                assert!(buf.iter().enumerate().all(|(i, &x)| x as usize == i / 100));
            });
        }
        // (The comparison can fail: the unsorted values are not sorted.)
        assert_ne!(values, want);
    }

    #[test]
    fn in_order_with_a_state_per_range() {
        for n in [0, 1, 7, 100, 1001] {
            // Each range counts its own calls: every state starts at 0.
            let out = map_ranges(
                n,
                || 0usize,
                |calls, i| {
                    *calls += 1;
                    (i * i, *calls)
                },
            );
            assert_eq!(out.len(), n);
            assert!(out.iter().enumerate().all(|(i, &(v, _))| v == i * i));
            assert!(out.iter().all(|&(_, c)| c >= 1));
            if n > 0 {
                assert_eq!(out[0].1, 1);
            }
        }
    }
}
