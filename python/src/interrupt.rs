//! Long computations with the GIL released, interruptible by Ctrl-C.
//!
//! Python runs its signal handlers (the `KeyboardInterrupt` of Ctrl-C) only on the main
//! thread and only while that thread holds the GIL. So [`run_detached`] releases the GIL,
//! runs the work on a helper thread and keeps the calling thread waiting on it, waking
//! every [`POLL`] to take the GIL for a moment and run the handlers
//! (`Python::check_signals`). A raised signal (or an exception of the user's progress
//! callback, see [`Cancel::call`]) sets the [`Cancel`] flag, the library's [`Stop`], which
//! the work checks between its steps (loads of a sweep, samples of a study) and which a
//! contact solver given the same flag ([`run_detached_with`],
//! `ContactSolver::with_stop`) polls once per iteration, so that even a single long solve
//! ends within an iteration; the exception is re-raised once the work has returned.
//!
//! The helper thread runs the work inside a rayon pool of the calling Python thread
//! ([`calling_thread_pool`]), so that the library's parallel loops start on a pool thread
//! directly instead of being handed from an outside thread to the pool loop by loop (that
//! hand-over cost a 256² free solve 17 %). One pool per calling Python thread, not rayon's
//! global one: two Python threads then never wait for each other's work, whatever the
//! number of threads per pool (`RAYON_NUM_THREADS`, default one per core).

use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

use asperity::stop::Stop;
use pyo3::prelude::*;

/// How often the waiting thread runs Python's signal handlers.
pub const POLL: Duration = Duration::from_millis(50);

/// Set when the work is to stop; holds the exception that stopped it.
pub struct Cancel {
    flag: Stop,
    error: Mutex<Option<PyErr>>,
}

impl Cancel {
    /// Whether the work should stop now.
    pub fn is_set(&self) -> bool {
        self.flag.is_requested()
    }

    /// Stops the work with `error` (the first error is kept).
    pub fn fail(&self, error: PyErr) {
        let mut slot = self.error.lock().unwrap_or_else(|e| e.into_inner());
        slot.get_or_insert(error);
        self.flag.request();
    }

    /// Calls the user's `progress(done, total)` (if any) with the GIL; an exception it
    /// raises stops the work.
    pub fn call(&self, progress: Option<&Py<PyAny>>, done: usize, total: usize) {
        if let Some(callback) = progress {
            if let Err(e) = Python::attach(|py| callback.call1(py, (done, total)).map(drop)) {
                self.fail(e);
            }
        }
    }

    fn take(&self) -> Option<PyErr> {
        self.error.lock().unwrap_or_else(|e| e.into_inner()).take()
    }
}

/// Runs `work` without the GIL on a helper thread while this thread watches for signals
/// (module docs). Returns the work's result, or the exception that cancelled it.
pub fn run_detached<R: Send>(
    py: Python<'_>,
    work: impl FnOnce(&Cancel) -> R + Send,
) -> PyResult<R> {
    run_detached_with(py, &Stop::new(), work)
}

/// [`run_detached`] with `stop` as the cancel flag: the flag a contact solver polls. A
/// request left over from an earlier interrupted call is withdrawn first.
pub fn run_detached_with<R: Send>(
    py: Python<'_>,
    stop: &Stop,
    work: impl FnOnce(&Cancel) -> R + Send,
) -> PyResult<R> {
    stop.clear();
    let cancel = Cancel {
        flag: stop.clone(),
        error: Mutex::new(None),
    };
    let pool = calling_thread_pool()?;
    let result = py.detach(|| {
        std::thread::scope(|scope| {
            let (sender, receiver) = mpsc::channel();
            let cancel = &cancel;
            scope.spawn(move || {
                let _ = sender.send(pool.install(|| work(cancel)));
            });
            loop {
                match receiver.recv_timeout(POLL) {
                    Ok(result) => return Some(result),
                    Err(mpsc::RecvTimeoutError::Timeout) => {
                        if !cancel.is_set() {
                            if let Err(e) = Python::attach(|py| py.check_signals()) {
                                cancel.fail(e);
                            }
                        }
                    }
                    // The work panicked; the scope re-raises its panic when it ends.
                    Err(mpsc::RecvTimeoutError::Disconnected) => return None,
                }
            }
        })
    });
    match (cancel.take(), result) {
        (Some(error), _) => Err(error),
        (None, Some(result)) => Ok(result),
        (None, None) => Err(pyo3::exceptions::PyRuntimeError::new_err(
            "the computation stopped unexpectedly",
        )),
    }
}

thread_local! {
    /// The rayon pool of this (Python) thread and the process it was built in, built on its
    /// first long computation and dropped, with its threads, when the thread ends.
    static POOL: std::cell::RefCell<Option<(u32, Arc<rayon::ThreadPool>)>> =
        const { std::cell::RefCell::new(None) };
}

/// The calling thread's own rayon pool (module docs): as many threads as rayon's global pool
/// would have (`RAYON_NUM_THREADS`, else one per core).
///
/// A process forked after the pool was built (Python's `multiprocessing` forks by default)
/// inherits the pool without its threads: work handed to it would wait forever. So a pool
/// is used only in the process that built it; a forked child builds its own (the parent's,
/// whose threads do not exist here, is leaked rather than dropped: dropping it would signal
/// threads that are not there).
fn calling_thread_pool() -> PyResult<Arc<rayon::ThreadPool>> {
    let pid = std::process::id();
    POOL.with(|cell| {
        let mut slot = cell.borrow_mut();
        match slot.take() {
            Some((built_in, pool)) if built_in == pid => {
                *slot = Some((built_in, Arc::clone(&pool)));
                return Ok(pool);
            }
            Some((_, inherited)) => std::mem::forget(inherited),
            None => {}
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .thread_name(|i| format!("asperity-{i}"))
            .build()
            .map_err(|e| {
                pyo3::exceptions::PyRuntimeError::new_err(format!(
                    "cannot start asperity's worker threads: {e}"
                ))
            })?;
        let pool = Arc::new(pool);
        *slot = Some((pid, Arc::clone(&pool)));
        Ok(pool)
    })
}
