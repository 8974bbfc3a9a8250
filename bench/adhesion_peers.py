#!/usr/bin/env python3
"""Compare asperity's exponential-potential adhesion (`asperity bem --work-of-adhesion W
--adhesion-range RHO --adhesion-model exponential --boundary periodic`) with tamaas'
`ExponentialAdhesionFunctional` (a `PolonskyKeerRey` solver on the gap, mean gap imposed)
on asperity's own periodic rough surfaces, in one run (docs/adhesion.md, issue 38).

Both codes walk the same loading-unloading path in displacement control: asperity's
`--indentations` then its retraction rows (step --retract-step), tamaas at the same mean
gaps, warm from its previous state. asperity's periodic indentation d is relative to the
mean elastic displacement, so the mean gap is max(h) - mean(h) - d, the quantity tamaas
imposes. Reported per row: both forces (mean pressures, E* units), the relative difference
(to the largest |F| of the path), both contact fractions (asperity's attached pixels,
tamaas' pixels with zero gap); then the pull-off (asperity's bisected displacement-control
pull-off against tamaas' force at the same d and the least force of a fine tamaas sweep
around it), and the CPU time of each code for the whole path (getrusage of the asperity
child; process_time of tamaas, both with one thread). The record states the load average.

Run with the peers' venv (tamaas):
  /work/venv-peers/bin/python bench/adhesion_peers.py --asperity target/release/asperity \
      [--sizes 64,128,256] [--w 1e-6] [--rho 5e-4] [--out results.json]
"""
import argparse
import csv
import json
import os
import platform
import resource
import subprocess
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("RAYON_NUM_THREADS", "1")
import numpy as np  # noqa: E402
import tamaas as tm  # noqa: E402

tm.set_log_level(tm.LogLevel.error)


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_asperity(args, surface, out):
    cmd = [args.asperity, "bem", "--surface", surface, "--boundary", "periodic",
           "--work-of-adhesion", str(args.w), "--adhesion-range", str(args.rho),
           "--adhesion-model", "exponential", "--indentations", args.indentations,
           "--retract-step", str(args.retract_step), "--tol", str(args.tol), "--out", out]
    before = child_cpu()
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    cpu = child_cpu() - before
    with open(out) as f:
        rows = list(csv.DictReader(f))
    with open(out + ".json") as f:
        record = json.load(f)
    return rows, record, cpu


def tamaas_solver(h, args):
    n = h.shape[0]
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [n, n])
    model.E, model.nu = 1.0, 0.0
    solver = tm.PolonskyKeerRey(model, h, args.tol, tm.PolonskyKeerRey.gap,
                                tm.PolonskyKeerRey.gap)
    adhesion = tm.ExponentialAdhesionFunctional(h)
    adhesion.parameters = {"rho": args.rho, "surface_energy": args.w}
    solver.addFunctionalTerm(adhesion)
    return model, solver, adhesion  # the solver does not own the functional: keep it alive


ZERO_GAP = 1e-8


def h_of(solver):
    return np.asarray(solver.surface)


def tamaas_point(model, solver, top, d):
    solver.solve(top - d)
    # tamaas' gap: u - h shifted to the imposed mean; contact where it vanishes (to ZERO_GAP rms h)
    u = np.asarray(model.displacement).reshape(h_of(solver).shape)
    g = u - h_of(solver)
    g += (top - d) - g.mean()
    area = float(np.mean(g <= ZERO_GAP * np.std(h_of(solver))))
    return float(np.mean(model.traction)), area


def compare(args, n, tmp):
    surface = os.path.join(tmp, f"s{n}.npy")
    subprocess.run([args.asperity, "surface", "--n", str(n), "--hurst", "0.8", "--rolloff", "4",
                    "--rms-slope", str(args.rms_slope), "--seed", "1", "--out", surface],
                   check=True, capture_output=True)
    h = np.load(surface)
    top = float(h.max() - h.mean())
    load = os.getloadavg()[0]
    rows, record, cpu_a = run_asperity(args, surface, os.path.join(tmp, f"a{n}.csv"))
    model, solver, _adhesion = tamaas_solver(h, args)
    t0, table = time.process_time(), []
    for r in rows:
        d = float(r["indentation"])
        f_t, a_t = tamaas_point(model, solver, top, d)
        table.append({"branch": r["branch"], "indentation": d, "mean_gap": top - d,
                      "force_asperity": float(r["force"]), "force_tamaas": f_t,
                      "area_asperity": float(r["area_fraction"]), "area_tamaas": a_t,
                      "rounds": int(r["rounds"]), "cg_iterations": int(r["cg_iterations"])})
    cpu_t = time.process_time() - t0
    scale = max(abs(r["force_asperity"]) for r in table)
    for r in table:
        r["force_difference"] = abs(r["force_asperity"] - r["force_tamaas"]) / scale
    pull = record["adhesion"]["pull_off"]["displacement_controlled"]
    d_po = pull["indentation"]
    sweep = [tamaas_point(model, solver, top, d)[0]
             for d in np.linspace(0.0, 2.0 * d_po, 41)]
    at_po = tamaas_point(model, solver, top, d_po)[0]
    return {"n": n, "load_average_before": load, "load_average_after": os.getloadavg()[0],
            "rms_height": float(h.std()), "zone_resolution": record["adhesion"]["zone_resolution"],
            "max_force_difference": max(r["force_difference"] for r in table),
            "max_area_difference": max(abs(r["area_asperity"] - r["area_tamaas"]) for r in table),
            "pull_off": {"asperity_force": pull["force"], "indentation": d_po,
                         "tamaas_force_at_same_d": at_po, "tamaas_least_force_sweep": min(sweep)},
            "cpu_seconds": {"asperity": cpu_a, "tamaas": cpu_t, "ratio_tamaas_over_asperity":
                            cpu_t / cpu_a if cpu_a > 0 else None},
            "solves": len(table), "rows": table}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--asperity", required=True)
    p.add_argument("--sizes", default="64,128,256")
    p.add_argument("--w", type=float, default=1e-6, help="work of adhesion (E* x length, L = 1)")
    p.add_argument("--rho", type=float, default=5e-4, help="range of the exponential law")
    p.add_argument("--rms-slope", type=float, default=0.1)
    p.add_argument("--indentations", default="0,0.001,0.002,0.003")
    p.add_argument("--retract-step", type=float, default=2e-4)
    p.add_argument("--tol", type=float, default=1e-10)
    p.add_argument("--out")
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        runs = [compare(args, int(n), tmp) for n in args.sizes.split(",")]
    version = subprocess.run([args.asperity, "--version"], capture_output=True, text=True).stdout
    result = {"machine": platform.node(), "cpus": os.cpu_count(), "asperity": version.strip(),
              "tamaas": tm.__version__, "threads": 1, "w": args.w, "rho": args.rho,
              "rms_slope": args.rms_slope, "tolerance_both": args.tol, "runs": runs}
    for r in runs:
        print(f"n={r['n']}: max |dF|/max|F| = {r['max_force_difference']:.2e}, "
              f"max |dA/A0| = {r['max_area_difference']:.2e}, pull-off asperity "
              f"{r['pull_off']['asperity_force']:.5e} tamaas {r['pull_off']['tamaas_force_at_same_d']:.5e}"
              f" (sweep min {r['pull_off']['tamaas_least_force_sweep']:.5e}); CPU s asperity "
              f"{r['cpu_seconds']['asperity']:.2f} tamaas {r['cpu_seconds']['tamaas']:.2f}; "
              f"load {r['load_average_before']:.1f}")
    text = json.dumps(result, indent=1)
    if args.out:
        tmp_out = args.out + ".tmp"
        with open(tmp_out, "w") as f:
            f.write(text + "\n")
        os.replace(tmp_out, args.out)
    else:
        print(text)


if __name__ == "__main__":
    main()
