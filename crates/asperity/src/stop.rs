//! [`Stop`]: a request, from another thread, that a long computation stop early.
//!
//! Iterative solvers cannot be killed from outside without losing their state, and a
//! front end (Ctrl-C in a terminal, a `KeyboardInterrupt` in Python, a GUI's cancel
//! button) must not wait for a solve of many seconds to end. So the computation polls a
//! shared flag at points where stopping leaves it consistent — once per iteration of the
//! contact solvers ([`crate::bem::ContactSolver::with_stop`]) — and returns an error
//! ([`crate::bem::SolveError::Interrupted`]) there. The same pattern (a shared atomic flag
//! handed to the solver, polled once per iteration) is the usual cancellation design of
//! numerical libraries; polling costs one relaxed atomic load.
//!
//! The flag stays set until [`Stop::clear`]: everything that shares it stops at its next
//! check, and the caller clears it before the next computation that should run.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A shared stop request: clones share one flag. [`Stop::default`] is a fresh, unset flag.
#[derive(Debug, Clone, Default)]
pub struct Stop(Arc<AtomicBool>);

impl Stop {
    /// A fresh, unset flag.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks every computation sharing this flag to stop at its next check.
    pub fn request(&self) {
        // Relaxed: the flag publishes no other data; the check only has to see it soon.
        self.0.store(true, Ordering::Relaxed);
    }

    /// Withdraws the request (before the next computation that should run).
    pub fn clear(&self) {
        self.0.store(false, Ordering::Relaxed);
    }

    /// Whether a stop was requested (one relaxed atomic load).
    #[inline]
    pub fn is_requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_flag_and_clear_withdraws_it() {
        let stop = Stop::new();
        let other = stop.clone();
        assert!(!other.is_requested());
        stop.request();
        assert!(other.is_requested());
        // A separate flag is untouched.
        assert!(!Stop::default().is_requested());
        other.clear();
        assert!(!stop.is_requested());
    }

    #[test]
    fn a_request_from_another_thread_is_seen() {
        let stop = Stop::new();
        let remote = stop.clone();
        std::thread::spawn(move || remote.request()).join().unwrap();
        assert!(stop.is_requested());
    }
}
