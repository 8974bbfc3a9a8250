//! What a study reports as its progress, the same in both front ends: the samples held in
//! all (those read back from checkpoints count at once, whichever task they belong to, so
//! that a resumed study shows all it holds), and, for the CLI's bar and its ETA, the steps
//! of a sample and their costs.
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
        let steps = self.steps_per_sample();
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
