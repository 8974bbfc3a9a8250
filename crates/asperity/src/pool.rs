//! Where the iterative solvers run: on a thread of rayon's pool.
//!
//! A parallel pass started from a thread outside the pool (the program's main thread, a
//! Python thread) is injected into the pool: the caller sleeps on a latch and a worker is
//! woken for it, twice per pass. Started from a worker, the pass is forked where it is and
//! the other workers steal its halves. Measured on the 2-core machine of docs/bem.md
//! (an empty pass over 32 chunks): 12–14 µs from outside against 2 µs from a worker on 2
//! threads, 70 µs against 0.2 µs on one; a BCCG iteration makes about twenty passes.

/// Runs `op` on a worker of the current rayon pool: at once where the caller is one (a
/// study's lane, a test's pool), else by one injection for the whole of `op`.
pub(crate) fn on_worker<R: Send>(op: impl FnOnce() -> R + Send) -> R {
    rayon::join(op, || ()).0
}
