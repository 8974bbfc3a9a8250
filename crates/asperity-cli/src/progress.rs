//! Progress reporting: an indicatif bar with ETA on a terminal, plain log lines otherwise
//! (indicatif hides its bar when stderr is not a terminal).

use std::io::IsTerminal;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

/// Progress of `total` steps of some named task.
pub struct Progress {
    bar: Option<ProgressBar>,
    name: String,
    total: u64,
    done: std::sync::atomic::AtomicU64,
    start: Instant,
    last_log: std::sync::Mutex<Instant>,
}

impl Progress {
    /// Starts reporting; `quiet` silences it.
    pub fn new(name: &str, total: u64, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new(total);
            bar.set_style(
                ProgressStyle::with_template(
                    "{msg} [{bar:40}] {pos}/{len} ({elapsed} elapsed, ETA {eta})",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar.set_message(name.to_string());
            bar
        });
        let now = Instant::now();
        Progress {
            bar,
            name: if quiet {
                String::new()
            } else {
                name.to_string()
            },
            total,
            done: 0.into(),
            start: now,
            last_log: std::sync::Mutex::new(now),
        }
    }

    /// One more step done (thread-safe).
    pub fn inc(&self) {
        let done = self.done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if let Some(bar) = &self.bar {
            bar.inc(1);
        } else if !self.name.is_empty() {
            let mut last = self.last_log.lock().expect("progress lock");
            if last.elapsed().as_secs_f64() >= 5.0 || done == self.total {
                *last = Instant::now();
                let elapsed = self.start.elapsed().as_secs_f64();
                let eta = elapsed / done as f64 * (self.total - done) as f64;
                eprintln!(
                    "{}: {done}/{} ({elapsed:.0} s elapsed, ETA {eta:.0} s)",
                    self.name, self.total
                );
            }
        }
    }

    /// Sets the number of steps done (thread-safe); logs like [`Progress::inc`].
    pub fn set(&self, done: u64) {
        let before = self.done.swap(done, std::sync::atomic::Ordering::Relaxed);
        if done == before {
            return;
        }
        if let Some(bar) = &self.bar {
            bar.set_position(done);
        } else if !self.name.is_empty() {
            let mut last = self.last_log.lock().expect("progress lock");
            if last.elapsed().as_secs_f64() >= 5.0 || done == self.total {
                *last = Instant::now();
                let elapsed = self.start.elapsed().as_secs_f64();
                let eta = elapsed / done.max(1) as f64 * (self.total - done.min(self.total)) as f64;
                eprintln!(
                    "{}: {done}/{} ({elapsed:.0} s elapsed, ETA {eta:.0} s)",
                    self.name, self.total
                );
            }
        }
    }

    /// Ends the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
