//! The record a coordinating process keeps of a study whose samples other processes compute
//! (issue 15: the CLI's MPI build, the Python package under `mpirun`).
//!
//! A [`Ledger`] is opened on a locked [`StudyDir`]: it reads every task's checkpoint
//! ([`StudyDir::restore_received`]), hands out the samples not yet computed
//! ([`Ledger::next_work`], task order then index order), takes in the curves computed
//! anywhere ([`Ledger::receive`]), checkpoints them ([`Ledger::save_due`]) and ends each
//! task with [`StudyDir::finish`] once all its samples are in, with the samples in index
//! order, so that the results and finished checkpoints are the serial run's, byte for byte.
//!
//! # Checkpoints
//! Samples arrive out of index order (a process that is slower holds back a low index). So
//! that a process lost mid-study costs only the samples it was computing, every sample
//! received is saved, gaps and all ([`StudyDir::save_received`]), soon after it arrives:
//! [`Ledger::save_due`] writes a task's checkpoint once new samples are in and either the
//! store's checkpoint interval has passed or writing costs less than 1/[`WRITE_SHARE`] of
//! the time since the last write (checkpoints of fast samples, MDR, are then batched; those
//! of BEM samples, seconds each, are written after every sample).

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use crate::study::{Received, SampleCurve, StudyDir, Task, TaskResult};
use crate::{Error, Result};

/// A checkpoint is written at the latest when this many times the last write's duration
/// has passed since it (writing then takes at most 1/WRITE_SHARE of the coordinator's
/// time).
pub const WRITE_SHARE: u32 = 20;

/// One task as the ledger keeps it.
#[derive(Debug)]
struct Entry {
    task: Task,
    /// Its result, once finished (or read back).
    result: Option<TaskResult>,
    /// The samples received, by index (empty once finished).
    slots: Vec<Option<SampleCurve>>,
    /// Indices neither received nor handed out, in order.
    pending: VecDeque<usize>,
    /// Samples received (read back or computed).
    received: usize,
    /// Samples received since the last checkpoint.
    unsaved: usize,
}

/// The tasks of a study computed elsewhere (module docs).
#[derive(Debug)]
pub struct Ledger {
    entries: Vec<Entry>,
    samples: usize,
    interval: Duration,
    /// When the last checkpoint was written, and how long writing it took.
    last_write: (Instant, Duration),
}

impl Ledger {
    /// Every task of `store`'s study as its checkpoint left it.
    pub fn restore(store: &StudyDir) -> Result<Ledger> {
        let samples = store.spec().samples;
        let mut entries = Vec::new();
        for task in store.spec().tasks() {
            let mut entry = Entry {
                task,
                result: None,
                slots: Vec::new(),
                pending: VecDeque::new(),
                received: 0,
                unsaved: 0,
            };
            match store.restore_received(task)? {
                Received::Done(result) => {
                    entry.result = Some(result);
                    entry.received = samples;
                }
                Received::Partial(slots) => {
                    entry.pending = (0..samples).filter(|&i| slots[i].is_none()).collect();
                    entry.received = samples - entry.pending.len();
                    entry.slots = slots;
                }
            }
            entries.push(entry);
        }
        Ok(Ledger {
            entries,
            samples,
            interval: store.checkpoint_interval(),
            last_write: (Instant::now(), Duration::ZERO),
        })
    }

    /// Task number `t` (in the order of [`crate::study::StudySpec::tasks`]).
    pub fn task(&self, t: usize) -> Task {
        self.entries[t].task
    }

    /// The number of tasks.
    pub fn tasks(&self) -> usize {
        self.entries.len()
    }

    /// Samples received over all tasks (read back or computed).
    pub fn done(&self) -> u64 {
        self.entries.iter().map(|e| e.received as u64).sum()
    }

    /// Samples of the whole study.
    pub fn total(&self) -> u64 {
        (self.entries.len() * self.samples) as u64
    }

    /// Whether every task is finished.
    pub fn finished(&self) -> bool {
        self.entries.iter().all(|e| e.result.is_some())
    }

    /// The next samples to compute, `(task number, indices)`: up to `lanes` samples of the
    /// first task with samples neither received nor handed out. Each is handed out once.
    pub fn next_work(&mut self, lanes: usize) -> Option<(usize, Vec<usize>)> {
        let (t, entry) = self
            .entries
            .iter_mut()
            .enumerate()
            .find(|(_, e)| !e.pending.is_empty())?;
        let take = lanes.max(1).min(entry.pending.len());
        Some((t, entry.pending.drain(..take).collect()))
    }

    /// Takes in the curves of samples `indices` of task `t` (handed out by
    /// [`Ledger::next_work`]) and ends the task when it is complete.
    pub fn receive(
        &mut self,
        store: &StudyDir,
        t: usize,
        indices: &[usize],
        curves: Vec<SampleCurve>,
    ) -> Result<()> {
        let samples = self.samples;
        let entry = self
            .entries
            .get_mut(t)
            .ok_or_else(|| Error::invalid("task", format!("no task number {t}")))?;
        if curves.len() != indices.len() {
            return Err(Error::invalid(
                "samples",
                format!("{} curves for {} samples", curves.len(), indices.len()),
            ));
        }
        if entry.result.is_some() {
            return Err(Error::invalid("samples", "samples of a finished task"));
        }
        for (&i, curve) in indices.iter().zip(curves) {
            let slot = entry.slots.get_mut(i).ok_or_else(|| {
                Error::invalid(
                    "samples",
                    format!("sample {i} of a task of {samples} samples"),
                )
            })?;
            if slot.replace(curve).is_none() {
                entry.received += 1;
                entry.unsaved += 1;
            }
        }
        if entry.received == samples {
            let all = std::mem::take(&mut entry.slots)
                .into_iter()
                .flatten()
                .collect();
            entry.result = Some(store.finish(entry.task, all)?);
            entry.unsaved = 0;
        }
        Ok(())
    }

    /// Checkpoints the tasks with samples received since their last checkpoint, if due
    /// (module docs); call it often (e.g. whenever the coordinator polls). Returns the
    /// number of checkpoints written.
    pub fn save_due(&mut self, store: &StudyDir) -> Result<usize> {
        let (at, cost) = self.last_write;
        if at.elapsed() < self.interval.min(cost * WRITE_SHARE) {
            return Ok(0);
        }
        let mut written = 0;
        let start = Instant::now();
        for entry in self.entries.iter_mut().filter(|e| e.unsaved > 0) {
            store.save_received(entry.task, &entry.slots)?;
            entry.unsaved = 0;
            written += 1;
        }
        if written > 0 {
            self.last_write = (Instant::now(), start.elapsed());
        }
        Ok(written)
    }

    /// The results of every task, in task order (all of them once [`Ledger::finished`]).
    pub fn results(self) -> Vec<TaskResult> {
        self.entries.into_iter().filter_map(|e| e.result).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::{run_any_task, FitWindow, Method, StudySpec, TaskSamples};

    fn spec() -> StudySpec {
        StudySpec {
            method: Method::Mdr,
            sizes: vec![64],
            hursts: vec![0.4, 0.9],
            samples: 6,
            rolloff: None,
            seed: 11,
            window: FitWindow::default(),
            levels: 12,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        }
    }

    fn folder(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("asperity-ledger-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    /// The checkpoint files of a folder, by name.
    fn files(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
        let mut out: Vec<_> = std::fs::read_dir(dir.join("checkpoint"))
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                (
                    p.file_name().unwrap().to_string_lossy().into_owned(),
                    std::fs::read(&p).unwrap(),
                )
            })
            .collect();
        out.sort();
        out
    }

    /// Samples computed out of order, with a stop after which a fresh ledger resumes from
    /// the checkpoints (gaps included), end with the serial run's checkpoints byte for byte.
    #[test]
    fn out_of_order_samples_resume_and_finish_as_the_serial_run() {
        let spec = spec();
        let serial = folder("serial");
        let store = StudyDir::open(&serial, &spec, false).unwrap();
        for task in spec.tasks() {
            run_any_task(&spec, task, &store, &|_, _| {}).unwrap();
        }
        let dir = folder("ledger");
        let store = StudyDir::open(&dir, &spec, false)
            .unwrap()
            .with_checkpoint_interval(Duration::ZERO);
        let mut ledger = Ledger::restore(&store).unwrap();
        // Hand out three pieces, receive the later ones only: sample 0 is "in flight".
        let mut pieces = Vec::new();
        for _ in 0..3 {
            pieces.push(ledger.next_work(2).unwrap());
        }
        assert_eq!(pieces[0], (0, vec![0, 1]));
        for (t, indices) in &pieces[1..] {
            let curves = TaskSamples::new(&spec, ledger.task(*t))
                .unwrap()
                .compute(indices)
                .unwrap();
            ledger.receive(&store, *t, indices, curves).unwrap();
        }
        assert_eq!(ledger.save_due(&store).unwrap(), 1);
        assert_eq!(ledger.done(), 4);
        // A process lost: a new ledger reads back the four samples beyond the gap.
        let mut ledger = Ledger::restore(&store).unwrap();
        assert_eq!(ledger.done(), 4);
        while let Some((t, indices)) = ledger.next_work(3) {
            assert!(
                !(t == 0 && indices.iter().any(|&i| i >= 2)),
                "recomputed {indices:?}"
            );
            let curves = TaskSamples::new(&spec, ledger.task(t))
                .unwrap()
                .compute(&indices)
                .unwrap();
            ledger.receive(&store, t, &indices, curves).unwrap();
            ledger.save_due(&store).unwrap();
        }
        assert!(ledger.finished());
        assert_eq!(ledger.done(), ledger.total());
        assert_eq!(files(&serial), files(&dir));
        let _ = std::fs::remove_dir_all(&serial);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_serial_run_resumes_a_checkpoint_with_gaps_to_the_same_bytes() {
        let spec = spec();
        let task = spec.tasks()[0];
        let serial = folder("serial2");
        let store = StudyDir::open(&serial, &spec, false).unwrap();
        run_any_task(&spec, task, &store, &|_, _| {}).unwrap();
        let dir = folder("gaps");
        let store = StudyDir::open(&dir, &spec, false).unwrap();
        let mut slots = vec![None; spec.samples];
        let curves = TaskSamples::new(&spec, task)
            .unwrap()
            .compute(&[0, 3])
            .unwrap();
        (slots[0], slots[3]) = (Some(curves[0].clone()), Some(curves[1].clone()));
        store.save_received(task, &slots).unwrap();
        assert_eq!(
            store.restore_received(task).unwrap(),
            Received::Partial(slots)
        );
        run_any_task(&spec, task, &store, &|_, _| {}).unwrap();
        assert_eq!(files(&serial), files(&dir));
        let _ = std::fs::remove_dir_all(&serial);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn samples_of_the_wrong_count_or_index_are_refused() {
        let spec = spec();
        let dir = folder("refused");
        let store = StudyDir::open(&dir, &spec, false).unwrap();
        let mut ledger = Ledger::restore(&store).unwrap();
        let curves = TaskSamples::new(&spec, ledger.task(0))
            .unwrap()
            .compute(&[1])
            .unwrap();
        assert!(ledger.receive(&store, 0, &[1, 2], curves.clone()).is_err());
        assert!(ledger.receive(&store, 0, &[9], curves.clone()).is_err());
        assert!(ledger.receive(&store, 5, &[1], curves).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
