//! Where a study keeps its spec and checkpoints: the folder ([`StudyDir`]: check, lock,
//! open, resume), the sealed checkpoint of each task and what it restores; [`identity`]
//! seals each checkpoint with what produced it, and [`ledger`] shares a study's samples
//! over processes (MPI).

pub mod identity;
pub mod ledger;

use super::*;

#[derive(Debug, Serialize, Deserialize)]
pub(super) struct Manifest {
    pub(super) format: String,
    pub(super) spec: StudySpec,
    /// Scales of the samples; informative here (each checkpoint's identity holds them
    /// too, and is compared).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) normalisation: Option<Scales>,
}

/// What `checkpoint/<task>.json` holds, sealed with the task's [`TaskIdentity`]: the
/// samples of a task in progress, or the result of a finished one. A finished BEM task
/// keeps its sample curves too (24 loads a sample: tens of kB), so that its α can be
/// refitted with other windows without solving again ([`StudyDir::stored_samples`]); a
/// finished MDR task does not (up to a thousand points a line, 500 lines; recomputing
/// them takes seconds).
#[derive(Debug, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "snake_case")]
pub(super) enum Checkpoint {
    InProgress {
        samples: Vec<SampleCurve>,
        /// Samples received beyond the first missing index, by index: a front end that
        /// computes samples out of order ([`StudyDir::save_received`], the MPI build)
        /// keeps them too. Absent (and then not written) in serial runs.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        later: Vec<LaterSample>,
    },
    Done {
        result: TaskResult,
        /// The sample curves (BEM only; absent from checkpoints written before they were kept).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        samples: Vec<SampleCurve>,
    },
}

/// A sample of a task in progress saved beyond the first missing index.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct LaterSample {
    pub(super) index: usize,
    pub(super) sample: SampleCurve,
}

/// A task in progress saves its samples at most this often (and always when it ends), so
/// that fast tasks (MDR) do not spend their time rewriting checkpoints.
pub const CHECKPOINT_INTERVAL: std::time::Duration = std::time::Duration::from_secs(10);

/// The longest checkpoint interval a caller may ask for, in seconds (about 11 days): longer
/// is no checkpoint at all, and `Duration::from_secs_f64` panics past its range.
pub const MAX_CHECKPOINT_INTERVAL_SECONDS: f64 = 1e6;

pub(super) const MANIFEST_FORMAT: &str = "asperity-study/1";

/// The largest checkpoint file read (2^34 bytes); the memory guard checks it first.
pub(super) const CHECKPOINT_MAX_BYTES: u64 = 1 << 34;

/// Where a study keeps its spec and checkpoints.
#[derive(Debug, Clone)]
pub struct StudyDir {
    pub(super) dir: PathBuf,
    pub(super) spec: StudySpec,
    pub(super) interval: std::time::Duration,
    pub(super) stop: crate::stop::Stop,
}

/// What a folder's `study.json` says, as [`StudyDir::check`] sees it.
pub(super) enum Stored {
    None,
    Same,
    /// The same study over more N, H or samples: it is extended, each
    /// checkpoint reused where its task's identity matches.
    Extended,
    /// The same study without some of the stored one's (N, H) or with fewer samples:
    /// what the stored study finished would be left out of the results.
    Narrower(String),
    Other(String),
    Corrupt(String),
}

impl StudyDir {
    /// Locks the study folder `dir` (made if missing) against other processes for as long
    /// as the returned lock lives (see [`FolderLock`]); a folder in use is refused at once.
    pub fn lock(dir: &Path) -> Result<FolderLock> {
        io::check_folder(dir)?;
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        FolderLock::acquire(dir)
    }

    pub(super) fn stored_spec(dir: &Path, spec: &StudySpec) -> Result<Stored> {
        let path = dir.join("study.json");
        if std::fs::symlink_metadata(&path).is_err() {
            return Ok(Stored::None);
        }
        let text = crate::input::read_text(&path, crate::input::TEXT_MAX_BYTES)?;
        let manifest = match serde_json::from_str::<Manifest>(&text) {
            Ok(m) if m.format == MANIFEST_FORMAT => m,
            Ok(m) => return Ok(Stored::Corrupt(format!("unknown format {:?}", m.format))),
            Err(e) => return Ok(Stored::Corrupt(crate::input::one_line(&e.to_string()))),
        };
        if &manifest.spec == spec {
            return Ok(Stored::Same);
        }
        // The grids, H values and sample count are not part of a task's identity: a task
        // of the stored study is the same task in this one.
        let extended = StudySpec {
            sizes: spec.sizes.clone(),
            hursts: spec.hursts.clone(),
            samples: spec.samples,
            ..manifest.spec.clone()
        };
        if &extended == spec {
            return Ok(match narrowing(&manifest.spec, spec) {
                Some(left_out) => Stored::Narrower(left_out),
                None => Stored::Extended,
            });
        }
        Ok(Stored::Other(spec_differences(&manifest.spec, spec)))
    }

    /// Checks, without writing, whether `dir` can hold `spec`:
    ///
    /// * `Ok(false)` when it is new or holds the same study (which then resumes; each
    ///   checkpoint is still checked against its task's identity when read), or the same
    ///   study over other grids N, H values or sample count (which is extended: the tasks
    ///   in both keep their checkpoints; a finished BEM task whose sample count changed
    ///   continues from its kept sample curves, a finished MDR task is computed again);
    /// * `Ok(true)` when its checkpoints are to be cleared first: it holds another study
    ///   (or a corrupt `study.json`, or checkpoints without one) and `discard` is set, or
    ///   its `study.json` names another study but no checkpoint holds a sample (that study
    ///   stopped before its first checkpoint: nothing is lost);
    /// * [`Error::NarrowerStudy`] when it holds samples of the same study and `spec` leaves
    ///   out one of its (N, H) or takes fewer samples (its results would shrink: a folder
    ///   only grows), unless `discard`, which then keeps every checkpoint (`Ok(false)`);
    /// * [`Error::ForeignCheckpoint`] when it holds samples of another study, and
    ///   [`Error::Metadata`] when its `study.json` is corrupt and checkpoints hold samples.
    pub fn check(dir: &Path, spec: &StudySpec, discard: bool) -> Result<bool> {
        io::check_folder(dir)?;
        let stored = Self::stored_spec(dir, spec)?;
        if matches!(stored, Stored::Same | Stored::Extended) {
            return Ok(false);
        }
        if let Stored::Narrower(left_out) = stored {
            // Its checkpoints stay valid (a later run over them reads them back).
            if discard || !Self::holds_samples(dir)? {
                return Ok(false);
            }
            return Err(Error::NarrowerStudy {
                dir: dir.to_path_buf(),
                reason: left_out,
            });
        }
        if !Self::holds_samples(dir)? {
            return Ok(!matches!(stored, Stored::None));
        }
        if discard {
            return Ok(true);
        }
        match stored {
            Stored::None | Stored::Same | Stored::Extended | Stored::Narrower(_) => Ok(false),
            Stored::Other(differences) => Err(Error::ForeignCheckpoint {
                dir: dir.to_path_buf(),
                reason: format!("its study.json has other parameters: {differences}"),
            }),
            Stored::Corrupt(why) => Err(Error::DamagedStudy {
                path: dir.join("study.json"),
                reason: format!("corrupt study file ({why}); restore it"),
            }),
        }
    }

    /// The study to run in `dir` for `spec`: `spec` itself, or, where `dir` holds samples
    /// of the same study with every load solved (no [`StudySpec::sweep_end`]: an α study
    /// made before α sweeps ended early, or with a full sweep), which `spec` would refuse
    /// as another study's, that whole-sweep study, so that the run resumes its checkpoints
    /// (its α are the same, bit for bit, at the cost of the loads past the windows). Never
    /// the other way round: a whole sweep does not take an ended one's samples; and never
    /// when `discard` (the caller discards another study's checkpoints, as in
    /// [`StudyDir::check`]).
    pub fn resumable(dir: &Path, spec: StudySpec, discard: bool) -> StudySpec {
        if discard || spec.sweep_end.is_none() || Self::check(dir, &spec, false).is_ok() {
            return spec;
        }
        let whole = StudySpec {
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
            ..spec.clone()
        };
        let resumes = matches!(
            Self::stored_spec(dir, &whole),
            Ok(Stored::Same | Stored::Extended)
        );
        if resumes && Self::holds_samples(dir).unwrap_or(false) {
            whole
        } else {
            spec
        }
    }

    /// Whether any checkpoint in `dir` holds a finished task or a sample. A checkpoint that
    /// cannot be read counts as holding one (nothing is discarded that might matter);
    /// temporary files of unfinished writes do not count.
    pub(super) fn holds_samples(dir: &Path) -> Result<bool> {
        let folder = dir.join("checkpoint");
        let entries = match std::fs::read_dir(&folder) {
            Ok(entries) => entries,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
            Err(e) => return Err(Error::io(&folder, e)),
        };
        for entry in entries {
            let path = entry.map_err(|e| Error::io(&folder, e))?.path();
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            if name.starts_with('.') || !name.ends_with(".json") {
                continue;
            }
            let value = crate::input::read_text(&path, CHECKPOINT_MAX_BYTES)
                .ok()
                .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok());
            let content = value.as_ref().map(|v| &v["content"]);
            let none = |v: &serde_json::Value| v.as_array().is_none_or(Vec::is_empty);
            let empty = content.is_some_and(|c| {
                c["state"] == "in_progress"
                    && c["samples"].as_array().is_some_and(Vec::is_empty)
                    && none(&c["later"])
            });
            if !empty {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Opens (creating) `dir` for `spec`: a folder with the same spec resumes, a folder with
    /// another study is refused unless `discard`, which deletes its checkpoints (see
    /// [`StudyDir::check`]). Another process must not work in the folder meanwhile: hold
    /// its [`StudyDir::lock`] (as the command-line front end does).
    pub fn open(dir: &Path, spec: &StudySpec, discard: bool) -> Result<Self> {
        if Self::check(dir, spec, discard)? {
            let checkpoints = dir.join("checkpoint");
            match std::fs::remove_dir_all(&checkpoints) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(Error::io(&checkpoints, e))
                }
                _ => {}
            }
        }
        let store = StudyDir {
            dir: dir.to_path_buf(),
            spec: spec.clone(),
            interval: CHECKPOINT_INTERVAL,
            stop: crate::stop::Stop::new(),
        };
        // Every checkpoint already there is verified before the folder is claimed, so that
        // a refused run leaves it exactly as it was.
        for task in spec.tasks() {
            store.load(task)?;
        }
        io::refuse_link(&dir.join("checkpoint"))?;
        std::fs::create_dir_all(dir.join("checkpoint")).map_err(|e| Error::io(dir, e))?;
        let manifest = Manifest {
            format: MANIFEST_FORMAT.into(),
            spec: spec.clone(),
            normalisation: Some(Scales::of(spec.method)),
        };
        io::write_json(&dir.join("study.json"), true, &manifest)?;
        Ok(store)
    }

    /// The study already in `dir`, read without writing anything (to read its
    /// checkpoints, e.g. [`StudyDir::stored_samples`]); an error when `dir` holds no study
    /// or a corrupt `study.json`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join("study.json");
        let text = crate::input::read_text(&path, crate::input::TEXT_MAX_BYTES)?;
        let manifest = serde_json::from_str::<Manifest>(&text)
            .ok()
            .filter(|m| m.format == MANIFEST_FORMAT)
            .ok_or_else(|| Error::DamagedStudy {
                path: path.clone(),
                reason: "not a study file of this asperity".into(),
            })?;
        Ok(StudyDir {
            dir: dir.to_path_buf(),
            spec: manifest.spec,
            interval: CHECKPOINT_INTERVAL,
            stop: crate::stop::Stop::new(),
        })
    }

    /// Saves tasks in progress at most every `interval` instead of [`CHECKPOINT_INTERVAL`]
    /// (zero: after every batch).
    pub fn with_checkpoint_interval(mut self, interval: std::time::Duration) -> Self {
        self.interval = interval;
        self
    }

    /// Tasks run on this folder ([`run_task`], [`run_any_task_with_loads`]) stop once
    /// `stop` is requested: between samples, and (BEM) within a solver iteration; the
    /// samples finished by then are checkpointed and the task ends with
    /// [`Error::Interrupted`] (or the interrupted sample's error).
    pub fn with_stop(mut self, stop: crate::stop::Stop) -> Self {
        self.stop = stop;
        self
    }

    /// The stop request the tasks run on this folder poll ([`StudyDir::with_stop`]).
    pub fn stop(&self) -> &crate::stop::Stop {
        &self.stop
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Refuses a symbolic link in place of the checkpoint folder or of the checkpoint
    /// `path`: a link planted in the study folder would redirect the study's writes.
    pub(super) fn refuse_links(&self, path: &Path) -> Result<()> {
        io::refuse_link(&self.dir.join("checkpoint"))?;
        io::refuse_link(path)
    }

    pub(super) fn checkpoint_path(&self, task: Task) -> PathBuf {
        let key = task.key(self.spec.method);
        self.dir.join("checkpoint").join(format!("{key}.json"))
    }

    /// The checkpoint of `task`, if any: refused unless intact (its checksum) and made by
    /// this task with this study's settings (its identity).
    pub(super) fn load(&self, task: Task) -> Result<Option<Checkpoint>> {
        let path = self.checkpoint_path(task);
        self.refuse_links(&path)?;
        let length = match std::fs::metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(Error::io(&path, e)),
            Ok(meta) => meta.len(),
        };
        // The text and its parsed samples (about as large again).
        crate::memory::ensure_fits(
            &format!("reading the checkpoint {}", path.display()),
            length.checked_mul(3),
        )?;
        let text = crate::input::read_text(&path, CHECKPOINT_MAX_BYTES)?;
        let wanted = TaskIdentity::of(&self.spec, task);
        let refuse = |what: String| Error::DamagedStudy {
            path: path.clone(),
            reason: format!("{what}; delete it to recompute its task"),
        };
        match identity::unseal::<Checkpoint>(text.as_bytes(), &wanted) {
            Ok(checkpoint) => Ok(Some(self.with_fraction_intervals(checkpoint))),
            Err(Unsealed::Corrupt(why)) => Err(refuse(format!("corrupt checkpoint ({why})"))),
            Err(Unsealed::Checksum) => Err(refuse(
                "the checkpoint does not match its checksum (edited or damaged)".into(),
            )),
            Err(Unsealed::Foreign(differences)) => Err(Error::ForeignCheckpoint {
                dir: self.dir.clone(),
                reason: format!(
                    "{} was made with other settings: {}",
                    path.display(),
                    differences.join(", ")
                ),
            }),
        }
    }

    /// A finished task's checkpoint written before the mean curve kept the contact
    /// fraction's interval (533a278, issue 36): the interval recomputed from the sample
    /// curves it keeps (BEM), by the operations that compute it for a new task, where they
    /// give the same force levels; else left unknown (MDR keeps no curves: an empty cell).
    /// The file is left as it is.
    fn with_fraction_intervals(&self, checkpoint: Checkpoint) -> Checkpoint {
        let Checkpoint::Done {
            mut result,
            samples,
        } = checkpoint
        else {
            return checkpoint;
        };
        let lacking = result
            .mean_curve
            .iter()
            .any(|p| p.lacks_fraction_interval());
        if lacking && !samples.is_empty() {
            let fresh = super::curve::ensemble_curve(&samples, self.spec.levels).ok();
            let old = &mut result.mean_curve;
            if let Some(fresh) = fresh.filter(|f| f.len() == old.len()) {
                if old.iter().zip(&fresh).all(|(a, b)| a.force == b.force) {
                    for (a, b) in old.iter_mut().zip(&fresh) {
                        (a.fraction_low, a.fraction_high) = (b.fraction_low, b.fraction_high);
                    }
                }
            }
        }
        Checkpoint::Done { result, samples }
    }

    pub(super) fn save(&self, task: Task, checkpoint: &Checkpoint) -> Result<()> {
        let path = self.checkpoint_path(task);
        self.refuse_links(&path)?;
        let bytes =
            identity::seal(&TaskIdentity::of(&self.spec, task), checkpoint).map_err(|reason| {
                Error::Metadata {
                    path: path.clone(),
                    reason,
                }
            })?;
        io::write_bytes(&path, true, &bytes)
    }

    /// Saves the first samples of `task`, in progress.
    pub fn save_in_progress(&self, task: Task, samples: &[SampleCurve]) -> Result<()> {
        self.save(
            task,
            &Checkpoint::InProgress {
                samples: samples.to_vec(),
                later: Vec::new(),
            },
        )
    }

    /// Saves the samples of `task` received so far, in progress: `slots[i]` is sample `i`
    /// if received. For front ends that receive samples out of index order (e.g. from
    /// other processes), so that a sample beyond a missing one is kept too.
    pub fn save_received(&self, task: Task, slots: &[Option<SampleCurve>]) -> Result<()> {
        let first = slots.iter().take_while(|s| s.is_some()).count();
        let later = slots
            .iter()
            .enumerate()
            .skip(first)
            .filter_map(|(index, s)| {
                s.as_ref().map(|sample| LaterSample {
                    index,
                    sample: sample.clone(),
                })
            })
            .collect();
        self.save(
            task,
            &Checkpoint::InProgress {
                samples: slots[..first].iter().flatten().cloned().collect(),
                later,
            },
        )
    }
}

/// What `spec`, the same study as `stored` over other N, H or samples, leaves out of
/// it: `None` when it covers every (N, H) of `stored` with at least its samples (it grows
/// the study), else e.g. `N = 4096 (stored 4096, wanted 2048)`.
pub(super) fn narrowing(stored: &StudySpec, spec: &StudySpec) -> Option<String> {
    let mut left_out = Vec::new();
    let sizes: Vec<usize> = (stored.sizes.iter())
        .filter(|n| !spec.sizes.contains(n))
        .copied()
        .collect();
    if !sizes.is_empty() {
        left_out.push(format!(
            "N = {sizes:?} (stored {:?}, wanted {:?})",
            stored.sizes, spec.sizes
        ));
    }
    let hursts: Vec<f64> = (stored.hursts.iter())
        .filter(|h| !spec.hursts.iter().any(|w| w.to_bits() == h.to_bits()))
        .copied()
        .collect();
    if !hursts.is_empty() {
        left_out.push(format!(
            "H = {hursts:?} (stored {:?}, wanted {:?})",
            stored.hursts, spec.hursts
        ));
    }
    if spec.samples < stored.samples {
        left_out.push(format!(
            "samples (stored {}, wanted {})",
            stored.samples, spec.samples
        ));
    }
    (!left_out.is_empty()).then(|| left_out.join(", "))
}

/// The fields of two specs that differ, as `name: stored X, wanted Y`.
pub(super) fn spec_differences(stored: &StudySpec, wanted: &StudySpec) -> String {
    let map = |s: &StudySpec| match serde_json::to_value(s) {
        Ok(serde_json::Value::Object(m)) => m,
        _ => serde_json::Map::new(),
    };
    let (a, b) = (map(stored), map(wanted));
    let clip = |v: &serde_json::Value| crate::input::clip(&v.to_string());
    let null = serde_json::Value::Null;
    // A key on one side only (an optional field left out) differs from `null`.
    let only_wanted = b.iter().filter(|(k, _)| !a.contains_key(*k));
    let items: Vec<String> = a
        .iter()
        .map(|(k, v)| (k, v, b.get(k).unwrap_or(&null)))
        .chain(only_wanted.map(|(k, w)| (k, &null, w)))
        .filter(|(_, v, w)| v != w)
        .map(|(k, v, w)| format!("{k}: stored {}, wanted {}", clip(v), clip(w)))
        .collect();
    items.join(", ")
}

/// What a task's checkpoint holds, as [`StudyDir::restore`] reads it.
#[derive(Debug, Clone, PartialEq)]
pub enum Restored {
    /// The task is finished: its result.
    Done(TaskResult),
    /// The task's first samples (none for a task not started), in index order.
    Partial(Vec<SampleCurve>),
}

/// What a task's checkpoint holds, sample by sample, as [`StudyDir::restore_received`]
/// reads it.
#[derive(Debug, Clone, PartialEq)]
pub enum Received {
    /// The task is finished: its result.
    Done(TaskResult),
    /// One slot per sample: those saved so far.
    Partial(Vec<Option<SampleCurve>>),
}

impl StudyDir {
    /// The checkpoint of `task`, read and verified as [`run_task`] reads it: the result of
    /// a finished task, or the samples saved so far (at most the study's sample count).
    /// For front ends that compute a task's samples elsewhere (e.g. on other processes)
    /// and keep its checkpoint with [`StudyDir::save_in_progress`] and
    /// [`StudyDir::finish`].
    pub fn restore(&self, task: Task) -> Result<Restored> {
        self.restore_as(task, self.spec.samples)
    }

    /// How many samples of `task` a run asking for `samples` of them reads back from its
    /// checkpoint instead of computing ([`StudyDir::restore`] with that count): what a
    /// progress bar or a run-time estimate leaves out before the run.
    pub fn samples_held(&self, task: Task, samples: usize) -> Result<usize> {
        Ok(match self.restore_as(task, samples)? {
            Restored::Done(_) => samples,
            Restored::Partial(held) => held.len(),
        })
    }

    /// [`StudyDir::restore`] for a run asking for `count` samples of `task`.
    pub(super) fn restore_as(&self, task: Task, count: usize) -> Result<Restored> {
        match self.load(task)? {
            Some(Checkpoint::Done { result, .. }) if result.samples == count => {
                Ok(Restored::Done(result))
            }
            // Samples saved beyond a gap are left out: the serial run computes in index
            // order (they are computed again, to the same bits). A finished task that kept
            // its sample curves (BEM) and now has another sample count continues from them:
            // sample i depends only on the seed and i, so the result is that of a fresh run.
            Some(Checkpoint::InProgress { mut samples, .. })
            | Some(Checkpoint::Done { mut samples, .. }) => {
                samples.truncate(count);
                Ok(Restored::Partial(samples))
            }
            None => Ok(Restored::Partial(Vec::new())),
        }
    }

    /// The checkpoint of `task` sample by sample: the result of a finished task, or one
    /// slot per sample of the study holding the samples saved so far, in and out of index
    /// order ([`StudyDir::save_received`]).
    pub fn restore_received(&self, task: Task) -> Result<Received> {
        let count = self.spec.samples;
        let mut slots = vec![None; count];
        match self.load(task)? {
            Some(Checkpoint::Done { result, .. }) if result.samples == count => {
                return Ok(Received::Done(result))
            }
            Some(Checkpoint::InProgress { samples, later }) => {
                for (slot, sample) in slots.iter_mut().zip(samples) {
                    *slot = Some(sample);
                }
                for LaterSample { index, sample } in later {
                    if let Some(slot) = slots.get_mut(index) {
                        *slot = Some(sample);
                    }
                }
            }
            // A finished task kept with another sample count continues from its curves
            // (as in [`StudyDir::restore`]).
            Some(Checkpoint::Done { samples, .. }) => {
                for (slot, sample) in slots.iter_mut().zip(samples) {
                    *slot = Some(sample);
                }
            }
            None => {}
        }
        Ok(Received::Partial(slots))
    }

    /// Ends `task` with all its `samples` (in index order): its result, saved as
    /// [`run_task`] saves it, so that the checkpoint is the same file byte for byte.
    pub fn finish(&self, task: Task, samples: Vec<SampleCurve>) -> Result<TaskResult> {
        if samples.len() != self.spec.samples {
            return Err(Error::invalid(
                "samples",
                format!(
                    "a task ends with its {} samples, got {}",
                    self.spec.samples,
                    samples.len()
                ),
            ));
        }
        let result = TaskResult::from_samples(&self.spec, task, &samples)?;
        let samples = match self.spec.method {
            Method::Bem => samples,
            Method::Mdr => Vec::new(),
        };
        self.save(
            task,
            &Checkpoint::Done {
                result: result.clone(),
                samples,
            },
        )?;
        Ok(result)
    }

    /// The sample curves of `task` stored in its checkpoint, in index order: those of a
    /// finished BEM task, or those saved so far of a task in progress; empty when none
    /// are stored (no checkpoint, a finished MDR task, or a checkpoint written before
    /// finished tasks kept their samples).
    pub fn stored_samples(&self, task: Task) -> Result<Vec<SampleCurve>> {
        Ok(match self.load(task)? {
            Some(Checkpoint::Done { samples, .. })
            | Some(Checkpoint::InProgress { samples, .. }) => samples,
            None => Vec::new(),
        })
    }

    /// The longest time between two checkpoints of a task in progress.
    pub fn checkpoint_interval(&self) -> std::time::Duration {
        self.interval
    }

    /// The study this folder was opened for.
    pub fn spec(&self) -> &StudySpec {
        &self.spec
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::{run_any_task, Method};

    /// A finished task's checkpoint as written before the mean curve kept the contact
    /// fraction's interval (533a278): the same result without `fraction_low`/`_high`.
    fn as_written_before_the_interval(store: &StudyDir, task: Task, keep_samples: bool) {
        let Some(Checkpoint::Done {
            mut result,
            samples,
        }) = store.load(task).unwrap()
        else {
            panic!("a finished task")
        };
        for p in &mut result.mean_curve {
            (p.fraction_low, p.fraction_high) = (f64::NAN, f64::NAN);
        }
        let samples = if keep_samples { samples } else { Vec::new() };
        store
            .save(task, &Checkpoint::Done { result, samples })
            .unwrap();
        let text = std::fs::read_to_string(store.checkpoint_path(task)).unwrap();
        assert!(!text.contains("fraction_low") && text.contains("\"fraction\""));
    }

    /// Every study folder written before 533a278 was refused as "corrupt checkpoint
    /// (missing field `fraction_low`)" (found resuming docs/results/tangential/study):
    /// such a checkpoint is read again, with the interval from its kept sample curves, the
    /// same as a new run's bit for bit; without kept curves, unknown (NaN).
    #[test]
    fn checkpoints_older_than_the_fraction_interval_are_read_with_it() {
        let (spec, _dir, store) = crate::study::tests::three_sample_study(Method::Bem, 16);
        let task = spec.tasks()[0];
        let result = run_any_task(&spec, task, &store, &|_, _| {}).unwrap();
        assert!(result.mean_curve.iter().all(|p| p.fraction_low.is_finite()));
        as_written_before_the_interval(&store, task, true);
        let Some(Checkpoint::Done { result: read, .. }) = store.load(task).unwrap() else {
            panic!("a finished task")
        };
        assert_eq!(read, result);
        as_written_before_the_interval(&store, task, false);
        let Some(Checkpoint::Done { result: read, .. }) = store.load(task).unwrap() else {
            panic!("a finished task")
        };
        assert!(read.mean_curve.iter().all(|p| p.lacks_fraction_interval()));
        let stiffness =
            |r: &TaskResult| r.mean_curve.iter().map(|p| p.stiffness).collect::<Vec<_>>();
        assert_eq!(stiffness(&read), stiffness(&result));
    }
}
