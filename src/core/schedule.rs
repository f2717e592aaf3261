//! A head's per-disc work on rayon's pool, the dearest first.
//!
//! A head step hands its discs to the pool three times at each of its cut
//! times: their cut windows, their cuts, and at the end their contacts.
//! rayon splits an indexed iterator into halves and lets an idle thread
//! steal a half that has not been started, but a half it is already
//! running it finishes alone. The reference head's 8 tilted gauge discs
//! are its last 8, and each costs four to six face discs in the contact
//! and up to twenty in the cut. On 2 threads, one thread therefore ran all
//! of them while the other waited: a step's contacts took 590 µs of wall
//! where half their summed time is 430 µs, and its cuts lost as much again
//! (`docs/head.md`, "The discs handed out dearest first").
//!
//! [`dearest_first`] hands the cuts and the contacts out one job each, in
//! descending order of what each took the last time (greedy list
//! scheduling, longest first), so the threads end at most about one of the
//! cheapest items apart. It times each item for the next call. The hints
//! only order the work: each item's result depends on the item alone and
//! comes back in the items' order, so results are the same for any hints
//! and any number of threads. On a pool of one thread it runs the items on
//! the calling thread. (The windows, a few µs each, keep rayon's own split:
//! through this function a step took 6 % longer.)

use std::time::Instant;

use rayon::prelude::*;

/// Runs `f` on every item on rayon's current pool, one job an item, the
/// items with the largest hint (what the item took the last time, in any
/// unit: 0 when unknown) first, and equal hints in the items' order.
/// Returns each item's result with the nanoseconds it took (0 on a pool of
/// one thread, where nothing is ordered), in the items' order.
pub(crate) fn dearest_first<T, R, F>(items: Vec<(u64, T)>, f: F) -> Vec<(R, u64)>
where
    T: Send,
    R: Send,
    F: Fn(T) -> R + Sync,
{
    // one thread: on the calling thread, in the items' order, untimed
    // (handing each phase of a head step to the pool's one worker and
    // waiting for it was a quarter of the reference head's step on one
    // thread)
    if rayon::current_num_threads() <= 1 {
        return items.into_iter().map(|(_, item)| (f(item), 0)).collect();
    }
    let mut done: Vec<(usize, R, u64)> = dearest_order(items)
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

/// The items numbered in their order, then sorted by hint, the largest
/// first, equal hints in the items' order.
fn dearest_order<T>(items: Vec<(u64, T)>) -> Vec<(usize, u64, T)> {
    let mut jobs: Vec<(usize, u64, T)> = items
        .into_iter()
        .enumerate()
        .map(|(k, (hint, item))| (k, hint, item))
        .collect();
    // (a stable sort: equal hints keep the items' order)
    jobs.sort_by_key(|j| std::cmp::Reverse(j.1));
    jobs
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

    /// The work is handed out by hint, the largest first, equal hints in
    /// the items' order; on one thread it runs in the items' order.
    #[test]
    fn the_dearest_go_first_and_one_thread_keeps_the_order() {
        let items = || vec![(3, 'a'), (9, 'b'), (0, 'c'), (9, 'd'), (5, 'e')];
        let order: Vec<char> = dearest_order(items()).into_iter().map(|j| j.2).collect();
        assert_eq!(order, vec!['b', 'd', 'e', 'a', 'c']);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let ran = std::sync::Mutex::new(Vec::new());
        pool.install(|| dearest_first(items(), |c| ran.lock().unwrap().push(c)));
        assert_eq!(ran.into_inner().unwrap(), vec!['a', 'b', 'c', 'd', 'e']);
    }
}
