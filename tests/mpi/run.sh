#!/usr/bin/env bash
# MPI test of issue 15 (docs/mpi.md): builds asperity with and without the `mpi` feature
# and checks, on small BEM and MDR studies, that
#   1. `mpirun -n K` for K = 1, 2, 3 writes the same files, byte for byte, as the default
#      build (CSV, plots, checkpoints, study.json), for `study alpha`, `study curve` and
#      `study file`;
#   2. a rank killed mid-study ends the job with a message naming it, and the same command
#      run again resumes from the checkpoints (an MPI run resumes a killed serial run and
#      the other way round) and ends with the same files;
#   3. the folder lock holds across runs: a serial run and a second MPI job on a folder an
#      MPI job is using are refused.
# Needs an MPI implementation with mpirun (Debian: libopenmpi-dev openmpi-bin) and libclang
# (libclang-dev) for the build. Usage: tests/mpi/run.sh [--no-build]
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Open MPI refuses root without these; --oversubscribe lets 3 ranks share 2 cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpirun_cmd=(mpirun --oversubscribe)
if mpirun --version 2>&1 | grep -qi "hydra\|mpich"; then
    mpirun_cmd=(mpirun) # MPICH oversubscribes by itself
fi

if [ "${1:-}" != "--no-build" ]; then
    cargo build --release -p asperity-cli --quiet
    cp target/release/asperity "$work/serial"
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
file=(study file "$work/study.toml" --quiet)
"$serial" "${bem[@]}" --out "$work/bem-serial"
"$serial" "${curve[@]}" --out "$work/curve-serial"
"$serial" "${file[@]}" --out "$work/file-serial"
for k in 1 2 3; do
    "${mpirun_cmd[@]}" -n $k "$mpi" "${bem[@]}" --out "$work/bem-$k"
    same_files "$work/bem-serial" "$work/bem-$k" "study alpha on $k ranks"
    "${mpirun_cmd[@]}" -n $k "$mpi" "${curve[@]}" --out "$work/curve-$k"
    same_files "$work/curve-serial" "$work/curve-$k" "study curve on $k ranks"
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

# 2. Kill a rank, then resume. A longer study, checkpointing after every sample.
long=(study alpha --method bem --n 96 --hurst 0.5,0.9 --samples 32 --seed 8 --quiet --checkpoint-every 0)
"$serial" "${long[@]}" --out "$work/long-serial"

# Samples in the checkpoints of a folder (each sample has one points_total).
saved() { cat "$1"/checkpoint/*.json 2>/dev/null | grep -o '"points_total"' | wc -l; }

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

# Waits (up to a minute) until the folder's checkpoints hold at least $2 samples.
wait_saved() {
    for _ in $(seq 600); do
        [ "$(saved "$1")" -ge "$2" ] && return 0
        sleep 0.1
    done
    fail "no checkpoint with $2 samples in $1"
}

"${mpirun_cmd[@]}" -n 3 "$mpi" "${long[@]}" --out "$work/long-killed" 2>"$work/killed.txt" &
job=$!
wait_saved "$work/long-killed" 4
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
victim=$(rank_pid "$job" 1)
[ -n "$victim" ] || fail "rank 1 of the job not found"
kill -9 "$victim"
if wait "$job"; then
    fail "the job went on after rank 1 was killed"
fi
grep -qi "rank 1" "$work/killed.txt" || fail "the failure does not name rank 1: $(cat "$work/killed.txt")"
kept=$(saved "$work/long-killed")
[ "$kept" -ge 4 ] || fail "only $kept samples checkpointed before the kill"
[ -e "$work/long-killed/alpha.csv" ] && fail "a killed job wrote its outputs"
"${mpirun_cmd[@]}" -n 2 "$mpi" "${long[@]}" --out "$work/long-killed"
same_files "$work/long-serial" "$work/long-killed" "resumed after a killed rank"
echo "ok: rank 1 killed ($kept samples kept), the job failed naming it, the rerun resumed"

# A killed serial run resumed by an MPI job.
"$serial" "${long[@]}" --out "$work/long-serial-killed" &
job=$!
wait_saved "$work/long-serial-killed" 3
kill -9 "$job"
wait "$job" || true
kept=$(saved "$work/long-serial-killed")
"${mpirun_cmd[@]}" -n 3 "$mpi" "${long[@]}" --out "$work/long-serial-killed"
same_files "$work/long-serial" "$work/long-serial-killed" "an MPI job resuming a serial run"
echo "ok: an MPI job resumed a killed serial run ($kept samples kept)"
echo "MPI tests passed"
cd "$root"
