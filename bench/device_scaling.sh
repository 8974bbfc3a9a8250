#!/usr/bin/env bash
# Thread scaling of one BCCG solve and memory per grid point (issue 39, item 4).
#
# Run on a machine with many cores (the project's lent 16-core machine):
#   ASPERITY=path/to/asperity OUT=some/folder bench/device_scaling.sh
# Writes OUT/machine.txt, OUT/scaling.txt (bench bem-solve lines, one per
# N × threads × boundary) and OUT/memory.txt (peak RSS of `asperity bem` at large N).
# bench/device_scaling.py turns them into bench/results/device_scaling.json.
set -u
B=${ASPERITY:-target/release/asperity}
OUT=${OUT:-bench/out/device}
mkdir -p "$OUT"
{ date -u; nproc; lscpu | grep -E "Model name|Socket|Core|Thread|NUMA node\(s\)|L3"; free -g; } \
    > "$OUT/machine.txt" 2>&1
"$B" --version >> "$OUT/machine.txt" 2>&1

# One cold solve per (N, threads, boundary), p̄ = 0.05 E*, H 0.8, roll-off 6, rms slope 1.
for n in ${SIZES:-1024 2048}; do
    repeat=2; [ "$n" -ge 2048 ] && repeat=1
    for t in ${THREADS:-1 2 4 8 16}; do
        RAYON_NUM_THREADS=$t "$B" bench bem-solve --n "$n" --repeat "$repeat" \
            --pressures 0.05 --solvers bccg --boundaries free,periodic 2>/dev/null \
            | grep '^kernel=' | tee -a "$OUT/scaling.txt"
    done
done

# Peak resident memory of a user's solve (surface generation + solve + frozen-set stiffness)
# at large N on all cores; the peak is sampled from /proc while it runs (a cut run still
# reports the allocation peak reached so far).
peak_rss() { # n seconds
    local n=$1 limit=$2 s="$OUT/surface_$1.npy"
    "$B" surface --n "$n" --hurst 0.8 --rolloff 6 --seed 1 --out "$s" >/dev/null 2>&1
    local start=$SECONDS
    "$B" bem --surface "$s" --pressures 0.05 --timing --quiet > "$OUT/bem_$n.csv" 2>"$OUT/bem_$n.err" &
    local pid=$! peak=0 v
    while kill -0 "$pid" 2>/dev/null; do
        v=$(awk '/VmHWM/ {print $2}' "/proc/$pid/status" 2>/dev/null || echo 0)
        [ -n "$v" ] && [ "$v" -gt "$peak" ] && peak=$v
        if [ $((SECONDS - start)) -ge "$limit" ]; then kill "$pid"; echo "n=$n cut_after_s=$limit" >> "$OUT/memory.txt"; fi
        sleep 0.5
    done
    wait "$pid"; echo "n=$n rc=$? wall_s=$((SECONDS - start)) peak_rss_kib=$peak" | tee -a "$OUT/memory.txt"
    rm -f "$s"
}
for m in ${MEMORY:-4096:100 8192:100}; do peak_rss "${m%%:*}" "${m##*:}"; done
