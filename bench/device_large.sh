#!/usr/bin/env bash
# The issue-39 setting (H 0.8, roll-off 6, rms slope 1, p̄ = 0.05, seed 1, free) at large N on all
# cores: iterations, solve and stiffness seconds, peak RSS; the largest N is the largest grid
# that fits in 24 GiB by the measured memory per point.
set -u
B=${ASPERITY:-target/release/asperity}; OUT=${OUT:-bench/out/device}; mkdir -p "$OUT"
for n in ${SIZES:-4096 8192 11264}; do
    s="$OUT/s.npy"
    "$B" surface --n "$n" --hurst 0.8 --rolloff 6 --rms-slope 1 --seed 1 --out "$s" --force >/dev/null 2>&1
    start=$SECONDS
    timeout "${LIMIT:-200}" "$B" bem --surface "$s" --pressures 0.05 --timing --quiet --force > "$OUT/large_$n.csv" 2>"$OUT/large_$n.err"
    echo "n=$n rc=$? wall_s=$((SECONDS - start))" | tee -a "$OUT/large.txt"; cat "$OUT/large_$n.csv"
    rm -f "$s" "$s.json"
done
