//! A head's per-disc work on rayon's pool, the dearest first.
//!
//! A head step hands its discs to the pool three times: their cut windows,
//! their cuts, their contacts. rayon splits an indexed iterator into halves
//! and lets an idle thread steal a half that has not been started, but a
//! half it is already running it finishes alone. The reference head's 8
//! tilted gauge discs are its last 8, and each costs four to six face discs
//! in the contact and up to twenty in the cut. On 2 threads, one thread
//! therefore ran all of them while the other waited: a step's contacts took
//! 590 µs of wall where half their summed time is 430 µs, and its cuts
//! lost as much again (`docs/head.md`, "The discs handed out dearest
//! first").
//!
//! [`dearest_first`] hands the items out one job each, in descending order
//! of what each took the last time (greedy list scheduling, longest first),
//! so the threads end at most about one of the cheapest items apart. It
//! times each item for the next call. The hints only order the work: each
//! item's result depends on the item alone and comes back in the items'
//! order, so results are the same for any hints and any number of threads.

use std::time::Instant;

use rayon::prelude::*;

/// Runs `f` on every item on rayon's current pool, one job an item, the
/// items with the largest hint (what the item took the last time, in any
/// unit: 0 when unknown) first, and equal hints in the items' order.
/// Returns each item's result with the nanoseconds it took, in the items'
/// order.
pub(crate) fn dearest_first<T, R, F>(items: Vec<(u64, T)>, f: F) -> Vec<(R, u64)>
where
    T: Send,
    R: Send,
    F: Fn(T) -> R + Sync,
{
    let mut jobs: Vec<(usize, u64, T)> = items
        .into_iter()
        .enumerate()
        .map(|(k, (hint, item))| (k, hint, item))
        .collect();
    // (a stable sort: equal hints keep the items' order)
    jobs.sort_by_key(|j| std::cmp::Reverse(j.1));
    let mut done: Vec<(usize, R, u64)> = jobs
        .into_par_iter()
        .with_max_len(1)
        .map(|(k, _, item)| {
            let start = Instant::now();
            let r = f(item);
            let took = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
            (k, r, took)
        })
        .collect();
    done.sort_unstable_by_key(|d| d.0);
    done.into_iter().map(|(_, r, took)| (r, took)).collect()
}

/// What a disc's work took the last time it was handed to the pool
/// (nanoseconds; 0 before the first time): the order [`dearest_first`]
/// hands the discs out. A hint, not state: it is neither saved nor
/// compared, and no result depends on it.
#[derive(Debug, Clone, Default)]
pub(crate) struct WorkHints {
    pub contact: std::cell::Cell<u64>,
    pub cut: std::cell::Cell<u64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Results come back in the items' order whatever the hints, each item
    /// run once, on a pool of one thread and of four.
    #[test]
    fn results_keep_the_items_order_for_any_hints() {
        let mut draw = crate::core::uniforms(7);
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for n in [0usize, 1, 2, 7, 56] {
                let hints: Vec<u64> = (0..n).map(|_| (draw() * 5.0) as u64).collect();
                let items: Vec<(u64, usize)> = hints.iter().copied().zip(0..n).collect();
                let runs = std::sync::atomic::AtomicUsize::new(0);
                let done = pool.install(|| {
                    dearest_first(items, |i| {
                        runs.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        i * i
                    })
                });
                let squares: Vec<usize> = done.iter().map(|d| d.0).collect();
                assert_eq!(squares, (0..n).map(|i| i * i).collect::<Vec<_>>());
                assert_eq!(runs.into_inner(), n);
            }
        }
    }

    /// On one thread the items run in the order of their hints, the largest
    /// first, equal hints in the items' order.
    #[test]
    fn one_thread_runs_the_dearest_first() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let items: Vec<(u64, usize)> = vec![(3, 0), (9, 1), (0, 2), (9, 3), (5, 4)];
        let order = std::sync::Mutex::new(Vec::new());
        pool.install(|| dearest_first(items, |i| order.lock().unwrap().push(i)));
        assert_eq!(order.into_inner().unwrap(), vec![1, 3, 4, 0, 2]);
    }
}
