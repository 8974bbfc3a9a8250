//! Progress reporting: an indicatif bar with ETA on a terminal, plain log lines otherwise
//! (indicatif hides its bar when stderr is not a terminal).
//!
//! # The ETA
//! The estimate is `elapsed / work done in this run × work left` ([`Eta`]), where
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

use indicatif::{HumanDuration, ProgressBar, ProgressState, ProgressStyle};

/// The ETA arithmetic of a run of weighted steps, apart from the clock (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Eta {
    /// Consecutive runs of steps: `(steps, cost of each)`.
    segments: Vec<(u64, f64)>,
    /// Cost of the steps read back instead of done in this run.
    restored: f64,
}

impl Eta {
    /// `total` steps of equal cost.
    pub fn uniform(total: u64) -> Self {
        Self::weighted(&[(total, 1.0)])
    }

    /// Runs of `(steps, cost of each step)`, in the order they are done.
    pub fn weighted(segments: &[(u64, f64)]) -> Self {
        Eta {
            segments: segments
                .iter()
                .map(|&(steps, cost)| (steps, if cost > 0.0 { cost } else { 0.0 }))
                .collect(),
            restored: 0.0,
        }
    }

    /// Number of steps.
    pub fn total(&self) -> u64 {
        self.segments.iter().map(|s| s.0).sum()
    }

    /// Cost of the first `steps` steps.
    pub fn cost_to(&self, steps: u64) -> f64 {
        let mut left = steps;
        let mut cost = 0.0;
        for &(count, each) in &self.segments {
            let take = left.min(count);
            cost += take as f64 * each;
            left -= take;
            if left == 0 {
                break;
            }
        }
        cost
    }

    /// Steps `from..to` were read back, not done in this run.
    pub fn restore(&mut self, from: u64, to: u64) {
        if to > from {
            self.restored += self.cost_to(to) - self.cost_to(from);
        }
    }

    /// Seconds left when `done` steps are done after `elapsed` seconds of this run; `None`
    /// until some work was done in this run.
    pub fn remaining(&self, done: u64, elapsed: f64) -> Option<f64> {
        let total = self.total();
        if done >= total {
            return Some(0.0);
        }
        let worked = self.cost_to(done) - self.restored;
        // Below a millionth of the cost done, rounding of the restored sum: nothing done.
        if worked <= 1e-9 * self.cost_to(total) || elapsed <= 0.0 {
            return None;
        }
        Some(elapsed / worked * (self.cost_to(total) - self.cost_to(done)))
    }
}

/// The log line printed when stderr is not a terminal.
fn log_line(name: &str, done: u64, total: u64, elapsed: f64, eta: f64) -> String {
    format!("{name}: {done}/{total} ({elapsed:.0} s elapsed, ETA {eta:.0} s)")
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restored_steps_do_not_count_towards_the_rate() {
        // The audit's case: 180 of 270 samples read back, then 30 done in 5 s. 60 are left
        // at 6 per second: 10 s (the old estimate, 5 s / 210 × 60, said 1 s).
        let mut eta = Eta::uniform(270);
        assert_eq!(eta.remaining(0, 1.0), None, "nothing done yet");
        eta.restore(0, 180);
        assert_eq!(eta.remaining(180, 0.5), None, "only restored so far");
        let left = eta.remaining(210, 5.0).unwrap();
        assert!((left - 10.0).abs() < 1e-9, "{left}");
        assert_eq!(eta.remaining(270, 9.0), Some(0.0));
    }

    #[test]
    fn restored_steps_in_a_later_task_are_not_counted_either() {
        // Task 1 (10 steps) done in this run in 2 s, task 2 (10 steps) half restored.
        let mut eta = Eta::weighted(&[(10, 1.0), (10, 1.0)]);
        eta.restore(10, 15);
        let left = eta.remaining(15, 2.0).unwrap();
        assert!((left - 1.0).abs() < 1e-9, "5 steps at 5 per second: {left}");
    }

    #[test]
    fn steps_are_weighted_by_cost() {
        // 10 cheap steps (cost 1) done in 2 s, 10 expensive ones (cost 4) left: 40 units at
        // 5 per second. Counting steps alike would say 2 s.
        let eta = Eta::weighted(&[(10, 1.0), (10, 4.0)]);
        assert_eq!(eta.total(), 20);
        assert_eq!(eta.cost_to(12), 18.0);
        let left = eta.remaining(10, 2.0).unwrap();
        assert!((left - 8.0).abs() < 1e-9, "{left}");
        // BEM N = 64 then 128, as `reproduce fig1 --quick`: the second grid's samples cost
        // 4.67 times as much.
        use asperity::study::{sample_cost, Method};
        let (a, b) = (sample_cost(Method::Bem, 64), sample_cost(Method::Bem, 128));
        let eta = Eta::weighted(&[(20, a), (20, b)]);
        let left = eta.remaining(20, 6.0).unwrap();
        assert!((left - 6.0 * b / a).abs() < 1e-9, "{left}");
    }

    #[test]
    fn the_log_line_keeps_its_format() {
        assert_eq!(
            log_line("mdr study", 210, 270, 5.2, 10.4),
            "mdr study: 210/270 (5 s elapsed, ETA 10 s)"
        );
    }
}
