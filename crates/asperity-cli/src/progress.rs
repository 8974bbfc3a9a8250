//! Progress reporting: an indicatif bar with ETA on a terminal, plain log lines otherwise
//! (indicatif hides its bar when stderr is not a terminal).
//!
//! # The ETA
//! The estimate is `elapsed / work done in this run × work left` (the front-end layer's
//! [`Eta`], which Python's progress bars use too), where
//!
//! * only steps done in this run count as done work: steps read back from a checkpoint
//!   ([`Progress::restore`]) move the bar but not the rate, so a resumed study does not
//!   look faster than it is;
//! * steps may weigh differently ([`Progress::weighted`]): a study weighs each sample by
//!   its cost, `N² log₂ N` for BEM and `N log₂ N` for MDR
//!   ([`asperity::study::sample_cost`]), so a sweep whose large grids come last does not
//!   promise to end early. A BEM study counts solved loads (24 a sample, each a 24th of
//!   its sample's cost), so that the line and its ETA move while a large sample runs.
//!
//! Until a step is done in this run the ETA is unknown (`?` on the bar; no log line).

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use asperity_app::study::progress::{log_line, Eta};
use indicatif::{HumanDuration, ProgressBar, ProgressState, ProgressStyle};

/// The least time between two lines of progress inside one solve ([`Progress::solve_monitor`]).
pub const SOLVE_EVERY: f64 = 2.0;

/// `--progress SECONDS`: a finite number of seconds, zero or more.
pub fn parse_seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "{text:?} is not a number of seconds (finite, 0 or more)"
        )),
    }
}

/// Whether to report progress inside each solve: asked for (`--progress`, with the hidden
/// `--progress-every SECONDS` of the tests), or on a terminal unless `--quiet`. Returns the
/// least seconds between two lines ([`SOLVE_EVERY`] unless given).
pub fn solve_progress((asked, every): (bool, Option<f64>), quiet: bool) -> Option<f64> {
    let shown = asked || every.is_some() || (!quiet && std::io::stderr().is_terminal());
    shown.then_some(every.unwrap_or(SOLVE_EVERY))
}

/// The line of progress inside a solve.
fn solve_line(
    name: &str,
    (load, loads): (u64, u64),
    (iteration, residual): (usize, f64),
    seconds: f64,
) -> String {
    format!(
        "{name}: load {load}/{loads}: iteration {iteration}, residual {residual:.3e} ({seconds:.0} s into the solve)"
    )
}

struct Shared {
    eta: Mutex<Eta>,
    start: Instant,
}

/// Progress of `total` steps of some named task.
pub struct Progress {
    bar: Option<ProgressBar>,
    name: String,
    total: u64,
    done: Arc<AtomicU64>,
    shared: Arc<Shared>,
    last_log: Mutex<Instant>,
}

impl Progress {
    /// Starts reporting `total` steps of equal cost; `quiet` silences it.
    pub fn new(name: &str, total: u64, quiet: bool) -> Self {
        Self::with_eta(name, Eta::uniform(total), quiet)
    }

    /// Starts reporting runs of `(steps, cost of each step)`, done in that order; the bar
    /// counts steps, the ETA weighs them by cost.
    pub fn weighted(name: &str, segments: &[(u64, f64)], quiet: bool) -> Self {
        Self::with_eta(name, Eta::weighted(segments), quiet)
    }

    fn with_eta(name: &str, eta: Eta, quiet: bool) -> Self {
        let total = eta.total();
        let now = Instant::now();
        let shared = Arc::new(Shared {
            eta: Mutex::new(eta),
            start: now,
        });
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new(total);
            let state = Arc::clone(&shared);
            bar.set_style(
                ProgressStyle::with_template(
                    "{msg} [{bar:40}] {pos}/{len} ({elapsed} elapsed, ETA {eta})",
                )
                .expect("valid template")
                .with_key(
                    "eta",
                    move |progress: &ProgressState, w: &mut dyn std::fmt::Write| {
                        let eta = state.eta.lock().expect("progress lock");
                        let left =
                            eta.remaining(progress.pos(), state.start.elapsed().as_secs_f64());
                        let _ = match left {
                            Some(s) => write!(w, "{:#}", HumanDuration(Duration::from_secs_f64(s))),
                            None => write!(w, "?"),
                        };
                    },
                )
                .progress_chars("=> "),
            );
            bar.set_message(name.to_string());
            bar
        });
        Progress {
            bar,
            name: if quiet {
                String::new()
            } else {
                name.to_string()
            },
            total,
            done: Arc::new(0.into()),
            shared,
            last_log: Mutex::new(now),
        }
    }

    /// One more step done in this run (thread-safe).
    pub fn inc(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        self.show(done);
    }

    /// Sets the number of steps done; the steps since the last call were done in this run
    /// (thread-safe).
    pub fn set(&self, done: u64) {
        let before = self.done.swap(done, Ordering::Relaxed);
        if done != before {
            self.show(done);
        }
    }

    /// Sets the number of steps done; the steps since the last call were read back (e.g.
    /// from a checkpoint), not done in this run, and do not count towards the rate.
    pub fn restore(&self, done: u64) {
        let before = self.done.swap(done, Ordering::Relaxed);
        if done != before {
            self.shared
                .eta
                .lock()
                .expect("progress lock")
                .restore(before, done);
            self.show(done);
        }
    }

    fn show(&self, done: u64) {
        if let Some(bar) = &self.bar {
            bar.set_position(done);
        } else if !self.name.is_empty() {
            let mut last = self.last_log.lock().expect("progress lock");
            if last.elapsed().as_secs_f64() >= 5.0 || done == self.total {
                let elapsed = self.shared.start.elapsed().as_secs_f64();
                let eta = self
                    .shared
                    .eta
                    .lock()
                    .expect("progress lock")
                    .remaining(done, elapsed);
                if let Some(eta) = eta {
                    *last = Instant::now();
                    eprintln!(
                        "{}",
                        log_line(&self.name, done.min(self.total), self.total, elapsed, eta)
                    );
                }
            }
        }
    }

    /// A monitor for the solver ([`asperity::bem::ContactSolver::set_monitor`]) that
    /// prints `name: load K/N: iteration I, residual R (S s into the solve)` at most every
    /// `every` seconds of a solve (above the bar on a terminal); `None` without `every`
    /// ([`solve_progress`]). The load is the one after those this progress counts done.
    pub fn solve_monitor(&self, name: &str, every: Option<f64>) -> Option<asperity::bem::Monitor> {
        let every = Duration::from_secs_f64(every?.max(0.0));
        let (name, loads, done, bar) = (
            name.to_string(),
            self.total,
            Arc::clone(&self.done),
            self.bar.clone(),
        );
        let (mut start, mut shown, mut previous) = (Instant::now(), Instant::now(), usize::MAX);
        Some(Box::new(move |iteration: usize, residual: f64| {
            let now = Instant::now();
            if iteration < previous {
                // A new solve.
                (start, shown) = (now, now);
            }
            previous = iteration;
            if now.duration_since(shown) < every {
                return;
            }
            shown = now;
            let load = (done.load(Ordering::Relaxed) + 1).min(loads.max(1));
            let seconds = now.duration_since(start).as_secs_f64();
            let line = solve_line(&name, (load, loads), (iteration, residual), seconds);
            match &bar {
                Some(bar) => bar.println(line),
                None => eprintln!("{line}"),
            }
        }))
    }

    /// Ends the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
