#!/usr/bin/env python3
"""Compare asperity's cohesive-law adhesion (`asperity bem --work-of-adhesion W
--adhesion-range RHO --adhesion-model exponential|maugis-dugdale --boundary periodic`) with
tamaas' `ExponentialAdhesionFunctional` or `MaugisAdhesionFunctional` (a `PolonskyKeerRey`
solver on the gap, mean gap imposed) on asperity's own periodic rough surfaces, in one run
(docs/adhesion.md, issue 38). --model picks the law (the same w and range in both codes:
exponential sigma_m = w/rho, Maugis-Dugdale sigma_0 = w/h0).

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
Each size's record is written to --out as soon as that size is done (the file is rewritten
with all sizes so far), so a long run loses nothing when it is stopped.

Run with the peers' venv (tamaas):
  /work/venv-peers/bin/python bench/adhesion_peers.py --asperity target/release/asperity \
      [--sizes 64,128,256] [--model exponential] [--w 1e-6] [--rho 5e-4] [--out results.json]
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


def run_asperity(args, surface, out, indentations=None):
    cmd = [args.asperity, "bem", "--surface", surface, "--boundary", "periodic",
           "--work-of-adhesion", str(args.w), "--adhesion-range", str(args.rho),
           "--adhesion-model", args.model, "--indentations", indentations or args.indentations,
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
    functional = {"exponential": tm.ExponentialAdhesionFunctional,
                  "maugis-dugdale": tm.MaugisAdhesionFunctional}[args.model]
    adhesion = functional(h)
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
    tensile = float(np.mean(np.asarray(model.traction) < 0.0))
    return float(np.mean(model.traction)), area, tensile


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
        f_t, a_t, t_t = tamaas_point(model, solver, top, d)
        table.append({"branch": r["branch"], "indentation": d, "mean_gap": top - d,
                      "force_asperity": float(r["force"]), "force_tamaas": f_t,
                      "area_asperity": float(r["area_fraction"]), "area_tamaas": a_t,
                      "tensile_asperity": float(r["tensile_fraction"]), "tensile_tamaas": t_t,
                      "rounds": int(r["rounds"]), "cg_iterations": int(r["cg_iterations"])})
    cpu_t = time.process_time() - t0
    scale = max(abs(r["force_asperity"]) for r in table)
    for r in table:
        r["force_difference"] = abs(r["force_asperity"] - r["force_tamaas"]) / scale
    pull = record["adhesion"]["pull_off"]["displacement_controlled"]
    d_po = pull["indentation"]
    sweep_d = np.linspace(0.0, 2.0 * d_po, 41)
    sweep = [tamaas_point(model, solver, top, d)[0] for d in sweep_d]
    at_po = tamaas_point(model, solver, top, d_po)[0]
    # asperity along the same history (its rows, then the sweep) for the least force on the sweep
    path = ",".join(repr(float(r["indentation"])) for r in rows)
    path += "," + ",".join(repr(float(d)) for d in sweep_d[1:])
    swept, _, _ = run_asperity(args, surface, os.path.join(tmp, f"b{n}.csv"), path)
    sweep_a = [float(r["force"]) for r in swept[len(rows):len(rows) + len(sweep_d) - 1]]
    return {"n": n, "load_average_before": load, "load_average_after": os.getloadavg()[0],
            "rms_height": float(h.std()), "zone_resolution": record["adhesion"]["zone_resolution"],
            "max_force_difference": max(r["force_difference"] for r in table),
            "max_area_difference": max(abs(r["area_asperity"] - r["area_tamaas"]) for r in table),
            "max_tensile_difference": max(abs(r["tensile_asperity"] - r["tensile_tamaas"])
                                          for r in table),
            "pixel_area": 1.0 / n**2,
            "pull_off": {"asperity_force": pull["force"], "indentation": d_po,
                         "tamaas_force_at_same_d": at_po, "tamaas_least_force_sweep": min(sweep),
                         "asperity_least_force_sweep": min(sweep_a),
                         "max_force_difference_sweep": max(
                             abs(a - t) for a, t in zip(sweep_a, sweep[1:])) / scale},
            "cpu_seconds": {"asperity": cpu_a, "tamaas": cpu_t, "ratio_tamaas_over_asperity":
                            cpu_t / cpu_a if cpu_a > 0 else None},
            "solves": len(table), "rows": table}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--asperity", required=True)
    p.add_argument("--sizes", default="64,128,256")
    p.add_argument("--model", choices=["exponential", "maugis-dugdale"], default="exponential")
    p.add_argument("--w", type=float, default=1e-6, help="work of adhesion (E* x length, L = 1)")
    p.add_argument("--rho", type=float, default=5e-4, help="range of the exponential law")
    p.add_argument("--rms-slope", type=float, default=0.1)
    p.add_argument("--indentations", default="0,0.001,0.002,0.003")
    p.add_argument("--retract-step", type=float, default=2e-4)
    p.add_argument("--tol", type=float, default=1e-10)
    p.add_argument("--out")
    args = p.parse_args()
    version = subprocess.run([args.asperity, "--version"], capture_output=True, text=True).stdout
    result = {"machine": platform.node(), "cpus": os.cpu_count(), "asperity": version.strip(),
              "tamaas": tm.__version__, "threads": 1, "model": args.model, "w": args.w,
              "rho": args.rho, "rms_slope": args.rms_slope, "tolerance_both": args.tol,
              "indentations": args.indentations, "retract_step": args.retract_step, "runs": []}
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.sizes.split(","):
            r = compare(args, int(n), tmp)
            result["runs"].append(r)
            print(f"n={r['n']}: max |dF|/max|F| = {r['max_force_difference']:.2e}, "
                  f"max |dA/A0| = {r['max_area_difference']:.2e}, pull-off asperity "
                  f"{r['pull_off']['asperity_force']:.5e} tamaas "
                  f"{r['pull_off']['tamaas_force_at_same_d']:.5e} (sweep min "
                  f"{r['pull_off']['tamaas_least_force_sweep']:.5e}); CPU s asperity "
                  f"{r['cpu_seconds']['asperity']:.2f} tamaas {r['cpu_seconds']['tamaas']:.2f}; "
                  f"load {r['load_average_before']:.1f}", flush=True)
            write(args.out, result)
    if not args.out:
        print(json.dumps(result, indent=1))


def write(path, result):
    """Rewrite the record with the sizes done so far (atomically: a stopped run keeps them)."""
    if not path:
        return
    tmp_out = path + ".tmp"
    with open(tmp_out, "w") as f:
        f.write(json.dumps(result, indent=1) + "\n")
    os.replace(tmp_out, path)


if __name__ == "__main__":
    main()
