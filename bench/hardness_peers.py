#!/usr/bin/env python3
"""Compare asperity's capped contact (`asperity bem --hardness H`) with ContactMechanics'
`constrained_conjugate_gradients(..., hardness=...)` and tamaas' `KatoSaturated` on
asperity's own surfaces, in one run (docs/hardness.md).

For each boundary and mean pressure: the contact fraction (p > 0) and the plastic fraction
(p within 1e-8 H of H) of each code, the largest distance of a plastic point's pressure from
H, the largest pressure difference to asperity (in units of H), the solve times and
iterations, and asperity's capped ÷ elastic time at the same load (`--rounds` interleaved
cold solves of each, capped then elastic, the minimum of each; the peers once each, in a
child process stopped after `--peer-timeout` seconds). The record states the machine, its
load average before and after each solve and the commit of the binary.

Run with the peers' venv (ContactMechanics, tamaas):
  /work/venv-peers/bin/python bench/hardness_peers.py --asperity target/release/asperity \
      [--n 64] [--hardness 0.3] [--pressures 0.01,0.03,0.1] [--solver bccg|pk] \
      [--rounds 3] [--peer-timeout 1800] [--out results.json]
"""
import argparse
import csv
import json
import os
import platform
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


def load_average():
    return [round(x, 2) for x in os.getloadavg()]


def run_asperity(exe, surface, boundary, pressure, h, args, folder):
    """One cold solve (`bem --timing --no-stiffness`), capped when `h` is given: the
    pressure field (capped only), solve_seconds and iterations."""
    out = os.path.join(folder, "asperity.csv")
    fields = os.path.join(folder, "fields")
    cmd = [exe, "bem", "--surface", surface, "--boundary", boundary, "--pressures", repr(pressure),
           "--solver", args.solver, "--tol", repr(args.tol), "--timing", "--no-stiffness",
           "--quiet", "--force", "--out", out]
    if h is not None:
        cmd += ["--hardness", repr(h), "--fields", fields]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    with open(out) as fh:
        row = next(csv.DictReader(fh))
    p = np.load(os.path.join(fields, "pressure_0.npy")) if h is not None else None
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


PEERS = {"contactmechanics": run_contactmechanics, "tamaas": run_tamaas}


def peer_child(args):
    """`--peer NAME`: one peer's solve in this (child) process; the pressure to `--field`,
    the rest as one JSON line on stdout."""
    heights = np.load(args.surface)
    tol = args.tamaas_tol if args.peer == "tamaas" else args.tol
    p, seconds, note = PEERS[args.peer](heights, args.boundaries, float(args.pressures), args.hardness, tol)
    if p is not None:
        np.save(args.field, p)
    print(json.dumps({"seconds": seconds, "note": note, "solved": p is not None}))


def run_peer(name, surface, boundary, pressure, args, folder):
    """A peer in a child process, stopped after `--peer-timeout` s: (pressure or None,
    seconds, note)."""
    field = os.path.join(folder, f"{name}.npy")
    cmd = [sys.executable, __file__, "--peer", name, "--surface", surface, "--boundaries", boundary,
           "--pressures", repr(pressure), "--hardness", repr(args.hardness), "--tol", repr(args.tol),
           "--tamaas-tol", repr(args.tamaas_tol), "--field", field, "--asperity", args.asperity]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=args.peer_timeout)
    except subprocess.TimeoutExpired:
        return None, args.peer_timeout, f"did not finish within {args.peer_timeout} s"
    if done.returncode != 0:
        return None, 0.0, f"error: {done.stderr.strip().splitlines()[-1] if done.stderr else done.returncode}"
    out = json.loads(done.stdout.strip().splitlines()[-1])
    p = np.load(field) if out["solved"] else None
    return p, out["seconds"], out["note"]


def machine(exe):
    model = ""
    try:
        with open("/proc/cpuinfo") as fh:
            model = next((l.split(":", 1)[1].strip() for l in fh if l.startswith("model name")), "")
    except OSError:
        pass
    version = subprocess.run([exe, "--version"], capture_output=True, text=True).stdout.strip()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    return {"cpu": model, "cores": os.cpu_count(), "platform": platform.platform(),
            "asperity": version, "commit": commit}


def asperity_rounds(surface, boundary, pressure, args, folder):
    """`--rounds` interleaved cold solves, capped then elastic: the capped field of the last
    round and each one's minimum time and iterations, with the load averages seen."""
    capped, elastic, loads = [], [], []
    for _ in range(args.rounds):
        loads.append(load_average())
        p, seconds, iterations = run_asperity(args.asperity, surface, boundary, pressure, args.hardness,
                                              args, folder)
        capped.append((seconds, iterations))
        _, e_seconds, e_iterations = run_asperity(args.asperity, surface, boundary, pressure, None,
                                                  args, folder)
        elastic.append((e_seconds, e_iterations))
    loads.append(load_average())
    entry = {**fractions(p, args.hardness), "seconds": min(s for s, _ in capped),
             "seconds_all": [s for s, _ in capped], "iterations": capped[-1][1],
             "elastic_seconds": min(s for s, _ in elastic),
             "elastic_seconds_all": [s for s, _ in elastic], "elastic_iterations": elastic[-1][1],
             "load_average": loads}
    entry["capped_over_elastic"] = entry["seconds"] / entry["elastic_seconds"]
    return p, entry


def compare(name, theirs, ours, h, seconds, note, before):
    entry = {**fractions(theirs, h), "seconds": seconds,
             "max_pressure_difference_over_h": float(np.max(np.abs(theirs - ours)) / h),
             "contact_sets_equal": bool(np.array_equal(theirs > 0, ours > 0)),
             "plastic_sets_equal": bool(np.array_equal(theirs >= h * (1 - PLASTIC),
                                                       ours >= h * (1 - PLASTIC))),
             "load_average": [before, load_average()]}
    if isinstance(note, int):
        entry["iterations"] = note
    return entry


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--asperity", required=True)
    parser.add_argument("--n", type=int, default=64)
    parser.add_argument("--hardness", type=float, default=0.3)
    parser.add_argument("--pressures", default="0.01,0.03,0.1")
    parser.add_argument("--boundaries", default="free,periodic")
    parser.add_argument("--solver", default="bccg", choices=["bccg", "pk"])
    parser.add_argument("--tol", type=float, default=1e-10)
    parser.add_argument("--tamaas-tol", type=float, default=1e-12)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--peers", default="contactmechanics,tamaas")
    parser.add_argument("--peer-timeout", type=float, default=1800)
    parser.add_argument("--out")
    parser.add_argument("--peer", help=argparse.SUPPRESS)
    parser.add_argument("--surface", help=argparse.SUPPRESS)
    parser.add_argument("--field", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.peer:
        return peer_child(args)
    h = args.hardness
    records = []
    about = machine(args.asperity)
    with tempfile.TemporaryDirectory() as folder:
        surface = os.path.join(folder, "s.npy")
        subprocess.run([args.asperity, "surface", "--n", str(args.n), "--hurst", "0.8", "--rolloff", "6",
                        "--rms-slope", "1", "--seed", "1", "--out", surface, "--force"], check=True,
                       capture_output=True)
        for boundary in args.boundaries.split(","):
            for pressure in map(float, args.pressures.split(",")):
                ours, entry = asperity_rounds(surface, boundary, pressure, args, folder)
                record = {"n": args.n, "boundary": boundary, "mean_pressure": pressure, "hardness": h,
                          "solver": args.solver, "tol": args.tol, "machine": about,
                          "asperity": entry}
                for name in filter(None, args.peers.split(",")):
                    before = load_average()
                    theirs, secs, note = run_peer(name, surface, boundary, pressure, args, folder)
                    if theirs is None:
                        record[name] = {"error": note, "seconds": secs,
                                        "load_average": [before, load_average()]}
                        continue
                    record[name] = compare(name, theirs, ours, h, secs, note, before)
                print(json.dumps(record), flush=True)
                records.append(record)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(records, fh, indent=1)


if __name__ == "__main__":
    sys.exit(main())
