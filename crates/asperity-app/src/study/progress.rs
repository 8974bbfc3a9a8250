//! What a study reports as its progress, the same in both front ends: the samples held in
//! all (those read back from checkpoints count at once, whichever task they belong to, so
//! that a resumed study shows all it holds), and, for the CLI's bar and its ETA, the steps
//! of a sample and their costs, and the ETA of both ([`Eta`], [`log_line`]).
//!
//! ```
//! use asperity::study::{Method, StudySpec};
//! use asperity_app::study::progress::StudyProgress;
//!
//! let spec = StudySpec { method: Method::Mdr, sizes: vec![64, 128], samples: 4, ..StudySpec::default() };
//! // Task 0 holds 1 sample and task 1 holds 3 in their checkpoints.
//! let progress = StudyProgress::new(&spec, vec![1, 3]);
//! assert_eq!((progress.held(0, 1), progress.total()), (4, 8));
//! assert_eq!(progress.held(0, 4), 7); // task 0 done, task 1's three still held
//! assert_eq!(progress.held(1, 4), 8);
//! // Python's ETA counts samples: the 4 held are restored, none done in this run yet.
//! let eta = progress.sample_eta();
//! assert_eq!((eta.total(), eta.remaining(4, 1.0)), (8, None));
//! ```

use asperity::study::samplers::BemSampler;
use asperity::study::{sample_cost, Method, StudyDir, StudySpec};

/// The progress of one study (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct StudyProgress {
    method: Method,
    samples: usize,
    /// The samples each task holds in its checkpoints before the run, in task order.
    stored: Vec<usize>,
    /// The cost of one sample of each task ([`sample_cost`]).
    costs: Vec<f64>,
}

impl StudyProgress {
    /// The progress of `spec`'s study whose tasks hold `stored` samples before the run.
    pub fn new(spec: &StudySpec, stored: Vec<usize>) -> Self {
        StudyProgress {
            method: spec.method,
            samples: spec.samples,
            costs: (spec.tasks().iter())
                .map(|t| sample_cost(spec.method, t.n))
                .collect(),
            stored,
        }
    }

    /// The progress of the study in `store`, from what its checkpoints hold.
    pub fn of(store: &StudyDir) -> asperity::Result<Self> {
        let spec = store.spec();
        let stored = (spec.tasks().iter())
            .map(|&task| store.samples_held(task, spec.samples))
            .collect::<asperity::Result<_>>()?;
        Ok(Self::new(spec, stored))
    }

    /// The samples of the study.
    pub fn total(&self) -> usize {
        self.costs.len() * self.samples
    }

    /// The samples held before the run.
    pub fn restored(&self) -> usize {
        self.stored.iter().sum()
    }

    /// The samples held in all once task number `task` holds `done` (at least what it held
    /// before the run): the tasks before it are finished, those after it hold what they
    /// held before the run.
    pub fn held(&self, task: usize, done: usize) -> usize {
        let before = self.stored.get(task).copied().unwrap_or(0);
        let after = self.stored.iter().skip(task + 1).sum::<usize>();
        task * self.samples + done.max(before) + after
    }

    /// The steps of one sample: a BEM sample reports each of its loads (a 512² sample
    /// takes minutes), an MDR sample (milliseconds) only itself.
    pub fn steps_per_sample(&self) -> u64 {
        match self.method {
            Method::Bem => BemSampler::LOADS as u64,
            Method::Mdr => 1,
        }
    }

    /// The `(steps, cost of each)` runs of a weighted bar: the stored samples of every
    /// task, then the samples left of every task, each step a share of its sample's cost.
    pub fn segments(&self) -> Vec<(u64, f64)> {
        self.segments_of(self.steps_per_sample())
    }

    /// The ETA of a progress that counts samples (Python's, whose callback is told the
    /// samples held): weighted as [`StudyProgress::segments`], one step a sample, the
    /// samples held before the run restored.
    pub fn sample_eta(&self) -> Eta {
        let mut eta = Eta::weighted(&self.segments_of(1));
        eta.restore(0, self.restored() as u64);
        eta
    }

    fn segments_of(&self, steps: u64) -> Vec<(u64, f64)> {
        let runs = |count: &dyn Fn(usize) -> usize| -> Vec<(u64, f64)> {
            (self.stored.iter().zip(&self.costs))
                .map(|(&s, &cost)| (count(s) as u64 * steps, cost / steps as f64))
                .collect()
        };
        let mut segments = runs(&|s| s);
        segments.extend(runs(&|s| self.samples - s));
        segments
    }
}

/// The ETA arithmetic of a run of weighted steps, apart from the clock: `elapsed / work
/// done in this run × work left`, where only steps done in this run count as done work
/// (steps read back from a checkpoint, [`Eta::restore`], move the count but not the rate)
/// and each step weighs its cost (a study's samples [`sample_cost`], so that a sweep whose
/// large grids come last does not promise to end early). The CLI's bar and log lines and
/// Python's progress bars of a study both use it.
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

/// The line of progress printed where the bar is not shown (stderr not a terminal), the
/// same in both front ends: `mdr study: 210/270 (5 s elapsed, ETA 10 s)`.
pub fn log_line(name: &str, done: u64, total: u64, elapsed: f64, eta: f64) -> String {
    format!("{name}: {done}/{total} ({elapsed:.0} s elapsed, ETA {eta:.0} s)")
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
