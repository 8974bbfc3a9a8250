//! Studies spread over the ranks of an MPI job (issue 15; built with the `mpi` feature).
//!
//! `mpirun -n K asperity study …` (or `srun`, or `asperity reproduce …`) runs the same
//! command on K processes. This module makes them one study:
//!
//! * **Rank 0 is the coordinator and the only writer.** It alone parses the command line,
//!   checks and locks the output folder ([`asperity::study::StudyDir::lock`], a `flock`),
//!   reads and writes checkpoints and writes the outputs; every other rank only computes
//!   samples and never opens the folder. A command that runs no study (e.g. `surface`)
//!   runs on rank 0 while the others wait for the end.
//! * **Who computes what is decided by the front-end layer's coordinator**
//!   ([`asperity_app::study::distributed::Coordinator`], a state machine without MPI that
//!   the Python package under `mpirun` drives too): this module turns each message into
//!   one of its events and carries out the actions it returns.
//! * **Samples are the unit of work, handed out dynamically.** A rank that is idle gets
//!   the next samples not yet given out (in task order, then index order; as many as it
//!   has threads, all of one task), computes them with
//!   [`asperity::study::TaskSamples`] and sends back their curves; BEM samples differ in
//!   cost, so a fast rank simply asks more often. Rank 0 computes too, on a thread of its
//!   own, while its main thread coordinates.
//! * **The same numbers.** Every sample is seeded by (study seed, method, N, H, index)
//!   ([`asperity::study::sample_seed`]) and depends on nothing else (not the rank, thread,
//!   or the samples a worker computed before: tested in the library), and rank 0
//!   assembles each task's samples in index order and ends it with
//!   [`asperity::study::StudyDir::finish`], as the serial run does. The CSV files and the
//!   finished checkpoints are therefore byte-identical to a single-process run, for any K,
//!   and either kind of run resumes the other's checkpoints. With K = 1 the serial code
//!   runs unchanged.
//! * **Checkpoints.** The coordinator keeps the study in an [`asperity::study::Ledger`], which
//!   checkpoints every sample received soon after it arrives, including samples beyond
//!   one still in flight (the checkpoint keeps them by index), so that a lost rank costs
//!   only the samples then being computed (the ledger's docs say when it writes).
//!
//! # Faults
//! MPI (Open MPI, MPICH, Slurm) ends the whole job when a rank dies; the launcher names
//! the rank that died (e.g. "mpirun noticed that process rank 1 … exited on signal 9").
//! What rank 0 had received is checkpointed (all but the samples in flight when the job
//! ended), and running the same command again resumes from it.
//! A sample that fails on a worker (a solver error) ends the study with an error naming
//! the rank, once the samples then in flight are in and checkpointed. An error of rank 0's
//! own (a garbled message) while samples are in flight aborts the job (`MPI_Abort`) after
//! printing it, so that no rank is left waiting.
//!
//! # Messages
//! One tag; JSON bodies (floats round-trip exactly, as in checkpoints). Worker → rank 0:
//! `Ready` once (its thread count), then `Done` or `Failed` per assignment. Rank 0 →
//! worker: `Assign` (the study's spec the first time a worker sees that study) or `Stop`.
//! Ranks that wait poll with short sleeps instead of blocking in MPI, whose blocking
//! receives spin and would take a core from the threads computing samples.

use std::collections::HashMap;
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::{anyhow, bail, Context, Result};
use asperity::study::{SampleCurve, StudyDir, StudySpec, Task, TaskResult, TaskSamples};
use asperity_app::study::distributed::{Action, Coordinator};
use mpi::point_to_point::{Destination, MatchedReceiveVec, Source};
use mpi::topology::{Communicator, SimpleCommunicator};
use serde::{Deserialize, Serialize};

/// The longest pause between two polls of a waiting rank; short against any sample.
const MAX_POLL: Duration = Duration::from_millis(20);

/// A message between ranks.
#[derive(Debug, Serialize, Deserialize)]
enum Message {
    /// Worker → rank 0, once: it is ready and computes this many samples at once.
    Ready { lanes: usize },
    /// Worker → rank 0: the curves of the samples assigned last, in the order asked.
    Done { curves: Vec<SampleCurve> },
    /// Worker → rank 0: the assignment failed.
    Failed { reason: String },
    /// Rank 0 → worker: compute samples `indices` of `task` of study number `study`
    /// (`spec` is sent the first time a worker meets a study).
    Assign {
        study: u64,
        spec: Option<StudySpec>,
        task: Task,
        indices: Vec<usize>,
    },
    /// Rank 0 → worker: the job is over.
    Stop,
}

fn encode(message: &Message) -> Vec<u8> {
    serde_json::to_vec(message).expect("messages serialise")
}

fn decode(bytes: &[u8], from: i32) -> Result<Message> {
    serde_json::from_slice(bytes).with_context(|| format!("a garbled message from rank {from}"))
}

/// Waits for the next message from `source` (any rank if `None`), polling.
fn receive(world: &SimpleCommunicator, source: Option<i32>) -> Result<(i32, Message)> {
    let mut pause = Duration::from_micros(100);
    loop {
        if let Some(got) = try_receive(world, source)? {
            return Ok(got);
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(MAX_POLL);
    }
}

fn try_receive(world: &SimpleCommunicator, source: Option<i32>) -> Result<Option<(i32, Message)>> {
    let probed = match source {
        Some(rank) => world.process_at_rank(rank).immediate_matched_probe(),
        None => world.any_process().immediate_matched_probe(),
    };
    let Some(probed) = probed else {
        return Ok(None);
    };
    let (bytes, status) = probed.matched_receive_vec::<u8>();
    let from = status.source_rank();
    Ok(Some((from, decode(&bytes, from)?)))
}

fn send(world: &SimpleCommunicator, rank: i32, message: &Message) {
    world.process_at_rank(rank).send(&encode(message)[..]);
}

/// Runs the command line under MPI: initialises MPI, runs `cli` on rank 0 and the worker
/// loop on the others, and returns the process's exit status.
pub fn main(cli: impl FnOnce() -> i32) -> i32 {
    // Serialized, not Funneled: one thread at a time calls MPI, but on rank 0 that is the
    // thread of rayon's pool the command runs on (main.rs), not the main thread.
    let Some((universe, _)) = mpi::initialize_with_threading(mpi::Threading::Serialized) else {
        eprintln!("error: MPI could not be initialised");
        return 2;
    };
    let world = universe.world();
    if world.size() <= 1 {
        return cli();
    }
    if world.rank() != 0 {
        return match serve(&world) {
            Ok(()) => 0,
            Err(err) => {
                eprintln!("error: rank {}: {err:#}", world.rank());
                world.abort(2)
            }
        };
    }
    *coordinator() = Some(Job::new(world.size()));
    let code = cli();
    let Some(mut state) = coordinator().take() else {
        return code;
    };
    if let Err(err) = state.stop(&world) {
        eprintln!("error: {err:#}");
        world.abort(if code == 0 { 2 } else { code });
    }
    drop(universe);
    code
}

/// The worker loop of ranks other than 0.
fn serve(world: &SimpleCommunicator) -> Result<()> {
    let lanes = rayon::current_num_threads().max(1);
    send(world, 0, &Message::Ready { lanes });
    let mut specs: HashMap<u64, StudySpec> = HashMap::new();
    let mut current: Option<(u64, TaskSamples)> = None;
    loop {
        match receive(world, Some(0))?.1 {
            Message::Stop => return Ok(()),
            Message::Assign {
                study,
                spec,
                task,
                indices,
            } => {
                if let Some(spec) = spec {
                    specs.insert(study, spec);
                }
                // On a thread of rayon's pool, so that the samples' parallel loops run
                // there directly (as the CLI runs its command, main.rs).
                let computed =
                    rayon::scope(|_| compute(&specs, &mut current, study, task, &indices));
                let reply = match computed {
                    Ok(curves) => Message::Done { curves },
                    Err(err) => Message::Failed {
                        reason: format!("{err:#}"),
                    },
                };
                send(world, 0, &reply);
            }
            other => bail!("unexpected message from rank 0: {other:?}"),
        }
    }
}

/// The samples `indices` of `task` of study `study`, with the workers of the last task
/// kept when the task is the same.
fn compute(
    specs: &HashMap<u64, StudySpec>,
    current: &mut Option<(u64, TaskSamples)>,
    study: u64,
    task: Task,
    indices: &[usize],
) -> Result<Vec<SampleCurve>> {
    let same = matches!(current, Some((s, t)) if *s == study && t.task().same_as(&task));
    if !same {
        let spec = specs
            .get(&study)
            .ok_or_else(|| anyhow!("no spec for study {study}"))?;
        *current = Some((study, TaskSamples::new(spec, task)?));
    }
    let (_, samples) = current.as_mut().expect("set above");
    Ok(samples.compute(indices)?)
}

/// The coordinator of rank 0, while the job runs with more than one rank.
fn coordinator() -> std::sync::MutexGuard<'static, Option<Job>> {
    static STATE: Mutex<Option<Job>> = Mutex::new(None);
    STATE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Whether studies run distributed (rank 0 of a job of several ranks).
pub fn active() -> bool {
    coordinator().is_some()
}

/// Rank 0's own worker: a thread computing samples while the main thread coordinates.
struct Local {
    jobs: Sender<(Arc<StudySpec>, u64, Task, Vec<usize>)>,
    results: Receiver<Result<Vec<SampleCurve>>>,
    thread: JoinHandle<()>,
}

impl Local {
    /// Starts the thread, with a rayon pool of `lanes` threads of its own: the coordinator
    /// runs on a thread of the global pool (the CLI runs its command there) and, polling,
    /// never lends it to other work, so that samples computed in the global pool could
    /// wait for it forever (a pool of one thread, as under `mpirun -n 2`, which binds each
    /// rank to one core).
    fn start(lanes: usize) -> Result<Local> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(lanes)
            .thread_name(|i| format!("rank0-samples-{i}"))
            .build()
            .context("rank 0 could not start its sample threads")?;
        let (jobs, job_rx) = mpsc::channel::<(Arc<StudySpec>, u64, Task, Vec<usize>)>();
        let (result_tx, results) = mpsc::channel();
        let thread = std::thread::spawn(move || {
            let mut current: Option<(u64, TaskSamples)> = None;
            let mut specs = HashMap::new();
            for (spec, study, task, indices) in job_rx {
                specs
                    .entry(study)
                    .or_insert_with(|| StudySpec::clone(&spec));
                let done = pool.install(|| compute(&specs, &mut current, study, task, &indices));
                if result_tx.send(done).is_err() {
                    return;
                }
            }
        });
        Ok(Local {
            jobs,
            results,
            thread,
        })
    }
}

/// The study being run: what an assignment needs.
struct Current {
    number: u64,
    spec: Arc<StudySpec>,
    tasks: Vec<Task>,
}

/// Rank 0's side of the job: the front-end layer's coordinator (which decides who computes
/// what, takes the samples in and checkpoints them: [`asperity_app::study::distributed`])
/// and the messages that carry its decisions out.
struct Job {
    machine: Coordinator,
    local: Option<Local>,
}

impl Job {
    fn new(size: i32) -> Job {
        let lanes = rayon::current_num_threads().max(1);
        Job {
            machine: Coordinator::new(size as usize, lanes),
            local: None,
        }
    }

    /// Ends the job: every other rank is told to stop once it is registered. Fails if
    /// samples are still in flight (a study ended by an error of this rank's own), which
    /// the caller turns into an abort.
    fn stop(&mut self, world: &SimpleCommunicator) -> Result<()> {
        let mut actions = self.machine.stop()?;
        if let Some(local) = self.local.take() {
            drop(local.jobs);
            let _ = local.thread.join();
        }
        loop {
            self.carry_out(world, None, actions)?;
            if self.machine.stopped() {
                return Ok(());
            }
            actions = match receive(world, None)? {
                (rank, Message::Ready { lanes }) => self.machine.on_ready(rank as usize, lanes),
                (rank, other) => bail!("unexpected message from rank {rank}: {other:?}"),
            };
        }
    }

    /// Carries out the coordinator's `actions`: whether the study ended.
    fn carry_out(
        &mut self,
        world: &SimpleCommunicator,
        study: Option<&Current>,
        actions: Vec<Action>,
    ) -> Result<bool> {
        let mut ended = false;
        for action in actions {
            match action {
                Action::Assign {
                    rank,
                    task,
                    indices,
                    spec,
                } => {
                    let study = study.ok_or_else(|| anyhow!("an assignment outside a study"))?;
                    self.assign(world, study, rank, study.tasks[task], indices, spec)?;
                }
                Action::Stop { rank } => send(world, rank as i32, &Message::Stop),
                Action::End => ended = true,
            }
        }
        Ok(ended)
    }

    /// Sends rank `rank` (rank 0: its own thread) samples `indices` of `task`.
    fn assign(
        &mut self,
        world: &SimpleCommunicator,
        study: &Current,
        rank: usize,
        task: Task,
        indices: Vec<usize>,
        first: bool,
    ) -> Result<()> {
        if rank == 0 {
            let local = self.local.as_ref().expect("started with the study");
            return local
                .jobs
                .send((study.spec.clone(), study.number, task, indices))
                .map_err(|_| anyhow!("rank 0's sample thread ended"));
        }
        let message = Message::Assign {
            study: study.number,
            spec: first.then(|| (*study.spec).clone()),
            task,
            indices,
        };
        send(world, rank as i32, &message);
        Ok(())
    }

    /// Takes in one message (a finished assignment, or a rank ready), if any, and returns
    /// the coordinator's answer to it (`None`: nothing arrived).
    fn collect(&mut self, world: &SimpleCommunicator) -> Result<Option<Vec<Action>>> {
        if let Some(done) = self.local.as_ref().and_then(|l| l.results.try_recv().ok()) {
            return Ok(Some(match done {
                Ok(curves) => self.machine.on_done(0, curves),
                Err(err) => self.machine.on_failed(0, &format!("{err:#}")),
            }));
        }
        let Some((rank, message)) = try_receive(world, None)? else {
            return Ok(None);
        };
        let rank_number = rank as usize;
        Ok(Some(match message {
            Message::Ready { lanes } => self.machine.on_ready(rank_number, lanes),
            Message::Done { curves } => self.machine.on_done(rank_number, curves),
            Message::Failed { reason } => self.machine.on_failed(rank_number, &reason),
            other => bail!("unexpected message from rank {rank}: {other:?}"),
        }))
    }
}

/// Progress of a distributed study: `(samples done over all tasks, whether the samples
/// since the last call were read back from checkpoints rather than computed)`.
pub type Progress<'a> = dyn Fn(u64, bool) + 'a;

/// Runs every task of the study in `store` over the ranks of the job (module docs) and
/// returns the results in task order. Rank 0 must be the coordinator ([`active`]).
/// Unless `quiet`, says at the end how many samples each rank computed.
pub fn run_study(store: &StudyDir, progress: &Progress, quiet: bool) -> Result<Vec<TaskResult>> {
    let mut guard = coordinator();
    let job = guard
        .as_mut()
        .ok_or_else(|| anyhow!("not the coordinator of an MPI job"))?;
    let world = SimpleCommunicator::world();
    if job.local.is_none() {
        job.local = Some(Local::start(rayon::current_num_threads().max(1))?);
    }
    let actions = job.machine.begin(store.clone())?;
    let study = Current {
        number: job.machine.study_number(),
        spec: Arc::new(store.spec().clone()),
        tasks: store.spec().tasks(),
    };
    progress(job.machine.progress().0, true);
    let mut ended = job.carry_out(&world, Some(&study), actions)?;
    let mut pause = Duration::from_micros(100);
    while !ended {
        let collected = job.collect(&world)?;
        let arrived = collected.is_some();
        let mut actions = collected.unwrap_or_default();
        actions.extend(job.machine.save_due());
        ended = job.carry_out(&world, Some(&study), actions)?;
        if arrived {
            progress(job.machine.progress().0, false);
            pause = Duration::from_micros(100);
        } else {
            std::thread::sleep(pause);
            pause = (pause * 2).min(MAX_POLL);
        }
    }
    if !quiet {
        let counts: Vec<String> = job.machine.computed().iter().map(u64::to_string).collect();
        eprintln!(
            "{} ranks computed {} samples (rank 0 first)",
            counts.len(),
            counts.join(" + ")
        );
    }
    Ok(job.machine.finish()?)
}
