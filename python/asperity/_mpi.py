"""Studies spread over the ranks of an MPI job (issue 15; docs/mpi.md, docs/python.md).

Under ``mpirun -n K python script.py`` (or ``srun``) with mpi4py installed, every rank runs
the script, and so calls :func:`asperity.study_alpha` / :func:`asperity.study_curve` with
the same arguments. This module makes those K calls one study, as the CLI's MPI build does
(crates/asperity-cli/src/distributed.rs):

* Rank 0 alone checks, locks and opens the folder, and keeps the study in the library's
  ``Ledger`` (``_asperity.StudyLedger``): it hands out samples not yet computed (task
  order, then index order; as many at once as a rank has threads), checkpoints every
  sample received soon after it arrives (out of index order too), and ends each task with
  its samples in index order, as the serial run does. Hence the checkpoints and results
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


def run_study(world_comm, open_ledger: Callable[[], Any],
              progress: Optional[Callable[[int, int], Any]]) -> str:
    """Runs the study over the ranks of `world_comm` (module docs); rank 0 opens it with
    `open_ledger()`. Returns the results as JSON text on every rank."""
    comm = world_comm.Dup()
    try:
        if comm.Get_rank() == 0:
            return _coordinate(comm, open_ledger, progress)
        return _serve(comm)
    finally:
        comm.Free()


def _serve(comm) -> str:
    """A rank other than 0: computes what rank 0 hands out until the study ends."""
    comm.send(("ready", _core.thread_count()), dest=0, tag=_TAG)
    computer = None
    while True:
        message = _receive(comm, 0)[1]
        if message[0] == "spec":
            computer = _core.SampleComputer(message[1])
        elif message[0] == "assign":
            _, t, indices = message
            try:
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

    def __init__(self, spec_json: str):
        self.jobs: "queue.Queue" = queue.Queue()
        self.results: "queue.Queue" = queue.Queue()
        self.busy = None
        computer = _core.SampleComputer(spec_json)

        def loop():
            for t, indices in iter(self.jobs.get, None):
                try:
                    self.results.put(("done", computer.compute(t, indices)))
                except BaseException as error:
                    self.results.put(("failed", f"{type(error).__name__}: {error}"))

        self.thread = threading.Thread(target=loop, name="asperity-rank0-samples", daemon=True)
        self.thread.start()

    def stop(self) -> None:
        self.jobs.put(None)
        self.thread.join()


def _end(comm, ready, records, error) -> None:
    """Tells every other rank that the study ended (after its `ready`, so that no message
    is left unmatched)."""
    for rank in range(1, comm.Get_size()):
        if rank not in ready:
            got, message = _receive(comm, rank)
            if message[0] != "ready":
                raise RuntimeError(f"unexpected message {message[0]!r} from rank {got}")
        comm.send(("end", records, error), dest=rank, tag=_TAG)


def _coordinate(comm, open_ledger, progress) -> str:
    """Rank 0: opens the study, hands out its samples, takes in and checkpoints theirs."""
    try:
        ledger = open_ledger()
    except BaseException as error:
        _end(comm, {}, None, _portable(error))
        raise
    try:
        return _coordinate_open(comm, ledger, progress)
    finally:
        ledger.close()


def _coordinate_open(comm, ledger, progress) -> str:
    spec = ledger.spec_json()
    for rank in range(1, comm.Get_size()):
        comm.send(("spec", spec), dest=rank, tag=_TAG)
    local = _Local(spec)
    ready = {}  # rank -> threads
    busy = {}  # rank -> (task, indices); rank 0 is the local thread
    error = None
    try:
        if progress is not None:
            progress(*ledger.progress())
        sleep = _sleeper()
        while busy or (error is None and not ledger.finished()):
            if error is None:
                _assign(comm, ledger, local, ready, busy)
            try:
                got = _collect(comm, ledger, local, ready, busy)
                ledger.save_due()
                if got and progress is not None:
                    progress(*ledger.progress())
            except Exception as failure:  # the samples in flight are let finish first
                if error is None:
                    error = failure
                got = True
            sleep(reset=True) if got else sleep()
    except BaseException as failure:
        # Not a failure of the study's own (e.g. KeyboardInterrupt): with samples in
        # flight on other ranks the job cannot end cleanly.
        if any(rank != 0 for rank in busy):
            print(f"asperity: rank 0: {type(failure).__name__}: {failure}; ending every rank",
                  file=sys.stderr, flush=True)
            comm.Abort(2)
        error = failure
    finally:
        local.stop()
    if error is not None:
        _end(comm, ready, None, _portable(error))
        raise error
    records = ledger.results()
    _end(comm, ready, records, None)
    return records


def _assign(comm, ledger, local, ready, busy) -> None:
    """Gives work to every idle rank (rank 0's thread included) while there is work."""
    if 0 not in busy:
        work = ledger.next_work(_core.thread_count())
        if work is not None:
            local.jobs.put(work)
            busy[0] = work
    for rank, lanes in ready.items():
        if rank in busy:
            continue
        work = ledger.next_work(lanes)
        if work is None:
            return
        comm.send(("assign", work[0], work[1]), dest=rank, tag=_TAG)
        busy[rank] = work


def _collect(comm, ledger, local, ready, busy) -> bool:
    """Takes in one message (a finished assignment, or a rank ready), if any: whether one
    was. A failed assignment raises, naming its rank."""
    from mpi4py import MPI

    if 0 in busy:
        try:
            rank, message = 0, local.results.get_nowait()
        except queue.Empty:
            rank, message = None, None
    if 0 not in busy or rank is None:
        status = MPI.Status()
        if not comm.iprobe(source=MPI.ANY_SOURCE, tag=_TAG, status=status):
            return False
        rank = status.Get_source()
        message = comm.recv(source=rank, tag=_TAG)
    if message[0] == "ready":
        ready[rank] = max(1, int(message[1]))
        return True
    if rank not in busy:
        raise RuntimeError(f"rank {rank} sent {message[0]!r} unasked")
    t, indices = busy.pop(rank)
    if message[0] == "failed":
        raise RuntimeError(f"rank {rank}: {message[1]}")
    ledger.receive(t, indices, message[1])
    return True
