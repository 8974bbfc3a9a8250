//! The coordinator of a study spread over the ranks of an MPI job (issue 15), as a state
//! machine that both front ends drive: the CLI's MPI build (`asperity-cli`'s
//! `distributed.rs`) and the Python package under `mpirun python` (`asperity/_mpi.py`,
//! through `_asperity.StudyCoordinator`). It holds no MPI: a front end receives messages,
//! turns each into an event ([`Coordinator::on_ready`], [`Coordinator::on_done`],
//! [`Coordinator::on_failed`]) and carries out the [`Action`]s the event returns (send an
//! assignment, tell a rank to stop, end the study).
//!
//! # The rules
//! * **Rank 0 is the coordinator and computes too**, on a thread of its own: it is a rank
//!   like the others, ready from the start with the lanes given to [`Coordinator::new`];
//!   the others become ready when their `ready` message (with their thread count) arrives.
//! * **Samples are handed out dynamically.** Whenever a rank is ready and idle it gets the
//!   next samples not yet handed out (task order, then index order; as many as it has
//!   lanes, all of one task: [`Ledger::next_work`]), ranks taken in rank order. A rank
//!   that has not yet met the study is marked to be sent its spec with the assignment.
//! * **Samples received are taken in by the library's [`Ledger`]**, which checkpoints
//!   them ([`Coordinator::save_due`], called whenever the front end polls) and ends each
//!   task with its samples in index order, as the serial run does: the results and
//!   finished checkpoints are the serial run's, byte for byte, whatever the order of
//!   events, and a study resumes whatever either kind of run checkpointed.
//! * **A failure ends the study once no sample is in flight.** A rank's failed assignment,
//!   samples a rank was not asked for, or an error taking samples in or checkpointing them
//!   stops the handing out; the samples in flight are still awaited and taken in (so that
//!   nothing computed is lost), and then the study ends with the first failure
//!   ([`Coordinator::finish`]). A front end that fails on its own says so with
//!   [`Coordinator::halt`].
//! * **Stopping.** [`Coordinator::stop`] (refused while samples are in flight) tells every
//!   ready rank to stop; a rank whose `ready` has not arrived yet is told once it does, so
//!   that no message is left unmatched. [`Coordinator::stopped`] says when all were told.
//!
//! ```
//! use asperity::study::{Method, StudyDir, StudySpec, TaskSamples};
//! use asperity_app::study::distributed::{Action, Coordinator};
//!
//! let spec = StudySpec { method: Method::Mdr, sizes: vec![64], samples: 3, levels: 12, ..StudySpec::default() };
//! let dir = tempfile::tempdir().unwrap();
//! let store = StudyDir::open(dir.path(), &spec, false).unwrap();
//! // Two ranks: this one (rank 0, 2 lanes) and rank 1, whose `ready` has not come yet.
//! let mut job = Coordinator::new(2, 2);
//! let actions = job.begin(store).unwrap();
//! assert_eq!(actions, [Action::Assign { rank: 0, task: 0, indices: vec![0, 1], spec: true }]);
//! let actions = job.on_ready(1, 4);
//! assert_eq!(actions, [Action::Assign { rank: 1, task: 0, indices: vec![2], spec: true }]);
//! let samples = |indices: &[usize]| TaskSamples::new(&spec, spec.tasks()[0]).unwrap().compute(indices).unwrap();
//! assert_eq!(job.on_done(1, samples(&[2])), []);
//! assert_eq!(job.on_done(0, samples(&[0, 1])), [Action::End]);
//! let results = job.finish().unwrap();
//! assert_eq!((results.len(), job.computed()), (1, vec![2, 1]));
//! assert_eq!(job.stop().unwrap(), [Action::Stop { rank: 1 }]);
//! assert!(job.stopped());
//! ```

use asperity::study::{Ledger, SampleCurve, StudyDir, TaskResult};

use super::TaskFailure;

/// What the front end must do after an event.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Action {
    /// Have rank `rank` compute samples `indices` of task number `task` (in the order of
    /// [`asperity::study::StudySpec::tasks`]; rank 0: its own sample thread). `spec`: the
    /// rank has not met this study yet, send it the study's spec first (or with it).
    Assign {
        rank: usize,
        task: usize,
        indices: Vec<usize>,
        spec: bool,
    },
    /// Tell rank `rank` (never 0) to stop.
    Stop { rank: usize },
    /// The study is over (finished or failed) and no sample is in flight: call
    /// [`Coordinator::finish`].
    End,
}

/// Why a distributed study failed, or why the coordinator refused a call.
#[derive(Debug, thiserror::Error)]
pub enum DistributedError {
    /// A rank's assignment failed; `reason` is its error's text.
    #[error("rank {rank}: {reason}")]
    Failed { rank: usize, reason: String },
    /// A rank sent samples it was not asked for.
    #[error("rank {rank} sent samples it was not asked for")]
    Unasked { rank: usize },
    /// An event named a rank the job does not have.
    #[error("rank {rank} is not a rank of this job of {size}")]
    NoRank { rank: usize, size: usize },
    /// Samples received could not be taken in (named with their task).
    #[error(transparent)]
    Task(#[from] TaskFailure),
    /// The samples received could not be checkpointed.
    #[error(transparent)]
    Store(asperity::Error),
    /// [`Coordinator::stop`] with samples in flight: the job cannot end cleanly.
    #[error("the study stopped with samples in flight: ending every rank")]
    InFlight,
    /// The front end gave up on the study ([`Coordinator::halt`]), for this reason.
    #[error("{0}")]
    Halted(String),
    /// [`Coordinator::begin`] while a study runs, or [`Coordinator::finish`] before the
    /// study ended.
    #[error("{0}")]
    Sequence(&'static str),
}

/// What the coordinator knows of one rank.
#[derive(Debug, Default)]
struct Rank {
    /// Samples it computes at once; `None` until its `ready` arrived.
    lanes: Option<usize>,
    /// The number of the last study it met (was assigned samples of).
    met: Option<u64>,
    /// What it is computing: `(task number, indices)`.
    busy: Option<(usize, Vec<usize>)>,
    /// Samples it computed in the current study.
    computed: u64,
    /// Whether it was told to stop.
    stopped: bool,
}

/// The study being run.
#[derive(Debug)]
struct Study {
    ledger: Ledger,
    store: StudyDir,
    /// Whether [`Action::End`] was returned.
    ended: bool,
}

/// Rank 0's view of a job of several ranks (module docs).
#[derive(Debug)]
pub struct Coordinator {
    ranks: Vec<Rank>,
    study: Option<Study>,
    /// Studies begun so far (a job of the CLI may run several: `asperity reproduce`).
    studies: u64,
    /// The first failure of the current study (or, outside a study, of the job).
    failure: Option<DistributedError>,
    stopping: bool,
}

impl Coordinator {
    /// A job of `size` ranks (at least 1), rank 0 computing `lanes` samples at once.
    pub fn new(size: usize, lanes: usize) -> Coordinator {
        let mut ranks: Vec<Rank> = (0..size.max(1)).map(|_| Rank::default()).collect();
        ranks[0].lanes = Some(lanes.max(1));
        Coordinator {
            ranks,
            study: None,
            studies: 0,
            failure: None,
            stopping: false,
        }
    }

    /// Begins the study in `store` (a locked, opened folder), resumed from its
    /// checkpoints: the first assignments, or [`Action::End`] if nothing is left to do.
    pub fn begin(&mut self, store: StudyDir) -> Result<Vec<Action>, DistributedError> {
        if self.study.is_some() || self.stopping {
            return Err(DistributedError::Sequence(
                "a study begun while another runs or after the job stopped",
            ));
        }
        let ledger = Ledger::restore(&store).map_err(DistributedError::Store)?;
        self.studies += 1;
        self.ranks.iter_mut().for_each(|r| r.computed = 0);
        self.study = Some(Study {
            ledger,
            store,
            ended: false,
        });
        Ok(self.dispatch())
    }

    /// The number of the current (or last) study, counting from 1: a front end that
    /// sends a study's spec names the study with it.
    pub fn study_number(&self) -> u64 {
        self.studies
    }

    /// Rank `rank` is ready and computes `lanes` samples at once.
    pub fn on_ready(&mut self, rank: usize, lanes: usize) -> Vec<Action> {
        let stopping = self.stopping;
        let Some(state) = self.rank(rank) else {
            return self.dispatch();
        };
        state.lanes = Some(lanes.max(1));
        if stopping && rank != 0 && !state.stopped {
            state.stopped = true;
            return vec![Action::Stop { rank }];
        }
        self.dispatch()
    }

    /// Rank `rank` computed the samples it was assigned last: their `curves`, in the order
    /// of the assignment's indices.
    pub fn on_done(&mut self, rank: usize, curves: Vec<SampleCurve>) -> Vec<Action> {
        let Some(state) = self.rank(rank) else {
            return self.dispatch();
        };
        let Some((t, indices)) = state.busy.take() else {
            self.fail(DistributedError::Unasked { rank });
            return self.dispatch();
        };
        state.computed += indices.len() as u64;
        self.take_in(t, &indices, curves);
        self.dispatch()
    }

    /// [`Ledger::receive`]; its failure named with the task, as the serial run names it.
    fn take_in(&mut self, t: usize, indices: &[usize], curves: Vec<SampleCurve>) {
        if let Some(study) = self.study.as_mut() {
            let taken = study.ledger.receive(&study.store, t, indices, curves);
            if let Err(source) = taken {
                let failure = TaskFailure {
                    method: study.store.spec().method,
                    task: study.ledger.task(t),
                    source,
                };
                self.fail(failure.into());
            }
        }
    }

    /// Rank `rank`'s last assignment failed with `reason`: the study ends once no sample
    /// is in flight, with this failure unless an earlier one.
    pub fn on_failed(&mut self, rank: usize, reason: &str) -> Vec<Action> {
        let reason = reason.to_string();
        if let Some(state) = self.rank(rank) {
            state.busy = None;
            self.fail(DistributedError::Failed { rank, reason });
        }
        self.dispatch()
    }

    /// The front end failed on its own (a progress callback raised, a message could not
    /// be read): nothing more is handed out and the study ends once no sample is in
    /// flight, with `reason` unless an earlier failure.
    pub fn halt(&mut self, reason: &str) -> Vec<Action> {
        self.fail(DistributedError::Halted(reason.to_string()));
        self.dispatch()
    }

    /// Checkpoints the samples received, when due ([`Ledger::save_due`]); call it whenever
    /// the front end polls. A failure to write ends the study as a rank's failure does.
    pub fn save_due(&mut self) -> Vec<Action> {
        let Some(study) = self.study.as_mut() else {
            return Vec::new();
        };
        if let Err(err) = study.ledger.save_due(&study.store) {
            self.fail(DistributedError::Store(err));
        }
        self.dispatch()
    }

    /// `(samples received, samples of the study)`, those read back from checkpoints
    /// included; `(0, 0)` outside a study.
    pub fn progress(&self) -> (u64, u64) {
        self.study
            .as_ref()
            .map_or((0, 0), |s| (s.ledger.done(), s.ledger.total()))
    }

    /// The samples each rank computed in the current (or last) study, rank 0 first.
    pub fn computed(&self) -> Vec<u64> {
        self.ranks.iter().map(|r| r.computed).collect()
    }

    /// Whether any rank is computing samples.
    pub fn in_flight(&self) -> bool {
        self.ranks.iter().any(|r| r.busy.is_some())
    }

    /// The ranks computing samples, in order.
    pub fn busy(&self) -> Vec<usize> {
        (0..self.ranks.len())
            .filter(|&r| self.ranks[r].busy.is_some())
            .collect()
    }

    /// The results of the study that ended ([`Action::End`]), in task order, or its first
    /// failure.
    pub fn finish(&mut self) -> Result<Vec<TaskResult>, DistributedError> {
        if !self.study.as_ref().is_some_and(|s| s.ended) {
            return Err(DistributedError::Sequence("the study has not ended"));
        }
        let study = self.study.take().expect("checked above");
        match self.failure.take() {
            Some(failure) => Err(failure),
            None => Ok(study.ledger.results()),
        }
    }

    /// Ends the job: [`Action::Stop`] for every ready rank but 0; the others are told when
    /// their `ready` arrives ([`Coordinator::on_ready`]). A study not finished is given up
    /// (with its failure). Refused with samples in flight, and with the failure of an
    /// event outside a study, if any.
    pub fn stop(&mut self) -> Result<Vec<Action>, DistributedError> {
        if self.in_flight() {
            return Err(DistributedError::InFlight);
        }
        if self.study.take().is_some() {
            // A study given up before it ended: its failure goes with it.
            self.failure = None;
        }
        self.stopping = true;
        let mut actions = Vec::new();
        for (rank, state) in self.ranks.iter_mut().enumerate().skip(1) {
            if state.lanes.is_some() && !state.stopped {
                state.stopped = true;
                actions.push(Action::Stop { rank });
            }
        }
        match self.failure.take() {
            Some(failure) => Err(failure),
            None => Ok(actions),
        }
    }

    /// Whether every rank but 0 was told to stop.
    pub fn stopped(&self) -> bool {
        self.stopping && self.ranks.iter().skip(1).all(|r| r.stopped)
    }

    /// The state of rank `rank`, or `None` (and a failure) for a rank the job lacks.
    fn rank(&mut self, rank: usize) -> Option<&mut Rank> {
        let size = self.ranks.len();
        if rank >= size {
            self.fail(DistributedError::NoRank { rank, size });
            return None;
        }
        Some(&mut self.ranks[rank])
    }

    /// Records `failure` unless an earlier one is.
    fn fail(&mut self, failure: DistributedError) {
        self.failure.get_or_insert(failure);
    }

    /// Assigns work to every ready, idle rank (in rank order) while there is work and no
    /// failure; then [`Action::End`] once, when the study is finished or failed and no
    /// sample is in flight.
    fn dispatch(&mut self) -> Vec<Action> {
        let mut actions = Vec::new();
        let Some(study) = self.study.as_mut().filter(|s| !s.ended) else {
            return actions;
        };
        if self.failure.is_none() && !self.stopping {
            for (rank, state) in self.ranks.iter_mut().enumerate() {
                let Some(lanes) = state.lanes.filter(|_| state.busy.is_none()) else {
                    continue;
                };
                let Some((task, indices)) = study.ledger.next_work(lanes) else {
                    break;
                };
                let spec = state.met != Some(self.studies);
                state.met = Some(self.studies);
                state.busy = Some((task, indices.clone()));
                actions.push(Action::Assign {
                    rank,
                    task,
                    indices,
                    spec,
                });
            }
        }
        let over = self.failure.is_some() || study.ledger.finished();
        if over && !self.ranks.iter().any(|r| r.busy.is_some()) {
            study.ended = true;
            actions.push(Action::End);
        }
        actions
    }
}

#[cfg(test)]
mod tests;
