//! Deterministic data parallelism over slices: a slice is cut into chunks of a fixed length, each
//! chunk's work is done whole on one thread (rayon's pool with the `parallel` feature), and the
//! chunks' results come back in chunk order. A reduction summed from them in that order is the
//! same whatever the number of threads, and with or without the feature: only the chunk length
//! decides how the arithmetic is grouped. A slice of one chunk is worked on the calling thread
//! (handing a small product to the pool costs more than doing it).

#[cfg(feature = "parallel")]
use rayon::prelude::*;

/// Runs `work` on rayon's pool with the `parallel` feature: inline on a thread of the pool,
/// else handed to the pool once and waited for. The parallel loops inside it then split among
/// the pool's threads without each handing its work over from outside and waiting (a resting
/// cube of 34 295 tetrahedra stepped implicitly on one thread: 326 ms per frame with every loop
/// handed over, 181 ms entered once). Without the feature, on the calling thread.
pub(crate) fn on_pool<R: Send>(work: impl FnOnce() -> R + Send) -> R {
    #[cfg(feature = "parallel")]
    return rayon::scope(|_| work());
    #[cfg(not(feature = "parallel"))]
    work()
}

/// `a()` and `b()` at once, each on a thread of rayon's pool with the `parallel` feature (both
/// on the calling thread, one after the other, without it or on a pool of one thread): for
/// two pieces of work that share nothing.
pub(crate) fn both<RA: Send, RB: Send>(
    a: impl FnOnce() -> RA + Send,
    b: impl FnOnce() -> RB + Send,
) -> (RA, RB) {
    #[cfg(feature = "parallel")]
    return on_pool(|| rayon::join(a, b));
    #[cfg(not(feature = "parallel"))]
    (a(), b())
}

/// `work(index, chunk)` on each `chunk`-long piece of `data` (the last may be shorter), the
/// results in chunk order.
pub(crate) fn map_chunks<T: Send, R: Send>(
    data: &mut [T],
    chunk: usize,
    work: impl Fn(usize, &mut [T]) -> R + Sync + Send,
) -> Vec<R> {
    #[cfg(feature = "parallel")]
    if data.len() > chunk {
        return data
            .par_chunks_mut(chunk)
            .enumerate()
            .map(|(index, piece)| work(index, piece))
            .collect();
    }
    data.chunks_mut(chunk)
        .enumerate()
        .map(|(index, piece)| work(index, piece))
        .collect()
}

/// `work(index, a_chunk, b_chunk)` on the matching `chunk`-long pieces of two slices of one
/// length, the results in chunk order.
pub(crate) fn map_chunk_pairs<T: Send, U: Send, R: Send>(
    (a, b): (&mut [T], &mut [U]),
    chunk: usize,
    work: impl Fn(usize, &mut [T], &mut [U]) -> R + Sync + Send,
) -> Vec<R> {
    debug_assert_eq!(a.len(), b.len());
    #[cfg(feature = "parallel")]
    if a.len() > chunk {
        return a
            .par_chunks_mut(chunk)
            .zip(b.par_chunks_mut(chunk))
            .enumerate()
            .map(|(index, (a, b))| work(index, a, b))
            .collect();
    }
    a.chunks_mut(chunk)
        .zip(b.chunks_mut(chunk))
        .enumerate()
        .map(|(index, (a, b))| work(index, a, b))
        .collect()
}

/// `work(item)` on each of `items`, each on one thread.
pub(crate) fn for_each<T: Send>(items: &mut [T], work: impl Fn(&mut T) + Sync + Send) {
    #[cfg(feature = "parallel")]
    if items.len() > 1 {
        items.par_iter_mut().for_each(work);
        return;
    }
    items.iter_mut().for_each(work);
}

/// `work(item)` on each of `items`, the results in the items' order. The items start dearest
/// first by `expected` cost (equal costs in their order), each taken by the next thread free:
/// longest-first list scheduling of independent items, within `4/3 − 1/(3p)` of the shortest
/// time `p` threads can take when the expected costs are the true ones (7/6 on two), where
/// splitting the slice in halves can leave the dearest item for last on one thread while the
/// other waits. Each item's work is the same whichever thread does it.
pub(crate) fn map_dearest_first<T: Send, R: Send>(
    items: &mut [T],
    expected: impl Fn(&T) -> f64,
    work: impl Fn(&mut T) -> R + Sync + Send,
) -> Vec<R> {
    #[cfg(feature = "parallel")]
    if items.len() > 1 && threads() > 1 {
        use std::sync::Mutex;
        use std::sync::atomic::{AtomicUsize, Ordering};
        let mut order: Vec<usize> = (0..items.len()).collect();
        order.sort_by(|&a, &b| expected(&items[b]).total_cmp(&expected(&items[a])));
        let slots: Vec<Mutex<(&mut T, Option<R>)>> = items
            .iter_mut()
            .map(|item| Mutex::new((item, None)))
            .collect();
        let (next, helpers) = (AtomicUsize::new(0), threads().min(order.len()) - 1);
        let take_next = || {
            while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
                // Each slot is locked once, by the thread that took its index.
                let mut slot = slots[i]
                    .lock()
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                slot.1 = Some(work(&mut *slot.0));
            }
        };
        rayon::scope(|scope| {
            for _ in 0..helpers {
                scope.spawn(|_| take_next());
            }
            take_next();
        });
        return (slots.into_iter())
            .map(|slot| {
                let (_, result) = slot
                    .into_inner()
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                // Every index was taken once; a panicking `work` left the scope with its panic.
                result.expect("every item worked")
            })
            .collect();
    }
    #[cfg(not(feature = "parallel"))]
    let _ = expected;
    items.iter_mut().map(work).collect()
}

/// The threads work may be spread over: rayon's current pool's with the `parallel` feature, else
/// one.
pub(crate) fn threads() -> usize {
    #[cfg(feature = "parallel")]
    return rayon::current_num_threads();
    #[cfg(not(feature = "parallel"))]
    1
}

/// `work(range)` for each range of `chunk` (the last may be shorter) cutting `0..count`, the
/// results in order.
pub(crate) fn map_ranges<R: Send>(
    count: usize,
    chunk: usize,
    work: impl Fn(std::ops::Range<usize>) -> R + Sync + Send,
) -> Vec<R> {
    let range = |index: usize| work(index * chunk..((index + 1) * chunk).min(count));
    let chunks = count.div_ceil(chunk);
    #[cfg(feature = "parallel")]
    if chunks > 1 {
        return (0..chunks).into_par_iter().map(range).collect();
    }
    (0..chunks).map(range).collect()
}

/// `Σ term(range)` over the ranges of [`map_ranges`], their sums added in order.
pub(crate) fn sum_ranges(
    count: usize,
    chunk: usize,
    term: impl Fn(std::ops::Range<usize>) -> f64 + Sync + Send,
) -> f64 {
    map_ranges(count, chunk, term).iter().sum()
}

/// `Σ a_i b_i`, summed chunk by chunk (`chunk` entries each) and the chunks' sums in order.
pub(crate) fn dot(a: &[f64], b: &[f64], chunk: usize) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    sum_ranges(a.len(), chunk, |range| {
        a[range.clone()]
            .iter()
            .zip(&b[range])
            .map(|(a, b)| a * b)
            .sum()
    })
}

/// Sorts `items` (unstable: equal items may move, so give every item a distinct key for a
/// result that does not depend on the number of threads), on rayon's threads with the `parallel`
/// feature.
pub(crate) fn sort_unstable<T: Ord + Send>(items: &mut [T]) {
    #[cfg(feature = "parallel")]
    items.par_sort_unstable();
    #[cfg(not(feature = "parallel"))]
    items.sort_unstable();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same sums on a pool of one thread and of four: the grouping depends on the chunk
    /// length only (bit-identical, not within a tolerance).
    #[cfg(feature = "parallel")]
    #[test]
    fn sums_do_not_depend_on_the_threads() {
        let a: Vec<f64> = (0..10_007).map(|i| (i as f64 * 0.37).sin()).collect();
        let b: Vec<f64> = (0..10_007).map(|i| (i as f64 * 1.91).cos()).collect();
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            pool.install(|| {
                let mut c = a.clone();
                let partial = map_chunks(&mut c, 1000, |_, piece| {
                    piece.iter_mut().for_each(|v| *v *= 3.0);
                    piece.iter().sum::<f64>()
                });
                (dot(&a, &b, 1000), partial)
            })
        };
        let (one, four) = (on(1), on(4));
        assert_eq!(one.0.to_bits(), four.0.to_bits());
        assert_eq!(one.1, four.1);
        assert_eq!(one.1.len(), 11);
    }

    /// Every item is worked once, the results come back in the items' order, and the two
    /// dearest items are the first two taken (one by each thread of a pool of two); on one
    /// thread, the items' own order.
    #[cfg(feature = "parallel")]
    #[test]
    fn dearest_items_start_first() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let costs = [0.5, 3.0, 0.1, 2.0, 0.0, 1.0];
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            let started = AtomicUsize::new(0);
            let mut items: Vec<(f64, usize)> = costs.iter().map(|&c| (c, 0)).collect();
            let results = pool.install(|| {
                map_dearest_first(
                    &mut items,
                    |item| item.0,
                    |item| {
                        item.1 += 1;
                        (item.0 * 10.0, started.fetch_add(1, Ordering::SeqCst))
                    },
                )
            });
            assert!(
                items.iter().all(|item| item.1 == 1),
                "each item worked once"
            );
            results
        };
        let two = on(2);
        let values: Vec<f64> = two.iter().map(|r| r.0).collect();
        assert_eq!(values, costs.map(|c| c * 10.0));
        let mut first_two: Vec<usize> = (two.iter().enumerate())
            .filter(|(_, r)| r.1 < 2)
            .map(|(i, _)| i)
            .collect();
        first_two.sort_unstable();
        assert_eq!(first_two, vec![1, 3], "the costs 3.0 and 2.0 start first");
        let one: Vec<usize> = on(1).iter().map(|r| r.1).collect();
        assert_eq!(one, (0..costs.len()).collect::<Vec<_>>());
    }

    /// Pairs of slices are cut at the same places, the last chunk shorter.
    #[test]
    fn pairs_are_cut_alike() {
        let (mut a, mut b) = (vec![1.0; 25], vec![2.0; 25]);
        let lengths = map_chunk_pairs((&mut a, &mut b), 10, |index, a, b| {
            a.iter_mut().zip(b.iter()).for_each(|(a, b)| *a += b);
            (index, a.len(), b.len())
        });
        assert_eq!(lengths, vec![(0, 10, 10), (1, 10, 10), (2, 5, 5)]);
        assert!(a.iter().all(|&v| v == 3.0));
        assert_eq!(dot(&a, &b, 7), 25.0 * 6.0);
    }
}
