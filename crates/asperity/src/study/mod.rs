//! Ensemble studies: many seeded realisations per (method, N, H), their mean force–stiffness
//! curves and the exponent α of `k ∝ F^α` (paper eq. 3, Figs. 1, 2, 5), with checkpoints.
//!
//! A [`StudySpec`] lists grid sizes, Hurst exponents and the number of samples; each
//! `(N, H)` pair is a [`Task`]. Every sample has its own seed, derived from the study seed,
//! N, H and the sample index ([`sample_seed`]), so results do not depend on the order or
//! the thread on which samples run, nor on which other tasks a study contains.
//!
//! # Checkpoints
//! [`StudyDir::open`] writes `DIR/study.json` (the spec), and [`run_any_task`] writes,
//! after every batch of samples, `DIR/checkpoint/<task>.json` with all samples done so far
//! (atomically). Run again with
//! the same spec, it resumes where it stopped and — since samples are deterministic and
//! stored with round-trip precision — gives bit-identical results. A folder holding a
//! different study is refused ([`Error::ForeignCheckpoint`], naming the parameters that
//! differ) unless `discard` is set. The same study over other grids, H values or sample
//! counts is no different study: it is extended, every task it shares with the stored one
//! keeping its checkpoint (a finished BEM task whose sample count changed continues from
//! its kept sample curves; a finished MDR task, whose curves are not kept, is computed
//! again). A folder whose `study.json` names another study but
//! whose checkpoints hold no sample (a study that stopped before its first checkpoint) is
//! free and reused.
//!
//! Every checkpoint is sealed with the full identity of what produced it and a checksum
//! of its content ([`identity`]): one copied from another study, left behind by a study
//! whose `study.json` was deleted, written by an older asperity, edited by hand or damaged
//! is refused with the fields that differ, never merged. Two processes never share a
//! folder: a front end holds [`StudyDir::lock`] while it runs.
//!
//! `study.json` also records the scales of the samples (`normalisation`, see
//! [`samplers::Scales`]), which every checkpoint's identity holds as well.
//!
//! # Samples computed elsewhere
//! A front end that spreads a study's samples over processes (the CLI's MPI build) keeps
//! the folder on one process with [`StudyDir::restore`], [`StudyDir::save_in_progress`]
//! and [`StudyDir::finish`], and computes chosen samples of a task anywhere with
//! [`TaskSamples`]: assembled in index order, they give the serial run's checkpoints and
//! results byte for byte. [`Ledger`] does that bookkeeping: it hands out the samples not
//! yet computed and checkpoints every sample received ([`StudyDir::save_received`]), in
//! index order or not, so that a lost process costs only the samples it was computing.
//!
//! # Files, by concern
//! `spec.rs` what a study is ([`StudySpec`] with its rules and `Default`, [`Method`],
//! [`Task`], seeds, costs); `run.rs` how a task runs ([`Sampler`], [`run_task`], lanes,
//! [`TaskResult`]); `store/` the folder ([`StudyDir`], checkpoints, [`Restored`]), sealed
//! by [`identity`] and shared over processes by [`ledger`]; [`samplers`] (MDR, BEM);
//! [`curve`] (ensemble means, the α window); [`sensitivity`]; [`theory`]; [`compare`].

pub mod compare;
pub mod curve;
pub mod samplers;
pub mod sensitivity;
pub mod theory;

mod run;
mod spec;
mod store;

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

pub use curve::{
    ensemble_alpha, ensemble_curve, quantile, CurvePoint, EnsemblePoint, FitWindow, MeanInterval,
    SampleCurve,
};
#[allow(unused_imports)] // the crate-private items of the three, for the tests below
use run::*;
pub use run::{run_task, ProgressFn, Sampler, TaskResult};
pub use samplers::{run_any_task, run_any_task_with_loads, Scales, TaskSamples};
#[allow(unused_imports)]
use spec::*;
pub use spec::{
    sample_cost, sample_seed, Method, StudySpec, Task, ALPHA_SWEEP_MARGIN, DEFAULT_LEVELS,
    MAX_LEVELS, MAX_STUDY_SAMPLES,
};
pub use store::ledger::Ledger;
#[allow(unused_imports)]
use store::*;
pub use store::{identity, ledger};
pub use store::{
    Received, Restored, StudyDir, CHECKPOINT_INTERVAL, MAX_CHECKPOINT_INTERVAL_SECONDS,
};

use crate::bem::tangential::Directions;
use crate::fit::PowerLawFit;
use crate::lock::FolderLock;
use crate::memory::array_bytes;
use crate::spectrum::HURST_RANGE;
use crate::{io, Error, Result};
use identity::{TaskIdentity, Unsealed};

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A study of one task (N = `n`, H = 0.5, 3 samples) in a new folder, opened.
    pub(crate) fn three_sample_study(
        method: Method,
        n: usize,
    ) -> (StudySpec, tempfile::TempDir, StudyDir) {
        let spec = StudySpec {
            method,
            sizes: vec![n],
            hursts: vec![0.5],
            samples: 3,
            rolloff: None,
            seed: 3,
            window: FitWindow::default(),
            levels: 16,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        };
        let dir = tempfile::tempdir().unwrap();
        let store = StudyDir::open(dir.path(), &spec, false).unwrap();
        (spec, dir, store)
    }

    #[test]
    fn samples_held_are_what_a_run_of_that_size_reads_back() {
        // A finished task of 3 samples: a run of 3 reads back all 3; a run of 2 or 5
        // continues from the kept curves (BEM: 2 and 3 of them) or, without kept curves
        // (MDR), recomputes everything.
        for (method, n, other) in [(Method::Bem, 16, [2, 3]), (Method::Mdr, 512, [0, 0])] {
            let (spec, _dir, store) = three_sample_study(method, n);
            let task = spec.tasks()[0];
            assert_eq!(store.samples_held(task, 3).unwrap(), 0);
            run_any_task(&spec, task, &store, &|_, _| {}).unwrap();
            let held: Vec<usize> = [3, 2, 5]
                .iter()
                .map(|&wanted| store.samples_held(task, wanted).unwrap())
                .collect();
            assert_eq!(held, [3, other[0], other[1]], "{method:?}");
        }
    }

    #[test]
    fn finished_bem_tasks_keep_their_sample_curves_and_mdr_tasks_do_not() {
        for (method, n, kept) in [(Method::Bem, 16, true), (Method::Mdr, 512, false)] {
            let (spec, dir, store) = three_sample_study(method, n);
            let task = spec.tasks()[0];
            let result = run_any_task(&spec, task, &store, &|_, _| {}).unwrap();
            let stored = StudyDir::read(dir.path())
                .unwrap()
                .stored_samples(task)
                .unwrap();
            if kept {
                // The stored curves give the finished result again, bit for bit.
                assert_eq!(stored.len(), 3);
                assert_eq!(
                    TaskResult::from_samples(&spec, task, &stored).unwrap(),
                    result
                );
            } else {
                assert!(stored.is_empty());
            }
        }
        assert!(StudyDir::read(tempfile::tempdir().unwrap().path()).is_err());
    }

    #[test]
    fn a_finished_bem_task_grows_from_its_kept_curves_to_a_fresh_runs_result() {
        let spec = |samples| StudySpec {
            method: Method::Bem,
            sizes: vec![16],
            hursts: vec![0.5],
            samples,
            rolloff: None,
            seed: 5,
            window: FitWindow::default(),
            levels: 16,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        };
        let (small, grown) = (spec(3), spec(5));
        let task = small.tasks()[0];
        let dir = tempfile::tempdir().unwrap();
        let store = StudyDir::open(dir.path(), &small, false).unwrap();
        run_any_task(&small, task, &store, &|_, _| {}).unwrap();
        drop(store);
        let kept = StudyDir::read(dir.path())
            .unwrap()
            .stored_samples(task)
            .unwrap();
        let store = StudyDir::open(dir.path(), &grown, false).unwrap();
        match store.restore(task).unwrap() {
            Restored::Partial(samples) => assert_eq!(samples, kept, "the 3 kept curves"),
            Restored::Done(_) => panic!("a task of 3 samples is not done at 5"),
        }
        let grown_result = run_any_task(&grown, task, &store, &|_, _| {}).unwrap();
        let fresh_dir = tempfile::tempdir().unwrap();
        let fresh = StudyDir::open(fresh_dir.path(), &grown, false).unwrap();
        assert_eq!(
            run_any_task(&grown, task, &fresh, &|_, _| {}).unwrap(),
            grown_result
        );
        // Shrinking would leave samples out of the results: refused unless discarding
        // (force), which keeps the checkpoint and takes its first samples: again a fresh
        // run's result.
        let err = StudyDir::open(dir.path(), &small, false).unwrap_err();
        assert!(matches!(err, Error::NarrowerStudy { .. }), "{err}");
        let store = StudyDir::open(dir.path(), &small, true).unwrap();
        let shrunk = run_any_task(&small, task, &store, &|_, _| {}).unwrap();
        let fresh_dir = tempfile::tempdir().unwrap();
        let fresh = StudyDir::open(fresh_dir.path(), &small, false).unwrap();
        assert_eq!(
            run_any_task(&small, task, &fresh, &|_, _| {}).unwrap(),
            shrunk
        );
    }

    #[test]
    fn seeds_differ_by_task_and_index_only() {
        let t = Task { n: 512, hurst: 0.5 };
        let a = sample_seed(1, Method::Mdr, t, 0);
        assert_eq!(a, sample_seed(1, Method::Mdr, t, 0));
        assert_ne!(a, sample_seed(1, Method::Mdr, t, 1));
        assert_ne!(a, sample_seed(2, Method::Mdr, t, 0));
        assert_ne!(a, sample_seed(1, Method::Bem, t, 0));
        assert_ne!(
            a,
            sample_seed(1, Method::Mdr, Task { n: 512, hurst: 0.6 }, 0)
        );
    }

    fn spec(samples: usize) -> StudySpec {
        StudySpec {
            method: Method::Mdr,
            sizes: vec![64],
            hursts: vec![0.5],
            samples,
            rolloff: None,
            seed: 3,
            window: FitWindow {
                min_contacts: 1,
                max_fraction: 1.0,
            },
            levels: 10,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        }
    }

    #[test]
    fn validation_rejects_bad_studies() {
        assert!(spec(0).validate().is_err());
        let mut s = spec(3);
        s.hursts.clear();
        assert!(s.validate().is_err());
        s.hursts = vec![4.0];
        assert!(s.validate().is_err());
        s.hursts = vec![0.5];
        s.sizes = vec![2];
        assert!(s.validate().is_err());
        s.sizes = vec![64];
        for end in [0.0, -0.1, 1.5, f64::NAN, f64::INFINITY] {
            s.sweep_end = Some(end);
            let err = s.validate().unwrap_err().to_string();
            assert!(err.contains("sweep_end"), "{end}: {err}");
        }
        s.sweep_end = Some(1.0);
        s.validate().unwrap();
    }

    #[test]
    fn an_alpha_sweep_ends_past_every_window_it_may_be_fitted_on() {
        let mut s = spec(3);
        s.method = Method::Bem;
        s.window = FitWindow::default();
        s.sizes = vec![128, 64];
        // 4 × the sensitivity table's 2 % (above the default window's 1 %).
        assert_eq!(s.clone().with_alpha_sweep().sweep_end, Some(0.08));
        s.window.max_fraction = 0.05;
        assert_eq!(s.clone().with_alpha_sweep().sweep_end, Some(0.2));
        // On a 16² grid, 16 contacts are 6.25 % and the window spans 4× that: 25 %, so
        // the sweep would end past full contact, and solves every load.
        s.window.max_fraction = 0.01;
        s.sizes = vec![64, 16];
        assert_eq!(s.clone().with_alpha_sweep().sweep_end, None);
        s.sizes = vec![32];
        let end = s.clone().with_alpha_sweep().sweep_end.unwrap();
        assert!((end - 4.0 * 4.0 * 16.0 / 1024.0).abs() < 1e-15, "{end}");
        // MDR curves cost one pass whatever their length: no sweep to end.
        s.method = Method::Mdr;
        assert_eq!(s.with_alpha_sweep().sweep_end, None);
    }

    #[test]
    fn repeated_or_colliding_values_are_refused() {
        let message = |s: &StudySpec| s.validate().unwrap_err().to_string();
        let mut s = spec(3);
        s.sizes = vec![64, 128, 64];
        assert!(
            message(&s).contains("N = 64 is given twice"),
            "{}",
            message(&s)
        );
        s.sizes = vec![64];
        s.hursts = vec![0.5, 1.0, 0.5];
        assert!(
            message(&s).contains("H = 0.5 is given twice"),
            "{}",
            message(&s)
        );
        s.hursts = vec![0.0, -0.0];
        assert!(s.validate().is_err(), "0 and -0 are one H");
        // Distinct values that round to the same checkpoint name: both named.
        s.hursts = vec![0.5000001, 0.5000002];
        let m = message(&s);
        assert!(m.contains("0.5000001") && m.contains("0.5000002"), "{m}");
        s.hursts = vec![0.500001, 0.500002];
        s.validate().unwrap();
        assert_ne!(s.tasks()[0].key(Method::Mdr), s.tasks()[1].key(Method::Mdr));
    }

    #[test]
    fn a_checkpoint_of_another_task_under_the_same_name_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let spec = spec(5);
        let store = StudyDir::open(dir.path(), &spec, false).unwrap();
        let stored = Task {
            n: 64,
            hurst: 0.5000001,
        };
        let asked = Task {
            n: 64,
            hurst: 0.5000002,
        };
        assert_eq!(stored.key(Method::Mdr), asked.key(Method::Mdr));
        // In progress.
        let first = vec![Synthetic.sample(&mut (), 1).unwrap()];
        store.save_in_progress(stored, &first).unwrap();
        let err = run_task(&spec, asked, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        assert!(err.to_string().contains("0.5000001"), "{err}");
        // Finished.
        run_task(&spec, stored, &Synthetic, &store, &|_, _| {}).unwrap();
        let err = run_task(&spec, asked, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        // The stored task itself is read back.
        run_task(&spec, stored, &Synthetic, &store, &|_, _| {}).unwrap();
    }

    /// An ended sweep resumes the whole sweep whose samples the folder holds (the same
    /// study otherwise, or that study extended); never another study's, never a folder
    /// without samples, and never the other way round.
    #[test]
    fn an_ended_sweep_resumes_the_whole_sweep_a_folder_holds() {
        let dir = tempfile::tempdir().unwrap();
        let whole = spec(4);
        let ended = StudySpec {
            sweep_end: Some(0.08),
            ..spec(4)
        };
        // study.json alone: the folder is free, the ended sweep runs as asked.
        let store = StudyDir::open(dir.path(), &whole, false).unwrap();
        assert_eq!(StudyDir::resumable(dir.path(), ended.clone(), false), ended);
        let one = vec![Synthetic.sample(&mut (), 1).unwrap()];
        store
            .save_in_progress(Task { n: 64, hurst: 0.5 }, &one)
            .unwrap();
        assert_eq!(StudyDir::resumable(dir.path(), ended.clone(), false), whole);
        assert_eq!(StudyDir::resumable(dir.path(), ended.clone(), true), ended);
        // The same with more samples (the study extended) ...
        let more = StudySpec {
            samples: 9,
            ..ended.clone()
        };
        let resumed = StudyDir::resumable(dir.path(), more.clone(), false);
        assert_eq!((resumed.sweep_end, resumed.samples), (None, 9));
        StudyDir::open(dir.path(), &resumed, false).unwrap();
        // ... but not with another seed, nor a whole sweep in an ended one's folder.
        let other = StudySpec { seed: 9, ..more };
        assert_eq!(StudyDir::resumable(dir.path(), other.clone(), false), other);
        let ended_dir = tempfile::tempdir().unwrap();
        let store = StudyDir::open(ended_dir.path(), &ended, false).unwrap();
        store
            .save_in_progress(Task { n: 64, hurst: 0.5 }, &one)
            .unwrap();
        assert_eq!(
            StudyDir::resumable(ended_dir.path(), whole.clone(), false),
            whole
        );
        assert!(StudyDir::open(ended_dir.path(), &whole, false).is_err());
    }

    #[test]
    fn a_folder_without_samples_is_free_for_another_study() {
        let dir = tempfile::tempdir().unwrap();
        // study.json written, then stopped before any checkpoint.
        StudyDir::open(dir.path(), &spec(20), false).unwrap();
        let store = StudyDir::open(dir.path(), &spec(21), false).unwrap();
        // An in-progress checkpoint without samples keeps nothing either.
        store
            .save_in_progress(Task { n: 64, hurst: 0.5 }, &[])
            .unwrap();
        let store = StudyDir::open(dir.path(), &spec(22), false).unwrap();
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("study.json")).unwrap()).unwrap();
        assert_eq!(manifest["spec"]["samples"], 22);
        assert_eq!(manifest["normalisation"]["rms_height"], 1.0);
        // One sample makes it another study's again.
        let one = vec![Synthetic.sample(&mut (), 1).unwrap()];
        store
            .save_in_progress(Task { n: 64, hurst: 0.5 }, &one)
            .unwrap();
        // (Another seed: more samples alone would extend the study.)
        let other = StudySpec {
            seed: 7,
            ..spec(23)
        };
        let err = StudyDir::open(dir.path(), &other, false).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        // A file that cannot be read counts as holding samples.
        std::fs::write(dir.path().join("checkpoint/x.json"), "{").unwrap();
        std::fs::remove_file(dir.path().join("checkpoint").join(format!(
            "{}.json",
            Task { n: 64, hurst: 0.5 }.key(Method::Mdr)
        )))
        .unwrap();
        assert!(StudyDir::open(dir.path(), &other, false).is_err());
    }

    /// Fails (and requests `stop`) on the sample whose seed is `failing`.
    struct FailsAt {
        failing: u64,
        stop: crate::stop::Stop,
    }

    impl Sampler for FailsAt {
        type Worker = ();
        fn worker(&self) -> Result<()> {
            Ok(())
        }
        fn sample(&self, worker: &mut (), seed: u64) -> Result<SampleCurve> {
            if seed == self.failing {
                self.stop.request();
                return Err(Error::invalid("sample", "interrupted"));
            }
            Synthetic.sample(worker, seed)
        }
    }

    /// Item 8 of issue 33: a task stopped early (Ctrl-C) or by a failed sample keeps the
    /// samples it finished, though no checkpoint interval has passed.
    #[test]
    fn an_interrupted_task_checkpoints_the_samples_it_finished() {
        let task = Task { n: 64, hurst: 0.5 };
        let dir = tempfile::tempdir().unwrap();
        let stop = crate::stop::Stop::new();
        let store = StudyDir::open(dir.path(), &spec(20), false)
            .unwrap()
            .with_stop(stop.clone());
        let failing = FailsAt {
            failing: sample_seed(3, Method::Mdr, task, 6),
            stop: stop.clone(),
        };
        assert!(run_task(&spec(20), task, &failing, &store, &|_, _| {}).is_err());
        let Restored::Partial(held) = store.restore(task).unwrap() else {
            panic!("not finished")
        };
        assert_eq!(held.len(), 6, "samples 0 to 5 kept");
        // Resumed with the stop still requested: nothing computed, nothing lost.
        let err = run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(matches!(err, Error::Interrupted { .. }), "{err}");
        assert_eq!(store.samples_held(task, 20).unwrap(), 6);
        stop.clear();
        let resumed = run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap();
        let fresh = {
            let other = tempfile::tempdir().unwrap();
            let store = StudyDir::open(other.path(), &spec(20), false).unwrap();
            run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap()
        };
        assert_eq!(resumed, fresh);
    }

    #[cfg(unix)]
    #[test]
    fn links_in_place_of_checkpoints_are_refused_and_their_targets_untouched() {
        let task = Task { n: 64, hurst: 0.5 };
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim.json");
        std::fs::write(&victim, "precious").unwrap();
        let store = StudyDir::open(dir.path(), &spec(4), false).unwrap();
        std::os::unix::fs::symlink(&victim, checkpoint_file(dir.path(), task)).unwrap();
        let sample = Synthetic.sample(&mut (), 1).unwrap();
        let err = store.save_in_progress(task, &[sample]).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert!(StudyDir::open(dir.path(), &spec(4), false).is_err());
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        // A link in place of the checkpoint folder.
        let elsewhere = tempfile::tempdir().unwrap();
        let linked = tempfile::tempdir().unwrap();
        std::os::unix::fs::symlink(elsewhere.path(), linked.path().join("checkpoint")).unwrap();
        let err = StudyDir::open(linked.path(), &spec(4), false).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert_eq!(std::fs::read_dir(elsewhere.path()).unwrap().count(), 0);
    }

    fn checkpoint_file(dir: &Path, task: Task) -> PathBuf {
        dir.join("checkpoint")
            .join(format!("{}.json", task.key(Method::Mdr)))
    }

    #[test]
    fn checkpoints_of_older_versions_are_refused_not_merged() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let store = StudyDir::open(dir.path(), &spec(4), false).unwrap();
        // The format before identities: key, task and samples, no checksum.
        let old = serde_json::json!({
            "state": "in_progress",
            "key": task.key(Method::Mdr),
            "task": task,
            "samples": [Synthetic.sample(&mut (), 1).unwrap()],
        });
        std::fs::write(checkpoint_file(dir.path(), task), old.to_string()).unwrap();
        let err = run_task(&spec(4), task, &Synthetic, &store, &|_, _| {}).unwrap_err();
        let text = err.to_string();
        assert!(
            matches!(err, Error::DamagedStudy { .. }) && text.contains("older asperity"),
            "{text}"
        );
        // Discarding (force) clears it.
        let mut other = spec(4);
        other.seed = 9;
        StudyDir::open(dir.path(), &other, true).unwrap();
        assert!(!checkpoint_file(dir.path(), task).exists());
    }

    /// Item 1 of issue 9: a checkpoint copied from another study, or left by a study whose
    /// study.json was deleted, is refused naming every field that differs; an edited or
    /// damaged one is refused by its checksum.
    #[test]
    fn checkpoints_carry_their_identity_and_checksum() {
        let task = Task { n: 64, hurst: 0.5 };
        let first = tempfile::tempdir().unwrap();
        let store = StudyDir::open(first.path(), &spec(6), false).unwrap();
        store
            .save_in_progress(task, &[Synthetic.sample(&mut (), 1).unwrap()])
            .unwrap();
        let saved = std::fs::read(checkpoint_file(first.path(), task)).unwrap();
        type Change = Box<dyn Fn(&mut StudySpec)>;
        let variants: Vec<(&str, Change)> = vec![
            ("seed", Box::new(|s| s.seed = 4)),
            ("rolloff", Box::new(|s| s.rolloff = Some(6.0))),
            ("levels", Box::new(|s| s.levels = 11)),
            (
                "window.min_contacts",
                Box::new(|s| s.window.min_contacts = 2),
            ),
            ("sweep_end", Box::new(|s| s.sweep_end = Some(0.08))),
        ];
        for (field, change) in variants {
            let mut other = spec(6);
            change(&mut other);
            let dir = tempfile::tempdir().unwrap();
            let store = StudyDir::open(dir.path(), &other, false).unwrap();
            // No study.json from the first study: only the copied checkpoint.
            std::fs::write(checkpoint_file(dir.path(), task), &saved).unwrap();
            let err = run_task(&other, task, &Synthetic, &store, &|_, _| {}).unwrap_err();
            assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
            let text = err.to_string();
            assert!(
                text.contains(&format!("{field}: stored")),
                "{field}: {text}"
            );
            assert!(!text.contains('\n'));
            // Refused, not merged: the copied file is left as it was.
            assert_eq!(
                std::fs::read(checkpoint_file(dir.path(), task)).unwrap(),
                saved
            );
        }
        // A hand edit that keeps valid JSON: a changed stiffness.
        let text = String::from_utf8(saved.clone()).unwrap();
        let at = text.find("\"stiffness\":").unwrap() + 12;
        let mut edited = text.clone();
        edited.insert(at, '9');
        std::fs::write(checkpoint_file(first.path(), task), edited).unwrap();
        let err = run_task(&spec(6), task, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(err.to_string().contains("checksum"), "{err}");
        // Truncated: corrupt.
        std::fs::write(
            checkpoint_file(first.path(), task),
            &saved[..saved.len() / 2],
        )
        .unwrap();
        let err = run_task(&spec(6), task, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(err.to_string().contains("corrupt checkpoint"), "{err}");
        // Intact: resumed.
        std::fs::write(checkpoint_file(first.path(), task), &saved).unwrap();
        run_task(&spec(6), task, &Synthetic, &store, &|_, _| {}).unwrap();
    }

    #[test]
    fn a_corrupt_study_json_is_named_as_such() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let store = StudyDir::open(dir.path(), &spec(4), false).unwrap();
        store
            .save_in_progress(task, &[Synthetic.sample(&mut (), 1).unwrap()])
            .unwrap();
        std::fs::write(dir.path().join("study.json"), "{\"format\": \"asp").unwrap();
        let err = StudyDir::check(dir.path(), &spec(4), false)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("corrupt study file") && !err.contains("other parameters"),
            "{err}"
        );
        // Another study's parameters are named.
        let mut other = spec(4);
        other.seed = 77;
        StudyDir::open(dir.path(), &spec(4), true).unwrap();
        store
            .save_in_progress(task, &[Synthetic.sample(&mut (), 1).unwrap()])
            .unwrap();
        let err = StudyDir::check(dir.path(), &other, false)
            .unwrap_err()
            .to_string();
        assert!(err.contains("seed: stored 3, wanted 77"), "{err}");
    }

    #[test]
    fn sizes_and_ranges_are_bounded_up_front() {
        // Item 7: 1e12 levels, an absurd sample count (ranges: the CLI's `range`).
        let mut s = spec(3);
        s.levels = 1_000_000_000_000;
        let err = s.validate().unwrap_err().to_string();
        assert!(err.contains("force levels"), "{err}");
        s.levels = 10;
        s.samples = usize::MAX / 2;
        s.hursts = vec![0.1, 0.2, 0.3];
        let err = s.validate().unwrap_err().to_string();
        assert!(err.contains("samples a study may hold"), "{err}");
    }

    #[test]
    fn duplicate_h_checking_is_linear() {
        // Item 9: 40 001 values (the quadratic check took minutes at this size).
        // H = -1, -0.9999, ..., 3 (rounded as the CLI's ranges are, so that 0.5 is exact).
        let hursts: Vec<f64> = (0..=40_000)
            .map(|i| ((-1.0 + i as f64 * 1e-4) * 1e12).round() / 1e12)
            .collect();
        assert_eq!(hursts.len(), 40_001);
        let mut s = spec(1);
        s.hursts = hursts;
        let start = std::time::Instant::now();
        s.validate().unwrap();
        // Milliseconds when linear, minutes when quadratic; the bound leaves room for a
        // busy machine (issue 33 item 16).
        assert!(
            start.elapsed() < std::time::Duration::from_secs(20),
            "{:?}",
            start.elapsed()
        );
        s.hursts.push(0.5);
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .contains("given twice"));
    }

    #[test]
    fn sample_costs_grow_with_n() {
        assert!(sample_cost(Method::Bem, 128) / sample_cost(Method::Bem, 64) > 4.0);
        let mdr = sample_cost(Method::Mdr, 1 << 15) / sample_cost(Method::Mdr, 1 << 9);
        assert!((mdr - 64.0 * 15.0 / 9.0).abs() < 1e-9);
    }

    /// A sampler whose curve is a deterministic function of the seed.
    struct Synthetic;
    impl Sampler for Synthetic {
        type Worker = ();
        fn worker(&self) -> Result<()> {
            Ok(())
        }
        fn sample(&self, _: &mut (), seed: u64) -> Result<SampleCurve> {
            let c = 1.0 + (seed % 1000) as f64 / 1000.0;
            let points = (1..50)
                .map(|j| {
                    let force = j as f64 * c;
                    CurvePoint {
                        fraction: j as f64 / 64.0,
                        force,
                        stiffness: force.sqrt(),
                        tangential_ratio: None,
                    }
                })
                .collect();
            Ok(SampleCurve {
                points_total: 64,
                points,
                piecewise_constant: false,
            })
        }
    }

    #[test]
    fn costly_samples_checkpoint_after_one_per_lane() {
        assert_eq!(batch_size(Method::Mdr, 1 << 15, 2), 8);
        assert_eq!(batch_size(Method::Bem, 128, 2), 8);
        assert_eq!(batch_size(Method::Bem, 256, 2), 2);
        assert_eq!(batch_size(Method::Bem, 1024, 16), 16);
    }

    #[test]
    fn a_study_grows_by_grids_h_values_and_samples_reusing_its_checkpoints() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let run = |spec: &StudySpec| -> Vec<TaskResult> {
            let store = StudyDir::open(dir.path(), spec, false).unwrap();
            spec.tasks()
                .into_iter()
                .map(|t| run_task(spec, t, &Synthetic, &store, &|_, _| {}).unwrap())
                .collect()
        };
        let first = run(&spec(6));
        let path = dir
            .path()
            .join("checkpoint")
            .join(format!("{}.json", task.key(Method::Mdr)));
        let modified = || std::fs::metadata(&path).unwrap().modified().unwrap();
        let before = modified();
        // Another N and another H: the finished task is read back, not recomputed.
        let wider = StudySpec {
            sizes: vec![64, 128],
            hursts: vec![0.5, 1.0],
            ..spec(6)
        };
        let grown = run(&wider);
        assert_eq!(grown.len(), 4);
        assert_eq!(grown[0], first[0], "the stored task, bit for bit");
        assert_eq!(modified(), before, "its checkpoint untouched");
        // More samples: that task again, now with 9, equal to a fresh study of 9.
        let more = StudySpec {
            samples: 9,
            ..wider.clone()
        };
        let extended = run(&more);
        let fresh = {
            let other = tempfile::tempdir().unwrap();
            let store = StudyDir::open(other.path(), &more, false).unwrap();
            run_task(&more, task, &Synthetic, &store, &|_, _| {}).unwrap()
        };
        assert_eq!(extended[0], fresh);
        // Anything else still makes another study.
        let rolled = StudySpec {
            rolloff: Some(2.0),
            ..more
        };
        let err = StudyDir::open(dir.path(), &rolled, false).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
    }

    #[test]
    fn foreign_checkpoint_is_refused_and_resume_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let full = {
            let store = StudyDir::open(dir.path(), &spec(20), false).unwrap();
            run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap()
        };
        // A different study in the same folder is refused and nothing is lost.
        let other_seed = StudySpec {
            seed: 4,
            ..spec(20)
        };
        let err = StudyDir::open(dir.path(), &other_seed, false).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        assert!(
            err.to_string().contains("seed: stored 3, wanted 4"),
            "{err}"
        );
        // A field the stored spec leaves out (an optional one) is named too.
        let ended = StudySpec {
            sweep_end: Some(0.5),
            ..spec(20)
        };
        let err = StudyDir::open(dir.path(), &ended, false).unwrap_err();
        assert!(
            err.to_string()
                .contains("sweep_end: stored null, wanted 0.5"),
            "{err}"
        );
        assert!(dir
            .path()
            .join("checkpoint")
            .join(format!("{}.json", task.key(Method::Mdr)))
            .exists());
        // Interrupted run: keep only the first 7 samples in the checkpoint, then resume.
        let other = tempfile::tempdir().unwrap();
        let store = StudyDir::open(other.path(), &spec(20), false).unwrap();
        let first: Vec<SampleCurve> = (0..7)
            .map(|i| {
                let seed = sample_seed(3, Method::Mdr, task, i);
                Synthetic.sample(&mut (), seed).unwrap()
            })
            .collect();
        store.save_in_progress(task, &first).unwrap();
        let resumed = run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap();
        assert_eq!(resumed, full);
        let a = serde_json::to_string(&resumed).unwrap();
        assert_eq!(a, serde_json::to_string(&full).unwrap(), "bit for bit");
    }
}
