//! Where the solvers run: on a thread of rayon's pool, with the other threads kept awake
//! while a solve has the pool to itself.
//!
//! A parallel pass started from a thread outside the pool (the program's main thread, a
//! Python thread) is injected into the pool: the caller sleeps on a latch and a worker is
//! woken for it, twice per pass. Started from a worker, the pass is forked where it is and
//! the other workers steal its halves. Measured on the 2-core machine of docs/bem_history.md
//! (an empty pass over 32 chunks): 12–14 µs from outside against 2 µs from a worker on 2
//! threads, 70 µs against 0.2 µs on one; a BCCG iteration makes about twenty passes.
//!
//! A worker that finds no job yields 32 times and then sleeps on a futex; a pass started
//! while it sleeps must wake it. A solve's passes are separated by serial stretches just
//! long enough for that, and on the virtual machine of docs/bem_history.md a wake is dear: 4–5 % of
//! the samples of 256² solves on 2 threads fell in the waking thread's `try_to_wake_up`,
//! and a pass waits for the sleeper to come back. So while a solve with
//! [`Parallelism::Exclusive`] runs, every other worker runs [`keep_awake`]: it executes
//! the pool's pending jobs as they appear ([`rayon::yield_now`]) and yields to the system
//! in between, as rayon's own idle loop does before it sleeps. Measured (`bench
//! bem-solve`, 256², 2 threads): solves 14–21 % faster (3–7 % at 512²), and their spread
//! gone. Not for a study's lanes ([`Parallelism::Shared`]): there every worker has its own
//! sample to solve, and a worker held awake for another lane's solve is one taken from its
//! own (`reproduce fig1 --quick` took 17.4 s against 15.4–15.9 s with keepers in every
//! solve).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use crate::bem::Parallelism;

/// Exclusive solves running now, in any pool. Keepers run only while there is one: two
/// solves started from two threads would otherwise hold each other's workers (a keeper
/// landing on a worker that waits inside the other solve holds that solve until its own
/// ends).
static EXCLUSIVE: AtomicUsize = AtomicUsize::new(0);

/// A keeper that has found no job for this long goes back to rayon's idle loop (and to
/// sleep): far longer than any serial stretch of a solve (the first solve of a process
/// faults its fields in serially for more than 1 ms, measured at 256²), short against a
/// whole solve.
const MAX_IDLE: Duration = Duration::from_millis(10);

/// Runs `op` on a worker of the current rayon pool: at once where the caller is one (the
/// CLI's command, a study's lane, a test's pool), else by one injection for the whole of
/// `op`. With [`Parallelism::Exclusive`], the pool's other workers are kept awake until it
/// returns (see the module docs).
pub(crate) fn on_worker<R: Send>(parallelism: Parallelism, op: impl FnOnce() -> R + Send) -> R {
    if parallelism == Parallelism::Shared || rayon::current_num_threads() < 2 {
        // On a worker, `join` runs `op` in place; from outside, it injects it once.
        return rayon::join(op, || ()).0;
    }
    let stop = &AtomicBool::new(false);
    rayon::scope(|scope| {
        let _exclusive = Exclusive::enter(stop);
        let owner = rayon::current_thread_index();
        scope.spawn_broadcast(move |_, worker| {
            if Some(worker.index()) != owner {
                keep_awake(stop, &EXCLUSIVE, MAX_IDLE);
            }
        });
        op()
    })
}

/// One exclusive solve, counted in [`EXCLUSIVE`] from `enter` until dropped; its keepers
/// stop when it is dropped (when `op` returns or panics).
struct Exclusive<'a>(&'a AtomicBool);

impl<'a> Exclusive<'a> {
    fn enter(stop: &'a AtomicBool) -> Self {
        EXCLUSIVE.fetch_add(1, Ordering::AcqRel);
        Exclusive(stop)
    }
}

impl Drop for Exclusive<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
        EXCLUSIVE.fetch_sub(1, Ordering::AcqRel);
    }
}

/// Executes the pool's pending jobs until `stop` is set, more than one exclusive solve runs
/// (`exclusive`, see [`EXCLUSIVE`]), or no job has come for `max_idle` ([`MAX_IDLE`]).
fn keep_awake(stop: &AtomicBool, exclusive: &AtomicUsize, max_idle: Duration) {
    let mut idle_since: Option<Instant> = None;
    while !stop.load(Ordering::Acquire) && exclusive.load(Ordering::Acquire) <= 1 {
        match rayon::yield_now() {
            Some(rayon::Yield::Executed) => idle_since = None,
            Some(rayon::Yield::Idle) => {
                if idle_since.get_or_insert_with(Instant::now).elapsed() > max_idle {
                    return;
                }
                std::thread::yield_now();
            }
            None => return,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// A parallel sum over chunks (a pass of a solve, in miniature).
    fn pass(n: u64) -> u64 {
        let values: Vec<u64> = (0..n).collect();
        values.par_chunks(1000).map(|c| c.iter().sum::<u64>()).sum()
    }

    /// The sum of `0..n`, by formula.
    fn expected(n: u64) -> u64 {
        n * (n - 1) / 2
    }

    #[test]
    fn ops_run_on_a_worker_and_return_their_value_from_inside_and_outside_pools() {
        for parallelism in [Parallelism::Exclusive, Parallelism::Shared] {
            let outside = on_worker(parallelism, || {
                (rayon::current_thread_index(), pass(1e5 as u64))
            });
            assert!(outside.0.is_some(), "{parallelism:?}: ran outside the pool");
            assert_eq!(outside.1, expected(1e5 as u64));
            for threads in [1, 2, 3] {
                let inside = crate::test_support::with_threads(threads, || {
                    (0..20)
                        .map(|_| on_worker(parallelism, || pass(1e5 as u64)))
                        .collect::<Vec<_>>()
                });
                assert!(inside.iter().all(|&s| s == expected(1e5 as u64)));
            }
        }
    }

    #[test]
    fn exclusive_ops_started_from_several_threads_all_finish() {
        // Each op's keepers would hold the workers the others wait for: they stand down
        // while more than one exclusive op runs, so all finish promptly.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let started = Instant::now();
        std::thread::scope(|threads| {
            for t in 0..4u64 {
                let pool = &pool;
                threads.spawn(move || {
                    for i in 0..5 {
                        let n = 10_000 * (t + i + 2);
                        let passes = || (0..100).map(|_| pass(n)).collect::<Vec<_>>();
                        let sums = pool.install(|| on_worker(Parallelism::Exclusive, passes));
                        assert!(sums.iter().all(|&s| s == expected(n)));
                    }
                });
            }
        });
        // Only a deadlock (keepers holding the workers the other ops wait for) takes this
        // long; a loaded machine takes seconds.
        assert!(started.elapsed() < DEADLOCK, "{:?}", started.elapsed());
    }

    /// Longer than any stall of a loaded machine: a bounded wait that only a deadlock
    /// (the property under test broken) runs out.
    const DEADLOCK: Duration = Duration::from_secs(60);

    /// Waits until `flag` is set; false if [`DEADLOCK`] passes first.
    fn wait_for(flag: &AtomicBool) -> bool {
        let started = Instant::now();
        while !flag.load(Ordering::Acquire) {
            if started.elapsed() > DEADLOCK {
                return false;
            }
            std::thread::yield_now();
        }
        true
    }

    /// What a keeper did: how long it ran, and whether it returned only once stopped.
    struct Kept {
        ran: Duration,
        stopped: bool,
    }

    /// Runs `keep_awake(stop, exclusive, max_idle)` on one worker of a 2-thread pool while
    /// the other runs `op(stop, keeper_returned)` once the keeper has started (so the test
    /// never depends on when the other worker steals the keeper); returns what `op`
    /// returned and what the keeper did.
    fn beside_a_keeper<R: Send>(
        (exclusive, max_idle): (usize, Duration),
        op: impl FnOnce(&AtomicBool, &AtomicBool) -> R + Send,
    ) -> (R, Kept) {
        let (stop, exclusive) = (AtomicBool::new(false), AtomicUsize::new(exclusive));
        let (started, returned) = (AtomicBool::new(false), AtomicBool::new(false));
        crate::test_support::with_threads(2, || {
            // The keeper is the second half of the join: the other worker steals it while
            // this one waits for it to start.
            rayon::join(
                || {
                    assert!(wait_for(&started), "the keeper never started");
                    op(&stop, &returned)
                },
                || {
                    started.store(true, Ordering::Release);
                    let begun = Instant::now();
                    keep_awake(&stop, &exclusive, max_idle);
                    let kept = Kept {
                        ran: begun.elapsed(),
                        stopped: stop.load(Ordering::Acquire),
                    };
                    returned.store(true, Ordering::Release);
                    kept
                },
            )
        })
    }

    /// Issue 33 item 16: no timing in the assertion. Each of 50 jobs is pushed by one
    /// worker that then spins until the job has run: only the keeper on the other worker
    /// can run it, so a keeper that did not run pending jobs deadlocks (the bounded wait
    /// fails). Idle time never stands it down here (`max_idle` of a minute).
    #[test]
    fn a_keeper_runs_the_pending_jobs_until_stopped() {
        let alone = (1, DEADLOCK);
        let (runners, kept) = beside_a_keeper(alone, |stop, _| {
            let owner = rayon::current_thread_index();
            let mut runners = std::collections::BTreeSet::new();
            for _ in 0..50 {
                let ran = AtomicBool::new(false);
                let ((), runner) = rayon::join(
                    || assert!(wait_for(&ran), "the keeper did not run the job"),
                    || {
                        ran.store(true, Ordering::Release);
                        (rayon::current_thread_index(), expected(64_000))
                    },
                );
                assert_eq!(runner.1, expected(64_000));
                runners.insert(runner.0);
            }
            stop.store(true, Ordering::Release);
            (owner, runners)
        });
        let (owner, runners) = runners;
        assert_eq!(runners.len(), 1, "{runners:?}");
        assert_ne!(runners.first().copied(), Some(owner), "run by the keeper");
        assert!(kept.stopped, "kept awake until stopped, ran {:?}", kept.ran);
    }

    #[test]
    fn a_keeper_stands_down_beside_another_exclusive_op_or_when_idle() {
        // Two exclusive ops: it returns without being stopped (the op waits for that).
        let two = (2, DEADLOCK);
        let (done, kept) = beside_a_keeper(two, |stop, returned| {
            let done = wait_for(returned);
            stop.store(true, Ordering::Release);
            done
        });
        assert!(done && !kept.stopped, "stood down on its own");
        // Alone but given no job: it returns after MAX_IDLE, not before, unstopped.
        let alone = (1, MAX_IDLE);
        let (done, kept) = beside_a_keeper(alone, |stop, returned| {
            let done = wait_for(returned);
            stop.store(true, Ordering::Release);
            done
        });
        assert!(done && !kept.stopped, "stood down on its own");
        assert!(kept.ran >= MAX_IDLE, "{:?}", kept.ran);
    }

    #[test]
    fn a_panicking_op_stops_its_keepers_and_propagates() {
        crate::test_support::with_threads(2, || {
            let result = std::panic::catch_unwind(|| {
                on_worker(Parallelism::Exclusive, || -> u64 {
                    panic!("inside the op")
                })
            });
            assert!(result.is_err());
            // The keepers stopped and the count came back: the next op runs as usual.
            assert_eq!(
                on_worker(Parallelism::Exclusive, || pass(5000)),
                expected(5000)
            );
        });
    }
}
