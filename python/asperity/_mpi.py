"""Studies spread over the ranks of an MPI job (issue 15; docs/mpi.md, docs/python.md).

Under ``mpirun -n K python script.py`` (or ``srun``) with mpi4py installed, every rank runs
the script, and so calls :func:`asperity.study_alpha` / :func:`asperity.study_curve` with
the same arguments. This module makes those K calls one study, as the CLI's MPI build does
(crates/asperity-cli/src/distributed.rs):

* Rank 0 alone checks, locks and opens the folder, and drives the front-end layer's
  coordinator (``_asperity.StudyCoordinator``: ``asperity_app::study::distributed``, the
  state machine the CLI's MPI build drives too; this module only carries messages): it
  hands out samples not yet computed (task order, then index order; as many at once as a
  rank has threads), checkpoints every sample received soon after it arrives (out of index
  order too, in the library's ``Ledger``), and ends each task with its samples in index
  order, as the serial run does. Hence the checkpoints and results
  are the serial run's, byte for byte, for any K, and either kind of run resumes the other.
* Every rank computes samples (``_asperity.SampleComputer``: the library's ``TaskSamples``);
  rank 0 on a thread beside its coordinating loop (the computation releases the GIL).
* Every rank returns the same result. Errors: a sample that fails on a rank, or an error
  of rank 0 (e.g. the folder is locked), is raised on every rank once no sample is in
  flight; an unexpected error of rank 0 while samples are in flight aborts the job
  (``MPI_Abort``) so that no rank is left waiting.

Messages go over a duplicate of ``COMM_WORLD`` (made and freed by every call, so they
never mix with the script's own), pickled tuples whose curves are JSON text (floats
round-trip exactly). Waiting ranks poll with short sleeps instead of blocking in MPI,
whose blocking receives spin and would take a core from the ranks computing samples.

MPI is used only when the process was started by a launcher with more than one rank (or
the script imported ``mpi4py.MPI`` itself) and mpi4py can be imported; otherwise the study
runs in this process alone, as without MPI.
"""

import os
import pickle
import queue
import sys
import threading
import time
from typing import Any, Callable, Optional

from . import _asperity as _core

# Set by launchers to the number of ranks: Open MPI, MPICH / Intel MPI (PMI), Slurm's srun.
_SIZE_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_STEP_NUM_TASKS")
_MAX_POLL = 0.02
_TAG = 15


def _launched_with_ranks() -> bool:
    for name in _SIZE_VARIABLES:
        try:
            if int(os.environ.get(name, "1")) > 1:
                return True
        except ValueError:
            pass
    return False


def world() -> Any:
    """mpi4py's ``COMM_WORLD`` when this process is one rank of several, else None."""
    if "mpi4py.MPI" not in sys.modules and not _launched_with_ranks():
        return None
    try:
        from mpi4py import MPI
    except ImportError:
        return None
    comm = MPI.COMM_WORLD
    return comm if comm.Get_size() > 1 else None


def _sleeper():
    """A pause that doubles from 0.1 ms up to _MAX_POLL, reset by calling it with True."""
    pause = [1e-4]

    def sleep(reset: bool = False) -> None:
        if reset:
            pause[0] = 1e-4
            return
        time.sleep(pause[0])
        pause[0] = min(2 * pause[0], _MAX_POLL)

    return sleep


def _receive(comm, source):
    """The next message from `source` (any rank: MPI.ANY_SOURCE), polling: (rank, message)."""
    from mpi4py import MPI

    sleep = _sleeper()
    status = MPI.Status()
    while not comm.iprobe(source=source, tag=_TAG, status=status):
        sleep()
    rank = status.Get_source()
    return rank, comm.recv(source=rank, tag=_TAG)


def _portable(error: BaseException) -> BaseException:
    """`error` if it survives pickling (to be raised on the other ranks), else its text."""
    try:
        pickle.loads(pickle.dumps(error))
        return error
    except Exception:
        return RuntimeError(f"{type(error).__name__}: {error}")


def run_study(world_comm, begin: Callable[[Any], Any],
              progress: Optional[Callable[[int, int], Any]]) -> str:
    """Runs the study over the ranks of `world_comm` (module docs); rank 0 opens it with
    `begin(coordinator)` (``_asperity.StudyCoordinator.begin``: its first actions).
    Returns the results as JSON text on every rank."""
    comm = world_comm.Dup()
    try:
        if comm.Get_rank() == 0:
            return _coordinate(comm, begin, progress)
        return _serve(comm)
    finally:
        comm.Free()


def _serve(comm) -> str:
    """A rank other than 0: computes what rank 0 hands out until the study ends."""
    comm.send(("ready", _core.thread_count()), dest=0, tag=_TAG)
    computer = None
    while True:
        message = _receive(comm, 0)[1]
        if message[0] == "assign":
            _, t, indices, spec = message
            try:
                if spec is not None:
                    computer = _core.SampleComputer(spec)
                reply = ("done", computer.compute(t, indices))
            except Exception as error:  # reported to rank 0, which ends the study
                reply = ("failed", f"{type(error).__name__}: {error}")
            comm.send(reply, dest=0, tag=_TAG)
        elif message[0] == "end":
            _, records, error = message
            if error is not None:
                raise error
            return records
        else:
            raise RuntimeError(f"rank {comm.Get_rank()}: unexpected message {message[0]!r}")


class _Local:
    """Rank 0's own computing: a thread running SampleComputer.compute."""

    def __init__(self):
        self.jobs: "queue.Queue" = queue.Queue()
        self.results: "queue.Queue" = queue.Queue()

        def loop():
            computer = None
            for t, indices, spec in iter(self.jobs.get, None):
                try:
                    if spec is not None:
                        computer = _core.SampleComputer(spec)
                    self.results.put(("done", computer.compute(t, indices)))
                except BaseException as error:
                    self.results.put(("failed", f"{type(error).__name__}: {error}"))

        self.thread = threading.Thread(target=loop, name="asperity-rank0-samples", daemon=True)
        self.thread.start()

    def stop(self) -> list:
        """Ends the thread once its assignment, if any, is computed: what it left."""
        self.jobs.put(None)
        self.thread.join()
        left = []
        while not self.results.empty():
            left.append(self.results.get_nowait())
        return left


def _stop(comm, coordinator, records, error) -> None:
    """Tells every other rank that the study ended, with its records or its error (a rank
    whose `ready` has not arrived is told once it does, so that no message is left
    unmatched)."""
    from mpi4py import MPI

    actions = coordinator.stop()
    while True:
        for action in actions:
            if action[0] == "stop":
                comm.send(("end", records, error), dest=action[1], tag=_TAG)
        if coordinator.stopped():
            return
        rank, message = _receive(comm, MPI.ANY_SOURCE)
        if message[0] != "ready":
            raise RuntimeError(f"unexpected message {message[0]!r} from rank {rank}")
        actions = coordinator.on_ready(rank, int(message[1]))


def _coordinate(comm, begin, progress) -> str:
    """Rank 0: opens the study and drives the coordinator of the front-end layer
    (``asperity_app::study::distributed``, the CLI's MPI build's too): each message is an
    event, each of its actions a message."""
    coordinator = _core.StudyCoordinator(comm.Get_size(), _core.thread_count())
    try:
        actions = begin(coordinator)
    except BaseException as error:
        coordinator.close()
        _stop(comm, coordinator, None, _portable(error))
        raise
    try:
        error = _drive(comm, coordinator, actions, progress)
        records = None
        if error is None:
            try:
                records = coordinator.finish()
            except Exception as failure:
                error = failure
    finally:
        coordinator.close()
    _stop(comm, coordinator, records, None if error is None else _portable(error))
    if error is not None:
        raise error
    return records


def _drive(comm, coordinator, actions, progress) -> Optional[BaseException]:
    """Carries out the coordinator's actions and feeds it the messages until the study
    ends: None, or an error of this process's own (e.g. of the progress callback), which
    ends the study once no sample is in flight."""
    local = _Local()
    error = None
    try:
        ended = _carry_out(comm, local, actions)
        if progress is not None:
            progress(*coordinator.progress())
        sleep = _sleeper()
        while not ended:
            got = _collect(comm, coordinator, local)
            ended = _carry_out(comm, local, (got or []) + coordinator.save_due())
            try:
                if got is not None and progress is not None:
                    progress(*coordinator.progress())
            except Exception as failure:  # the samples in flight are let finish first
                error = error or failure
                ended = _carry_out(comm, local, coordinator.halt(f"{failure}")) or ended
            sleep(reset=True) if got is not None else sleep()
    except BaseException as failure:
        # Not a failure of the study's own (e.g. KeyboardInterrupt): with samples in
        # flight on other ranks the job cannot end cleanly.
        if any(rank != 0 for rank in coordinator.busy()):
            print(f"asperity: rank 0: {type(failure).__name__}: {failure}; ending every rank",
                  file=sys.stderr, flush=True)
            comm.Abort(2)
        error = failure
    finally:
        left = local.stop()
    if error is not None and 0 in coordinator.busy():
        _take_local(coordinator, left[0] if left else ("failed", f"{error}"))
    return error


def _carry_out(comm, local, actions) -> bool:
    """Sends the coordinator's assignments (rank 0's to its own thread): whether the study
    ended."""
    ended = False
    for action in actions:
        kind, rank, t, indices, spec = action
        if kind == "assign" and rank == 0:
            local.jobs.put((t, indices, spec))
        elif kind == "assign":
            comm.send(("assign", t, indices, spec), dest=rank, tag=_TAG)
        elif kind == "end":
            ended = True
    return ended


def _take_local(coordinator, message) -> list:
    if message[0] == "done":
        return coordinator.on_done(0, message[1])
    return coordinator.on_failed(0, message[1])


def _collect(comm, coordinator, local) -> Optional[list]:
    """Takes in one message (a finished assignment, or a rank ready), if any: the
    coordinator's actions, or None if nothing arrived."""
    from mpi4py import MPI

    try:
        return _take_local(coordinator, local.results.get_nowait())
    except queue.Empty:
        pass
    status = MPI.Status()
    if not comm.iprobe(source=MPI.ANY_SOURCE, tag=_TAG, status=status):
        return None
    rank = status.Get_source()
    message = comm.recv(source=rank, tag=_TAG)
    if message[0] == "ready":
        return coordinator.on_ready(rank, int(message[1]))
    if message[0] == "done":
        return coordinator.on_done(rank, message[1])
    if message[0] == "failed":
        return coordinator.on_failed(rank, message[1])
    return coordinator.halt(f"rank {rank} sent {message[0]!r} unasked")
