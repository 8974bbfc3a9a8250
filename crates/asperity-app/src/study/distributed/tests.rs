//! The coordinator's state machine against the serial run: every order of events, a
//! failed rank, resuming from checkpoints, stopping.

use std::collections::HashMap;
use std::path::Path;
use std::time::Duration;

use asperity::study::{run_any_task, Method, SampleCurve, StudyDir, StudySpec, TaskSamples};

use super::{Action, Coordinator, DistributedError};

/// Two tasks of three samples: small enough to try every order of events.
fn spec() -> StudySpec {
    StudySpec {
        method: Method::Mdr,
        sizes: vec![64],
        hursts: vec![0.4, 0.9],
        samples: 3,
        seed: 11,
        levels: 12,
        ..StudySpec::default()
    }
}

/// Every sample's curve, by (task number, index), computed once.
fn curves(spec: &StudySpec) -> HashMap<(usize, usize), SampleCurve> {
    let mut all = HashMap::new();
    for (t, &task) in spec.tasks().iter().enumerate() {
        let indices: Vec<usize> = (0..spec.samples).collect();
        let computed = TaskSamples::new(spec, task)
            .unwrap()
            .compute(&indices)
            .unwrap();
        for (i, curve) in computed.into_iter().enumerate() {
            all.insert((t, i), curve);
        }
    }
    all
}

/// Every file of a study folder but its lock, by name.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut folders = vec![dir.to_path_buf()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
            } else {
                let name = path.strip_prefix(dir).unwrap().display().to_string();
                out.push((name, std::fs::read(&path).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// An error and its sources, as the CLI prints them (`{:#}` of anyhow).
fn chain(error: &dyn std::error::Error) -> String {
    let mut words = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        words += &format!(": {cause}");
        source = cause.source();
    }
    words
}

/// The folder of the serial run of `spec`.
fn serial(spec: &StudySpec) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let store = StudyDir::open(dir.path(), spec, false).unwrap();
    for task in spec.tasks() {
        run_any_task(spec, task, &store, &|_, _| {}).unwrap();
    }
    dir
}

/// A job in progress as the front ends drive it: the assignments in flight per rank.
struct Sim<'a> {
    job: Coordinator,
    curves: &'a HashMap<(usize, usize), SampleCurve>,
    busy: HashMap<usize, (usize, Vec<usize>)>,
    ready: Vec<bool>,
    /// Every sample assigned, in order.
    assigned: Vec<(usize, usize)>,
    ended: bool,
}

impl Sim<'_> {
    fn carry_out(&mut self, actions: Vec<Action>) {
        for action in actions {
            match action {
                Action::Assign {
                    rank,
                    task,
                    indices,
                    ..
                } => {
                    assert!(!self.ended, "an assignment after the end");
                    self.assigned.extend(indices.iter().map(|&i| (task, i)));
                    assert!(self.busy.insert(rank, (task, indices)).is_none());
                }
                Action::End => {
                    assert!(!self.ended, "two ends");
                    self.ended = true;
                }
                Action::Stop { .. } => panic!("a stop during the study"),
            }
        }
    }

    /// The events that may come next: `ready` of a rank that did not send it, `done` of a
    /// busy rank.
    fn events(&self) -> Vec<(bool, usize)> {
        let mut events: Vec<(bool, usize)> = (1..self.ready.len())
            .filter(|&r| !self.ready[r])
            .map(|r| (true, r))
            .collect();
        let mut busy: Vec<usize> = self.busy.keys().copied().collect();
        busy.sort();
        events.extend(busy.into_iter().map(|r| (false, r)));
        events
    }

    fn deliver(&mut self, (ready, rank): (bool, usize), lanes: &[usize]) {
        let actions = if ready {
            self.ready[rank] = true;
            self.job.on_ready(rank, lanes[rank])
        } else {
            let (t, indices) = self.busy.remove(&rank).unwrap();
            let done = indices.iter().map(|&i| self.curves[&(t, i)].clone());
            self.job.on_done(rank, done.collect())
        };
        self.carry_out(actions);
        let saved = self.job.save_due();
        self.carry_out(saved);
    }
}

/// Runs the study in `dir` on ranks of `lanes` (rank 0 first), choosing the next event
/// with `choose(number of possible events)`; returns the samples assigned.
fn run(
    spec: &StudySpec,
    dir: &Path,
    lanes: &[usize],
    curves: &HashMap<(usize, usize), SampleCurve>,
    choose: &mut dyn FnMut(usize) -> usize,
) -> Vec<(usize, usize)> {
    let store = StudyDir::open(dir, spec, false).unwrap();
    let mut sim = Sim {
        job: Coordinator::new(lanes.len(), lanes[0]),
        curves,
        busy: HashMap::new(),
        ready: vec![false; lanes.len()],
        assigned: Vec::new(),
        ended: false,
    };
    let begun = sim.job.begin(store).unwrap();
    sim.carry_out(begun);
    while !sim.ended {
        let events = sim.events();
        assert!(!events.is_empty(), "stuck before the end");
        let pick = choose(events.len());
        sim.deliver(events[pick], lanes);
    }
    sim.job.finish().unwrap();
    let stops = sim.job.stop().unwrap();
    assert_eq!(
        stops.len(),
        sim.ready.iter().skip(1).filter(|&&r| r).count()
    );
    sim.assigned
}

/// Runs the study on ranks of `lanes` in every order in which the ranks' `ready` and
/// `done` may arrive (each interleaving, tried by enumerating the choices at each step):
/// each ends with the serial run's files, byte for byte, every sample assigned exactly
/// once. Returns the number of orders.
fn every_order(lanes: &[usize]) -> usize {
    let spec = spec();
    let reference = files(serial(&spec).path());
    let curves = curves(&spec);
    // The choices of the last run, each as (taken, possible); the next run takes the
    // next choice at the last step that has one left.
    let mut path: Vec<(usize, usize)> = Vec::new();
    let mut orders = 0;
    loop {
        let dir = tempfile::tempdir().unwrap();
        let mut step = 0;
        let mut choose = |possible: usize| {
            if step == path.len() {
                path.push((0, possible));
            }
            assert_eq!(path[step].1, possible, "the same prefix, the same choices");
            step += 1;
            path[step - 1].0
        };
        let mut assigned = run(&spec, dir.path(), lanes, &curves, &mut choose);
        orders += 1;
        assert_eq!(files(dir.path()), reference, "order {path:?}");
        assigned.sort();
        let every: Vec<_> = (0..2).flat_map(|t| (0..3).map(move |i| (t, i))).collect();
        assert_eq!(assigned, every, "order {path:?}");
        while path
            .last()
            .is_some_and(|&(taken, possible)| taken + 1 == possible)
        {
            path.pop();
        }
        let Some(last) = path.last_mut() else { break };
        last.0 += 1;
    }
    orders
}

/// Every order of events on two ranks, one of them with two lanes.
#[test]
fn every_order_of_events_on_two_ranks_ends_as_the_serial_run() {
    let orders = every_order(&[1, 2]);
    assert!(orders >= 10, "only {orders} orders");
}

/// Every order of events on three ranks (713 orders, about 45 s on 2 loaded cores).
#[test]
#[ignore = "slow tier: cargo test --release -- --ignored (.ci/run runs it)"]
fn every_order_of_events_on_three_ranks_ends_as_the_serial_run() {
    let orders = every_order(&[1, 2, 1]);
    assert!(orders >= 700, "only {orders} orders");
}

/// The first assignments go to rank 0 (ready from the start), every later one to the
/// rank that asks, with its spec the first time it meets a study (and again in the next
/// study, where the ranks ready in the last one are given work at once).
#[test]
fn a_rank_gets_the_spec_with_its_first_assignment_of_each_study() {
    let spec = spec();
    let curves = curves(&spec);
    let mut job = Coordinator::new(2, 4);
    for number in 1..=2 {
        let dir = tempfile::tempdir().unwrap();
        let store = StudyDir::open(dir.path(), &spec, false).unwrap();
        let first = Action::Assign {
            rank: 0,
            task: 0,
            indices: vec![0, 1, 2],
            spec: true,
        };
        let second = Action::Assign {
            rank: 1,
            task: 1,
            indices: vec![0],
            spec: true,
        };
        if number == 1 {
            assert_eq!(job.begin(store).unwrap(), [first]);
            assert_eq!(job.on_ready(1, 1), [second]);
        } else {
            // Rank 1 is ready from the last study; it meets this one now.
            assert_eq!(job.begin(store).unwrap(), [first, second]);
        }
        assert_eq!(job.study_number(), number);
        let third = Action::Assign {
            rank: 1,
            task: 1,
            indices: vec![1],
            spec: false,
        };
        assert_eq!(job.on_done(1, vec![curves[&(1, 0)].clone()]), [third]);
        let done: Vec<_> = (0..3).map(|i| curves[&(0, i)].clone()).collect();
        let fourth = Action::Assign {
            rank: 0,
            task: 1,
            indices: vec![2],
            spec: false,
        };
        assert_eq!(job.on_done(0, done), [fourth]);
        assert_eq!(job.on_done(0, vec![curves[&(1, 2)].clone()]), []);
        assert_eq!(job.progress(), (5, 6));
        assert_eq!(job.on_done(1, vec![curves[&(1, 1)].clone()]), [Action::End]);
        assert_eq!(job.computed(), [4, 2]);
        assert_eq!(job.finish().unwrap().len(), 2);
    }
}

/// A rank whose assignment fails stops the handing out; the samples in flight are awaited
/// and checkpointed, the study ends naming the rank, and the same study resumed computes
/// only what is missing and ends as the serial run.
#[test]
fn a_failed_rank_ends_the_study_and_a_rerun_resumes_it() {
    let spec = spec();
    let reference = files(serial(&spec).path());
    let curves = curves(&spec);
    let dir = tempfile::tempdir().unwrap();
    let store = StudyDir::open(dir.path(), &spec, false)
        .unwrap()
        .with_checkpoint_interval(Duration::ZERO);
    let mut job = Coordinator::new(3, 1);
    assert_eq!(job.begin(store).unwrap().len(), 1); // rank 0: (0, [0])
    assert_eq!(job.on_ready(1, 1).len(), 1); // rank 1: (0, [1])
    assert_eq!(job.on_ready(2, 1).len(), 1); // rank 2: (0, [2])
    assert_eq!(job.on_failed(1, "solver diverged"), []);
    assert_eq!(job.halt("a later failure is not the one reported"), []);
    assert_eq!(job.busy(), [0, 2]);
    assert!(matches!(job.stop(), Err(DistributedError::InFlight)));
    assert_eq!(job.on_done(2, vec![curves[&(0, 2)].clone()]), []);
    assert_eq!(job.on_done(0, vec![curves[&(0, 0)].clone()]), [Action::End]);
    assert_eq!(job.save_due(), []);
    let failure = job.finish().unwrap_err();
    assert_eq!(failure.to_string(), "rank 1: solver diverged");
    assert_eq!(job.stop().unwrap().len(), 2);
    // The rerun: samples 0 and 2 of task 0 were checkpointed; only the rest is computed.
    let store = StudyDir::open(dir.path(), &spec, false).unwrap();
    let mut job = Coordinator::new(1, 8);
    let mut actions = job.begin(store).unwrap();
    assert_eq!(job.progress(), (2, 6));
    let mut computed = Vec::new();
    while let Some(Action::Assign { task, indices, .. }) = actions.first().cloned() {
        computed.extend(indices.iter().map(|&i| (task, i)));
        let done = indices
            .iter()
            .map(|&i| curves[&(task, i)].clone())
            .collect();
        actions = job.on_done(0, done);
    }
    assert_eq!(actions, [Action::End]);
    assert_eq!(computed, [(0, 1), (1, 0), (1, 1), (1, 2)]);
    job.finish().unwrap();
    assert_eq!(files(dir.path()), reference);
    // A finished study resumed ends at once, computing nothing.
    let store = StudyDir::open(dir.path(), &spec, false).unwrap();
    let mut job = Coordinator::new(2, 1);
    assert_eq!(job.begin(store).unwrap(), [Action::End]);
    assert_eq!(job.finish().unwrap().len(), 2);
}

/// Samples nobody asked for, a rank the job lacks, and curves the ledger refuses end the
/// study with their failure, once no sample is in flight.
#[test]
fn protocol_errors_end_the_study_with_their_words() {
    let spec = spec();
    let curves = curves(&spec);
    type Event<'a> = &'a dyn Fn(&mut Coordinator) -> Vec<Action>;
    let cases: [(Event, &str); 3] = [
        (
            &|job| job.on_done(1, vec![curves[&(0, 0)].clone()]),
            "rank 1 sent samples it was not asked for",
        ),
        (
            &|job| job.on_ready(5, 1),
            "rank 5 is not a rank of this job of 2",
        ),
        (
            &|job| job.on_done(0, Vec::new()),
            "mdr N = 64 H = 0.4: invalid samples: 0 curves for 3 samples",
        ),
    ];
    for (event, words) in cases {
        let dir = tempfile::tempdir().unwrap();
        let store = StudyDir::open(dir.path(), &spec, false).unwrap();
        let mut job = Coordinator::new(2, 3);
        assert_eq!(job.begin(store).unwrap().len(), 1);
        let actions = event(&mut job);
        if job.in_flight() {
            assert_eq!(actions, []);
            let done: Vec<_> = (0..3).map(|i| curves[&(0, i)].clone()).collect();
            assert_eq!(job.on_done(0, done), [Action::End]);
        } else {
            assert_eq!(actions, [Action::End]);
        }
        let failure = job.finish().unwrap_err();
        assert_eq!(chain(&failure), words);
        assert!(matches!(
            job.finish(),
            Err(DistributedError::Sequence("the study has not ended"))
        ));
    }
}

/// Stopping tells the ready ranks at once and the others when their `ready` arrives; a
/// study cannot begin after.
#[test]
fn stop_waits_for_the_ranks_not_yet_ready() {
    let mut job = Coordinator::new(4, 1);
    assert_eq!(job.on_ready(2, 3), []);
    assert_eq!(job.stop().unwrap(), [Action::Stop { rank: 2 }]);
    assert!(!job.stopped());
    assert_eq!(job.on_ready(3, 1), [Action::Stop { rank: 3 }]);
    assert_eq!(job.on_ready(1, 1), [Action::Stop { rank: 1 }]);
    assert!(job.stopped());
    let dir = tempfile::tempdir().unwrap();
    let store = StudyDir::open(dir.path(), &spec(), false).unwrap();
    assert!(matches!(
        job.begin(store),
        Err(DistributedError::Sequence(_))
    ));
}
