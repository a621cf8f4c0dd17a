//! Batches of items worked on the worker pool and handed over in order, with no barrier
//! between batches.
//!
//! ```text
//! spawn:  the items of batches 0 and 1, one pool task each, oldest first (FIFO)
//! loop:   wait for batch i (the waiting thread runs pending tasks meanwhile),
//!         write(batch i, its results in item order), spawn the items of batch i + 2
//! ```
//! At most two batches are held at once, as when batch i + 1 was built beside the writing
//! of batch i and the two then joined. The join was a barrier: a worker that finished its
//! share of a batch idled until the batch's largest clip was done (measured: `docs/decisions.md`,
//! "Measurements of the build engine"). Here it takes the next batch's items instead. The
//! batches, their order and the results are the same, so the outputs are too.
//!
//! A panic in a task or in `write` is carried to the caller after the other tasks end,
//! even when `write` has failed meanwhile; an error from `write` is returned once the
//! tasks already spawned have ended (those not yet started skip their work).

use std::collections::VecDeque;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError};
use std::time::Duration;

use super::sink::Defer;
use crate::error::{Error, Result};

/// Batches spawned ahead of the one being waited for or written.
const AHEAD: usize = 1;

/// How long the waiting thread sleeps when the pool has no task for it, before it looks
/// again (a task's own parallel work may have queued some).
const IDLE_WAIT: Duration = Duration::from_millis(1);

/// One finished item: batch, item, result or panic.
type Done<R> = (usize, usize, std::thread::Result<Option<R>>);

/// The results of one batch as they arrive.
struct Slots<R> {
    results: Vec<Option<R>>,
    missing: usize,
}

/// Run `work` on every item of every batch on the current rayon pool and call `write` with
/// each batch and its results, in item order, batch after batch. `write` runs on the
/// calling thread; while it waits for a batch, that thread runs the pool's pending tasks
/// (called outside a pool, the tasks go to the global pool and the caller only waits).
///
/// # Errors
/// The first error of `write`; the batches after it are not written.
///
/// # Panics
/// When `work` or `write` panics, with its payload, once the spawned tasks have ended.
pub fn in_order<B, T, R>(
    batches: &[B],
    items: impl Fn(&B) -> &[T],
    work: impl Fn(&T) -> R + Sync,
    mut write: impl FnMut(&B, Vec<R>) -> Result<()>,
) -> Result<()>
where
    T: Sync,
    R: Send,
{
    let stop = AtomicBool::new(false);
    let (tx, rx) = channel::<Done<R>>();
    let (items, work, stop_ref) = (&items, &work, &stop);
    let outcome = rayon::in_place_scope_fifo(|scope| {
        // However this ends (an error, a panic here or in a task), the tasks not yet
        // started skip their work.
        let _stop = Defer::new(|| stop_ref.store(true, Ordering::Relaxed));
        let spawn = |b: usize| -> Slots<R> {
            let list = items(&batches[b]);
            for (k, item) in list.iter().enumerate() {
                let tx = tx.clone();
                scope.spawn_fifo(move |_| {
                    // Every task must send, panic or not: the wait below counts on it (a
                    // sender stays alive, so a missing message would not end the wait).
                    let r = catch_unwind(AssertUnwindSafe(|| {
                        (!stop_ref.load(Ordering::Relaxed)).then(|| work(item))
                    }));
                    // The receiver lives until every task has ended (the scope waits).
                    let _ = tx.send((b, k, r));
                });
            }
            Slots {
                results: (0..list.len()).map(|_| None).collect(),
                missing: list.len(),
            }
        };
        let mut open: VecDeque<Slots<R>> = (0..batches.len().min(AHEAD + 1)).map(spawn).collect();
        for b in 0..batches.len() {
            while open[0].missing > 0 {
                let (db, k, r) = next_done(&rx)?;
                let slots = &mut open[db - b];
                slots.results[k] = r.unwrap_or_else(|panic| resume_unwind(panic));
                slots.missing -= 1;
            }
            let done = open.pop_front().map(|s| s.results).unwrap_or_default();
            // `stop` is set only when this returns, so every task of the batch ran its work.
            let done: Option<Vec<R>> = done.into_iter().collect();
            write(&batches[b], done.ok_or_else(skipped)?)?;
            if b + AHEAD + 1 < batches.len() {
                open.push_back(spawn(b + AHEAD + 1));
            }
        }
        Ok(())
    });
    // A task of the next batch may have panicked while `write` failed: the panic wins, as
    // it would have had the batch been joined.
    if outcome.is_err() {
        if let Some(panic) = rx.try_iter().find_map(|(_, _, r)| r.err()) {
            resume_unwind(panic);
        }
    }
    outcome
}

/// The error of a batch handed over with a result missing (a task skipped its work).
fn skipped() -> Error {
    Error::invalid("worker pool", "a batch's task ended without its result")
}

/// The next finished item, running the pool's pending tasks while none is in.
///
/// # Errors
/// Every sender is gone (cannot happen while [`in_order`] holds one).
fn next_done<R>(rx: &Receiver<Done<R>>) -> Result<Done<R>> {
    loop {
        if let Ok(d) = rx.try_recv() {
            return Ok(d);
        }
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            continue;
        }
        match rx.recv_timeout(IDLE_WAIT) {
            Ok(d) => return Ok(d),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => return Err(skipped()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::in_order;
    use crate::error::Error;
    use proptest::prelude::*;
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a test pool")
    }

    /// [`in_order`] over `batches` on a pool of `threads`.
    fn run(
        threads: usize,
        batches: &[Vec<u64>],
        work: impl Fn(&u64) -> u64 + Sync + Send,
        write: impl FnMut(&Vec<u64>, Vec<u64>) -> crate::error::Result<()> + Send,
    ) -> crate::error::Result<()> {
        pool(threads).install(|| in_order(batches, |b| b.as_slice(), work, write))
    }

    /// [`slow_square`], counting the items it started on `started`.
    fn counted(started: &AtomicUsize) -> impl Fn(&u64) -> u64 + Sync + Send + '_ {
        move |x| {
            started.fetch_add(1, Ordering::SeqCst);
            slow_square(x)
        }
    }

    /// Work whose time varies with the item, so items finish out of order.
    fn slow_square(x: &u64) -> u64 {
        let mut acc = *x;
        for i in 0..(x % 7) * 20_000 {
            acc = std::hint::black_box(acc.wrapping_add(i));
        }
        std::hint::black_box(acc);
        x * x
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        // Every batch is written once, in order, with its items' results in item order;
        // and no item of batch b + 2 has started when batch b is written (two batches in
        // memory at most).
        #[test]
        fn batches_are_written_in_order_two_at_most_in_flight(
            sizes in proptest::collection::vec(0usize..9, 0..12),
            threads in 1usize..5,
        ) {
            let mut next = 0u64;
            let batches: Vec<Vec<u64>> = sizes
                .iter()
                .map(|&n| (0..n).map(|_| { next += 1; next }).collect())
                .collect();
            let started = AtomicUsize::new(0);
            let mut written: Vec<Vec<u64>> = Vec::new();
            let mut most_ahead = Vec::new();
            run(threads, &batches, counted(&started), |_, results| {
                let through_next: usize =
                    batches.iter().take(written.len() + 2).map(Vec::len).sum();
                most_ahead.push((started.load(Ordering::SeqCst), through_next));
                written.push(results);
                Ok(())
            })
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
            let expected: Vec<Vec<u64>> = batches
                .iter()
                .map(|b| b.iter().map(|x| x * x).collect())
                .collect();
            prop_assert_eq!(written, expected);
            for (started, bound) in most_ahead {
                prop_assert!(started <= bound, "{started} items started, at most {bound}");
            }
        }
    }

    /// Batches 0..10 of four items; `write` fails on the third batch. The number of items
    /// whose work ran, and the error.
    fn fail_third_write(threads: usize) -> (usize, Error) {
        let batches: Vec<Vec<u64>> = (0..10).map(|b| (b * 4..b * 4 + 4).collect()).collect();
        let started = AtomicUsize::new(0);
        let mut written = 0;
        let r = run(threads, &batches, counted(&started), |_, _| {
            written += 1;
            if written == 3 {
                return Err(Error::invalid("table", "disk full"));
            }
            Ok(())
        });
        assert_eq!(written, 3, "no batch is written after the failure");
        (
            started.load(Ordering::SeqCst),
            r.expect_err("the write's error comes back"),
        )
    }

    #[test]
    fn an_error_from_write_stops_the_batches_after_it() {
        // One thread runs the tasks in order: batches 0..=2 ran, batch 3 was spawned but
        // skipped its work, nothing after it was spawned.
        let (started, e) = fail_third_write(1);
        assert!(e.to_string().contains("disk full"), "{e}");
        assert_eq!(started, 12);
        // More threads may start batch 3 before the failure, never batch 4.
        for threads in [2, 3] {
            let (started, e) = fail_third_write(threads);
            assert!(e.to_string().contains("disk full"), "{e}");
            assert!(started <= 16, "{started} items started");
        }
    }

    #[test]
    fn nested_parallel_work_and_writes_give_the_same_results() {
        let batches: Vec<Vec<u64>> = (0..7).map(|b| (b * 5..b * 5 + 5).collect()).collect();
        for threads in 1..=4 {
            let mut sums = Vec::new();
            run(
                threads,
                &batches,
                // Parallel work inside a task, as an ingest's own rayon calls.
                |x| (0..*x * 50).into_par_iter().map(|i| i % 7).sum::<u64>(),
                // And inside the write, as the tables' parallel encoding.
                |_, r| {
                    let (a, b) = rayon::join(|| r.iter().sum::<u64>(), || r.len());
                    sums.push((a, b));
                    Ok(())
                },
            )
            .expect("no error");
            let expected: Vec<(u64, usize)> = batches
                .iter()
                .map(|b| {
                    let s = b.iter().map(|x| (0..x * 50).map(|i| i % 7).sum::<u64>());
                    (s.sum(), b.len())
                })
                .collect();
            assert_eq!(sums, expected, "{threads} threads");
        }
    }

    /// The text of the panic that `in_order` over 6 batches of 3 items (0..18) on
    /// `threads` threads ends with (the test fails if it returns).
    fn panic_text(
        threads: usize,
        work: impl Fn(&u64) -> u64 + Sync + Send,
        write: impl FnMut(&Vec<u64>, Vec<u64>) -> crate::error::Result<()> + Send,
    ) -> String {
        let batches: Vec<Vec<u64>> = (0..6).map(|b| (b * 3..b * 3 + 3).collect()).collect();
        let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            run(threads, &batches, work, write)
        }));
        let payload = caught.expect_err("the panic reaches the caller");
        payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_default()
    }

    #[test]
    fn a_panic_in_a_task_or_a_write_reaches_the_caller_and_nothing_hangs() {
        for threads in [1, 2, 3] {
            let item = |x: &u64| {
                assert!(*x != 7, "item 7 fails");
                slow_square(x)
            };
            let text = panic_text(threads, item, |_, _| Ok(()));
            assert!(text.contains("item 7 fails"), "{threads} threads: {text}");
            // A panic in the write itself.
            let write = |b: &Vec<u64>, _| {
                assert!(b[0] != 6, "write of batch 2 fails");
                Ok(())
            };
            let text = panic_text(threads, slow_square, write);
            assert!(text.contains("batch 2"), "{threads} threads: {text}");
            // A task of batch 1 panics while the write of batch 0 fails: the panic wins.
            let item = |x: &u64| {
                assert!(*x != 4, "item 4 fails");
                *x
            };
            let write = |_: &Vec<u64>, _| {
                // Let batch 1 run before failing, whatever the thread count.
                while rayon::yield_now() == Some(rayon::Yield::Executed) {}
                Err(Error::invalid("table", "disk full"))
            };
            let text = panic_text(threads, item, write);
            assert!(text.contains("item 4"), "{threads} threads: {text}");
        }
    }
}
