"""Tangential stiffness and contact conductance of rough surfaces across H (issue 37).

For each Hurst exponent H, `SAMPLES` surfaces (seeds 1..SAMPLES; N² grid, roll-off
q0·L/2π = 4, rms slope 1, free boundaries, E* = 1) are swept over the same mean pressures
by `Solver.sweep(poisson=ν, resistivity=[1, 1])`: the normal frozen-set stiffness k, the
tangential (no-slip) k_x, k_y with Cerruti's kernel, and the electrical conductance by
Barber's analogy. Writes, beside this script:

* `samples.csv`: every sample and load (H, seed, p, F, area fraction, k, k_x, k_y,
  k_t/k_n, C);
* `tangential.csv`: per H and load, the ensemble means of the area fraction, of k_t/k_n
  and of C with 95 % intervals ±t·s/√m;
* `tangential.png`: k_t/k_n against the area fraction (Mindlin's 2(1−ν)/(2−ν) dashed), and
  C·ρ/L against F/(E*L²), log–log;
* `run.json`: the settings, the version and the wall time.

Oracles checked on every row before anything is written: C = 2k/(E*(ρ₁+ρ₂)) to 1e-15
(Barber's analogy, exact by construction: C is k times a constant), k_t/k_n at least
Mindlin's ratio (an exact bound, docs/tangential.md) and within 2 % of it, k_x, k_y > 0.

Run: `python docs/results/tangential/tangential_study.py` (about 5 min on 2 cores).
"""

import csv
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

import asperity

HERE = Path(__file__).resolve().parent
N, ROLLOFF, SLOPE, NU = 256, 4, 1.0, 0.3
HURSTS = [0.0, 0.3, 0.5, 0.8]
SAMPLES = 10
PRESSURES = list(np.geomspace(1e-3, 5e-2, 8))
MINDLIN = 2 * (1 - NU) / (2 - NU)
# Two-sided 95 % Student t for m − 1 degrees of freedom (m = SAMPLES = 10: 9).
T95 = {9: 2.262, 19: 2.093}


def run_sample(hurst, seed):
    s = asperity.surface(N, hurst=hurst, rolloff=ROLLOFF, rms_slope=SLOPE, seed=seed)
    sweep = asperity.Solver(s, size=1.0).sweep(pressures=PRESSURES, poisson=NU, resistivity=[1, 1])
    rows = []
    for i, p in enumerate(PRESSURES):
        k, kx, ky = sweep.stiffness[i], sweep.stiffness_x[i], sweep.stiffness_y[i]
        c = sweep.electrical_conductance[i]
        ratio = sweep.tangential_ratio[i]
        assert abs(c / (2 * k / 2) - 1) < 1e-15, (hurst, seed, p, c, k)
        assert kx > 0 and ky > 0 and abs(ratio / MINDLIN - 1) < 0.02, (hurst, seed, p, ratio)
        # (K_x + K_y)/2 = K_n/Mindlin exactly, so the mean ratio is at least Mindlin's
        # (operator convexity of the inverse; docs/tangential.md), to the CGs' precision.
        assert ratio >= MINDLIN * (1 - 1e-9), (hurst, seed, p, ratio)
        rows.append(dict(hurst=hurst, seed=seed, pressure=p, force=sweep.force[i],
                         area_fraction=sweep.area_fraction[i], stiffness=k, stiffness_x=kx,
                         stiffness_y=ky, tangential_ratio=ratio, electrical_conductance=c))
    return rows


def interval(values):
    v = np.asarray(values)
    m = len(v)
    half = T95[m - 1] * v.std(ddof=1) / math.sqrt(m)
    return v.mean(), half


def summarise(rows):
    out = []
    for hurst in HURSTS:
        for p in PRESSURES:
            sel = [r for r in rows if r["hurst"] == hurst and r["pressure"] == p]
            a, a_half = interval([r["area_fraction"] for r in sel])
            q, q_half = interval([r["tangential_ratio"] for r in sel])
            c, c_half = interval([r["electrical_conductance"] for r in sel])
            out.append(dict(hurst=hurst, pressure=p, force=sel[0]["force"], samples=len(sel),
                            area_fraction=a, area_fraction_half=a_half,
                            tangential_ratio=q, tangential_ratio_half=q_half,
                            electrical_conductance=c, electrical_conductance_half=c_half))
    return out


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: (repr(float(v)) if isinstance(v, (float, np.floating)) else v)
                        for k, v in r.items()})


def plot(summary, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for hurst in HURSTS:
        sel = [r for r in summary if r["hurst"] == hurst]
        a = [r["area_fraction"] for r in sel]
        left.errorbar(a, [r["tangential_ratio"] for r in sel],
                      yerr=[r["tangential_ratio_half"] for r in sel], marker="o", ms=3,
                      capsize=2, label=f"H = {hurst}")
        right.errorbar([r["force"] for r in sel], [r["electrical_conductance"] for r in sel],
                       yerr=[r["electrical_conductance_half"] for r in sel], marker="o", ms=3,
                       capsize=2, label=f"H = {hurst}")
    left.axhline(MINDLIN, color="k", ls="--", lw=1, label=f"Mindlin 2(1−ν)/(2−ν) = {MINDLIN:.4f}")
    left.set_xscale("log")
    left.set_xlabel("area fraction A/A0")
    left.set_ylabel("k_t/k_n = (k_x + k_y)/(2k)")
    left.set_title(f"tangential over normal stiffness, ν = {NU}")
    left.legend(fontsize=8)
    right.set_xscale("log")
    right.set_yscale("log")
    right.set_xlabel("F / (E* L²)")
    right.set_ylabel("C·ρ / L  (ρ₁ = ρ₂ = ρ)")
    right.set_title("electrical conductance (Barber: C = k/(E*ρ))")
    right.legend(fontsize=8)
    fig.suptitle(f"{N}² free, roll-off q0L/2π = {ROLLOFF}, rms slope {SLOPE}, "
                 f"{SAMPLES} samples per H, 95 % intervals", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    start = time.time()
    rows = []
    for hurst in HURSTS:
        for seed in range(1, SAMPLES + 1):
            rows.extend(run_sample(hurst, seed))
        print(f"H = {hurst}: {SAMPLES} samples, {time.time() - start:.0f} s", file=sys.stderr)
    summary = summarise(rows)
    write_csv(HERE / "samples.csv", rows)
    write_csv(HERE / "tangential.csv", summary)
    plot(summary, HERE / "tangential.png")
    run = dict(version=asperity.__version__, n=N, rolloff=ROLLOFF, rms_slope=SLOPE, poisson=NU,
               hursts=HURSTS, samples=SAMPLES, pressures=PRESSURES, boundary="free",
               modulus=1.0, resistivity=[1, 1], wall_seconds=round(time.time() - start, 1))
    (HERE / "run.json").write_text(json.dumps(run, indent=1) + "\n")


if __name__ == "__main__":
    main()
