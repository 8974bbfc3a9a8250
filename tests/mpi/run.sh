#!/usr/bin/env bash
# MPI test of issue 15 (docs/mpi.md): builds asperity with and without the `mpi` feature
# and checks, on small BEM and MDR studies, that
#   1. `mpirun -n K` for K = 1, 2, 3 writes the same files, byte for byte, as the default
#      build (CSV, plots, checkpoints, study.json), for `study alpha`, `study curve` and
#      `study file`;
#   2. a rank killed mid-study ends the job with a message naming it, loses only its sample
#      in flight (every sample the others computed is checkpointed, also beyond the lost
#      one in index order), and the same command run again computes just that sample and
#      ends with the uninterrupted run's files; an MPI run resumes a killed serial run;
#   3. the folder lock holds across runs: a serial run and a second MPI job on a folder an
#      MPI job is using are refused;
#   4. the Python package's studies under `mpirun python` with mpi4py: the same checkpoints
#      as the CLI's and the same result on every rank for 1, 2, 3 ranks, a killed rank and
#      the lock (needs python/.venv with the package: python/ci.sh makes it; mpi4py's
#      binary wheel is added to it).
# Needs an MPI implementation with mpirun (Debian: libopenmpi-dev openmpi-bin) and libclang
# (libclang-dev) for the build; without mpirun it fails at once, saying what to install.
# Usage: tests/mpi/run.sh [--no-build] [--no-python]
#   ASPERITY_BIN=PATH: the serial binary to compare with (else built here); --no-build takes
#   both binaries from ASPERITY_SERIAL and ASPERITY_MPI.
set -euo pipefail
cd "$(dirname "$0")/../.."
if ! command -v mpirun >/dev/null 2>&1; then
    echo "tests/mpi/run.sh: no mpirun: install an MPI implementation and libclang (Debian/Ubuntu: sudo apt-get install libopenmpi-dev openmpi-bin libclang-dev; .ci/run does it)" >&2
    exit 1
fi
root=$(pwd)
work=$(mktemp -d)
job=""
# A job left running by a failed check (rank 1 frozen) is ended with the test.
cleanup() {
    if [ -n "$job" ] && kill -0 "$job" 2>/dev/null; then
        pkill -KILL -P "$job" 2>/dev/null || true
        kill -KILL "$job" 2>/dev/null || true
    fi
    rm -rf "$work"
}
trap cleanup EXIT
# Open MPI refuses root without these; --oversubscribe lets 3 ranks share 2 cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpirun_cmd=(mpirun --oversubscribe)
if mpirun --version 2>&1 | grep -qi "hydra\|mpich"; then
    mpirun_cmd=(mpirun) # MPICH oversubscribes by itself
fi

build=1
python_tests=1
for arg in "$@"; do
    case "$arg" in
    --no-build) build=0 ;;
    --no-python) python_tests=0 ;;
    *) echo "usage: tests/mpi/run.sh [--no-build] [--no-python]" >&2 && exit 2 ;;
    esac
done
if [ "$build" = 1 ]; then
    # The serial binary: ASPERITY_BIN where given (.ci/run passes the one its tests built:
    # the same code, and no second build of the workspace with other dependency features).
    if [ -n "${ASPERITY_BIN:-}" ] && [ -x "$ASPERITY_BIN" ]; then
        cp "$ASPERITY_BIN" "$work/serial"
    else
        cargo build --release -p asperity-cli --quiet
        cp target/release/asperity "$work/serial"
    fi
    cargo build --release -p asperity-cli --features mpi --quiet
    cp target/release/asperity "$work/mpi"
else
    cp "${ASPERITY_SERIAL:?}" "$work/serial"
    cp "${ASPERITY_MPI:?}" "$work/mpi"
fi
serial="$work/serial"
mpi="$work/mpi"

fail() {
    echo "FAIL: $*" >&2
    exit 1
}

# Every file of two study folders but the lock (which holds its holder's PID).
same_files() {
    diff -r -x .asperity.lock "$1" "$2" >/dev/null || {
        diff -r -x .asperity.lock "$1" "$2" | head -20 >&2
        fail "$3: $1 and $2 differ"
    }
}

cat >"$work/study.toml" <<'EOF'
kind = "curve"
method = "mdr"
n = 1024
hurst = [0.3, 1.5]
samples = 40
seed = 5
EOF

# 1. The same files for K = 1, 2, 3 ranks.
bem_loud=(study alpha --method bem --n 32,48 --hurst 0.5,0.8 --samples 7 --seed 3)
bem=("${bem_loud[@]}" --quiet)
curve=(study curve --method bem --n 32 --hurst 0.2,1.0 --samples 5 --rolloff 4 --quiet)
tangential=("${curve[@]}" --poisson 0.3 --resistivity 1,1)
file=(study file "$work/study.toml" --quiet)
"$serial" "${bem[@]}" --out "$work/bem-serial"
"$serial" "${curve[@]}" --out "$work/curve-serial"
"$serial" "${tangential[@]}" --out "$work/tangential-serial"
"$serial" "${file[@]}" --out "$work/file-serial"
for k in 1 2 3; do
    "${mpirun_cmd[@]}" -n $k "$mpi" "${bem[@]}" --out "$work/bem-$k"
    same_files "$work/bem-serial" "$work/bem-$k" "study alpha on $k ranks"
    "${mpirun_cmd[@]}" -n $k "$mpi" "${curve[@]}" --out "$work/curve-$k"
    same_files "$work/curve-serial" "$work/curve-$k" "study curve on $k ranks"
    "${mpirun_cmd[@]}" -n $k "$mpi" "${tangential[@]}" --out "$work/tangential-$k"
    same_files "$work/tangential-serial" "$work/tangential-$k" "study curve --poisson on $k ranks"
    "${mpirun_cmd[@]}" -n $k "$mpi" "${file[@]}" --out "$work/file-$k"
    same_files "$work/file-serial" "$work/file-$k" "study file on $k ranks"
done
# The mpi build alone (no mpirun) is the serial run too.
"$mpi" "${bem[@]}" --out "$work/bem-alone"
same_files "$work/bem-serial" "$work/bem-alone" "the mpi build without mpirun"
# Work was spread: every rank computed samples.
"${mpirun_cmd[@]}" -n 3 "$mpi" "${bem_loud[@]}" --out "$work/bem-loud" 2>"$work/loud.txt"
grep -Eq "3 ranks computed [1-9][0-9]* \+ [1-9][0-9]* \+ [1-9][0-9]* samples" "$work/loud.txt" ||
    fail "not every rank computed samples: $(tail -1 "$work/loud.txt")"
echo "ok: identical outputs on 1, 2, 3 ranks (study alpha, curve, file)"

# 2. Kill a rank, then resume. One thread per rank, so that a rank computes one sample at
# a time; the default checkpoint interval (10 s): rank 0 checkpoints what it receives
# promptly all the same.
export RAYON_NUM_THREADS=1
long_loud=(study alpha --method bem --n 96 --hurst 0.5,0.9 --samples 16 --seed 8)
long=("${long_loud[@]}" --quiet)
total=32
"$serial" "${long[@]}" --out "$work/long-serial"

# Samples in the checkpoints of a folder: those of tasks in progress (in index order or
# not) and those of finished tasks.
saved() {
    python3 - "$1" <<'PY'
import json, pathlib, sys
count = 0
for path in pathlib.Path(sys.argv[1], "checkpoint").glob("*.json"):
    try:
        content = json.loads(path.read_text())["content"]
    except (OSError, ValueError, KeyError):
        continue  # being replaced
    if content["state"] == "done":
        count += content["result"]["samples"]
    else:
        count += len(content["samples"]) + len(content.get("later", []))
print(count)
PY
}

# The PID of rank $2 among the children of mpirun $1.
rank_pid() {
    local child
    for child in $(ps -o pid= --ppid "$1"); do
        if tr '\0' '\n' <"/proc/$child/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$2\|PMI_RANK=$2"; then
            echo "$child"
            return
        fi
    done
}

# Waits (up to two minutes) until the folder's checkpoints hold at least $2 samples.
wait_saved() {
    for _ in $(seq 600); do
        [ "$(saved "$1")" -ge "$2" ] && return 0
        sleep 0.2
    done
    fail "no checkpoint with $2 samples in $1 (it holds $(saved "$1"))"
}

# Rank 1 is frozen (SIGSTOP) holding its sample while ranks 0 and 2 compute all the others;
# once rank 0 has checkpointed those (all but one of the study's samples, some of them
# beyond the frozen one in index order), rank 1 is killed. Nothing but its sample is lost.
kill_rank_1() { # $1: mpirun's PID, $2: the folder; prints the samples kept
    local victim=""
    wait_saved "$2" 2
    for _ in $(seq 100); do
        victim=$(rank_pid "$1" 1)
        [ -n "$victim" ] && break
        sleep 0.1
    done
    [ -n "$victim" ] || fail "rank 1 of the job not found"
    kill -STOP "$victim"
    wait_saved "$2" $((total - 1))
    echo "$victim"
}

"${mpirun_cmd[@]}" -n 3 "$mpi" "${long[@]}" --out "$work/long-killed" 2>"$work/killed.txt" &
job=$!
victim=$(kill_rank_1 "$job" "$work/long-killed")
# 3. While the job runs, its folder is locked against a serial run and a second job.
if "$serial" "${long[@]}" --out "$work/long-killed" 2>"$work/lock1.txt"; then
    fail "a serial run was let into a folder an MPI job holds"
fi
grep -q "in use by another asperity process (PID" "$work/lock1.txt" || fail "lock: $(cat "$work/lock1.txt")"
if "${mpirun_cmd[@]}" -n 2 "$mpi" "${long[@]}" --out "$work/long-killed" 2>"$work/lock2.txt"; then
    fail "a second MPI job was let into a folder an MPI job holds"
fi
grep -q "in use by another asperity process (PID" "$work/lock2.txt" || fail "lock: $(cat "$work/lock2.txt")"
echo "ok: the folder lock refuses a serial run and a second MPI job"
kill -9 "$victim"
if wait "$job"; then
    fail "the job went on after rank 1 was killed"
fi
grep -qi "rank 1" "$work/killed.txt" || fail "the failure does not name rank 1: $(cat "$work/killed.txt")"
kept=$(saved "$work/long-killed")
[ "$kept" -eq $((total - 1)) ] || fail "$kept of $total samples checkpointed after rank 1 was killed holding 1"
[ -e "$work/long-killed/alpha.csv" ] && fail "a killed job wrote its outputs"
"${mpirun_cmd[@]}" -n 2 "$mpi" "${long_loud[@]}" --out "$work/long-killed" 2>"$work/resumed.txt"
grep -Eq "2 ranks computed (1 \+ 0|0 \+ 1) samples" "$work/resumed.txt" ||
    fail "the resumed run did not compute exactly the lost sample: $(grep 'ranks computed' "$work/resumed.txt")"
same_files "$work/long-serial" "$work/long-killed" "resumed after a killed rank"
echo "ok: rank 1 killed holding 1 sample: $kept of $total kept, the job failed naming it, the rerun computed 1 and ended byte-identical"

# A killed serial run resumed by an MPI job.
"$serial" "${long[@]}" --checkpoint-every 0 --out "$work/long-serial-killed" &
job=$!
wait_saved "$work/long-serial-killed" 3
kill -9 "$job"
wait "$job" || true
kept=$(saved "$work/long-serial-killed")
"${mpirun_cmd[@]}" -n 3 "$mpi" "${long[@]}" --out "$work/long-serial-killed"
same_files "$work/long-serial" "$work/long-serial-killed" "an MPI job resuming a serial run"
echo "ok: an MPI job resumed a killed serial run ($kept samples kept)"
# 4. The Python package under `mpirun python` with mpi4py: the same checkpoints as the CLI's
# serial run for K = 1, 2, 3, the same result on every rank, a killed rank, the lock.
if [ "$python_tests" = 1 ]; then
    py="$root/python/.venv/bin/python"
    if ! "$py" -c "import asperity._mpi" 2>/dev/null; then
        fail "the Python part needs the package installed in python/.venv: run python/ci.sh first (or pass --no-python)"
    fi
    # mpi4py's binary wheel loads the system's MPI library (seconds; no compiler needed).
    "$py" -c "import mpi4py" 2>/dev/null || "$py" -m pip install --quiet "mpi4py>=4.1"
    study_py=("$py" "$root/tests/mpi/study.py")
    same_checkpoints() {
        cmp -s "$1/study.json" "$2/study.json" || fail "$3: study.json differs"
        same_files "$1/checkpoint" "$2/checkpoint" "$3"
    }
    unset RAYON_NUM_THREADS
    "${study_py[@]}" alpha "$work/py-serial" "$work/py-serial.json"
    same_checkpoints "$work/bem-serial" "$work/py-serial" "Python against the CLI"
    for k in 1 2 3; do
        "${mpirun_cmd[@]}" -n $k "${study_py[@]}" alpha "$work/py-$k" "$work/py-$k.json"
        same_checkpoints "$work/bem-serial" "$work/py-$k" "Python on $k ranks"
        for ((rank = 0; rank < k; rank++)); do
            cmp -s "$work/py-serial.json.0" "$work/py-$k.json.$rank" ||
                fail "Python on $k ranks: rank $rank returned another result than the serial run"
        done
    done
    # Issue 37: Poisson's ratio and the resistivities reach the ranks (they were refused).
    "${study_py[@]}" tangential "$work/py-tangential-serial" "$work/py-tangential-serial.json"
    same_checkpoints "$work/tangential-serial" "$work/py-tangential-serial" "Python --poisson against the CLI"
    for k in 2 3; do
        "${mpirun_cmd[@]}" -n $k "${study_py[@]}" tangential "$work/py-tangential-$k" "$work/py-tangential-$k.json"
        same_checkpoints "$work/tangential-serial" "$work/py-tangential-$k" "Python --poisson on $k ranks"
        for ((rank = 0; rank < k; rank++)); do
            cmp -s "$work/py-tangential-serial.json.0" "$work/py-tangential-$k.json.$rank" ||
                fail "Python --poisson on $k ranks: rank $rank returned another result than the serial run"
        done
    done
    echo "ok: Python under mpirun: identical checkpoints and results on 1, 2, 3 ranks (also with poisson)"
    export RAYON_NUM_THREADS=1
    "${mpirun_cmd[@]}" -n 3 "${study_py[@]}" long "$work/py-long" >/dev/null 2>"$work/py-killed.txt" &
    job=$!
    victim=$(kill_rank_1 "$job" "$work/py-long")
    if "$serial" "${long[@]}" --out "$work/py-long" 2>"$work/lock3.txt"; then
        fail "a CLI run was let into a folder a Python MPI job holds"
    fi
    grep -q "in use by another asperity process (PID" "$work/lock3.txt" || fail "lock: $(cat "$work/lock3.txt")"
    kill -9 "$victim"
    if wait "$job"; then
        fail "the Python job went on after rank 1 was killed"
    fi
    grep -qi "rank 1" "$work/py-killed.txt" || fail "the failure does not name rank 1: $(cat "$work/py-killed.txt")"
    kept=$(saved "$work/py-long")
    [ "$kept" -eq $((total - 1)) ] || fail "Python: $kept of $total samples checkpointed after rank 1 was killed holding 1"
    "${mpirun_cmd[@]}" -n 2 "${study_py[@]}" long "$work/py-long" >/dev/null
    same_checkpoints "$work/long-serial" "$work/py-long" "Python resumed after a killed rank"
    echo "ok: Python: rank 1 killed holding 1 sample, $kept of $total kept, the lock held, the rerun ended byte-identical"
fi
echo "MPI tests passed"
cd "$root"
