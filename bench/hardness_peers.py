#!/usr/bin/env python3
"""Compare asperity's capped contact (`asperity bem --solver pk --hardness H`) with
ContactMechanics' `constrained_conjugate_gradients(..., hardness=...)` and tamaas'
`KatoSaturated` on asperity's own surfaces (docs/hardness.md).

For each boundary and mean pressure: the contact fraction (p > 0) and the plastic fraction
(p within 1e-8 H of H) of each code, the largest distance of a plastic point's pressure from
H, the largest pressure difference to asperity (in units of H), and the solve times.

Run with the peers' venv (ContactMechanics, tamaas):
  /work/venv-peers/bin/python bench/hardness_peers.py --asperity target/release/asperity \
      [--n 64] [--hardness 0.3] [--pressures 0.01,0.03,0.1] [--out results.json]
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

PLASTIC = 1e-8  # a point is plastic when its pressure is within PLASTIC * H of H


def fractions(pressure, h):
    plastic = pressure >= h * (1 - PLASTIC)
    return {
        "area_fraction": float(np.mean(pressure > 0)),
        "plastic_fraction": float(np.mean(plastic)),
        "plastic_distance_from_h": float(np.max(np.abs(pressure[plastic] - h))) if plastic.any() else 0.0,
        "mean_pressure": float(np.mean(pressure)),
    }


def run_asperity(exe, surface, boundary, pressure, h, tol, folder):
    out = os.path.join(folder, "asperity.csv")
    fields = os.path.join(folder, "fields")
    cmd = [exe, "bem", "--surface", surface, "--boundary", boundary, "--pressures", repr(pressure),
           "--solver", "pk", "--hardness", repr(h), "--tol", repr(tol), "--timing", "--no-stiffness",
           "--quiet", "--force", "--out", out, "--fields", fields]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    with open(out) as fh:
        row = next(csv.DictReader(fh))
    p = np.load(os.path.join(fields, "pressure_0.npy"))
    return p, float(row["solve_seconds"]), int(row["iterations"])


def run_contactmechanics(heights, boundary, pressure, h, tol):
    from ContactMechanics import FreeFFTElasticHalfSpace, PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients

    n_rows, n_cols = heights.shape
    cls = FreeFFTElasticHalfSpace if boundary == "free" else PeriodicFFTElasticHalfSpace
    substrate = cls(heights.shape, 1.0, physical_sizes=(n_rows / n_cols, 1.0))
    area = n_rows / n_cols
    pixel_area = area / (n_rows * n_cols)
    rms = float(np.std(heights))
    start = time.perf_counter()
    result = constrained_conjugate_gradients(
        substrate, heights, hardness=h * pixel_area, external_force=pressure * area,
        pentol=tol * rms, forcetol=1e-12 * pressure * area / (n_rows * n_cols),
        thermotol=tol, maxiter=100000)
    seconds = time.perf_counter() - start
    if not result.success:
        return None, seconds, f"no convergence: {result.message}"
    return np.asarray(result.jac) / pixel_area, seconds, int(result.nit)


def run_tamaas(heights, boundary, pressure, h, tol):
    import tamaas as tm

    tm.set_log_level(tm.LogLevel.error)
    n_rows, n_cols = heights.shape
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, n_rows / n_cols], [n_rows, n_cols])
    model.E, model.nu = 1.0, 0.0
    if boundary == "free":
        return None, 0.0, "KatoSaturated: periodic only here"
    solver = tm.KatoSaturated(model, heights, tol, h)
    solver.setMaxIterations(100000)
    start = time.perf_counter()
    solver.solve(pressure)
    seconds = time.perf_counter() - start
    return np.array(model.traction, copy=True), seconds, None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--asperity", required=True)
    parser.add_argument("--n", type=int, default=64)
    parser.add_argument("--hardness", type=float, default=0.3)
    parser.add_argument("--pressures", default="0.01,0.03,0.1")
    parser.add_argument("--boundaries", default="free,periodic")
    parser.add_argument("--tol", type=float, default=1e-10)
    parser.add_argument("--tamaas-tol", type=float, default=1e-12)
    parser.add_argument("--out")
    args = parser.parse_args()
    h = args.hardness
    records = []
    with tempfile.TemporaryDirectory() as folder:
        surface = os.path.join(folder, "s.npy")
        subprocess.run([args.asperity, "surface", "--n", str(args.n), "--hurst", "0.8", "--rolloff", "6",
                        "--rms-slope", "1", "--seed", "1", "--out", surface, "--force"], check=True,
                       capture_output=True)
        heights = np.load(surface)
        for boundary in args.boundaries.split(","):
            for pressure in map(float, args.pressures.split(",")):
                ours, seconds, iterations = run_asperity(args.asperity, surface, boundary, pressure, h,
                                                         args.tol, folder)
                record = {"n": args.n, "boundary": boundary, "mean_pressure": pressure, "hardness": h,
                          "asperity": {**fractions(ours, h), "seconds": seconds, "iterations": iterations}}
                peers = {"contactmechanics": lambda: run_contactmechanics(heights, boundary, pressure, h, args.tol),
                         "tamaas": lambda: run_tamaas(heights, boundary, pressure, h, args.tamaas_tol)}
                for name, run in peers.items():
                    try:
                        theirs, secs, note = run()
                    except Exception as err:  # a peer's failure is a result, not a crash
                        theirs, secs, note = None, 0.0, f"error: {err}"
                    if theirs is None:
                        record[name] = {"error": note}
                        continue
                    entry = {**fractions(theirs, h), "seconds": secs,
                             "max_pressure_difference_over_h": float(np.max(np.abs(theirs - ours)) / h),
                             "contact_sets_equal": bool(np.array_equal(theirs > 0, ours > 0)),
                             "plastic_sets_equal": bool(np.array_equal(theirs >= h * (1 - PLASTIC),
                                                                       ours >= h * (1 - PLASTIC)))}
                    if isinstance(note, int):
                        entry["iterations"] = note
                    record[name] = entry
                print(json.dumps(record), flush=True)
                records.append(record)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(records, fh, indent=1)


if __name__ == "__main__":
    sys.exit(main())
