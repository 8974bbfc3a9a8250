#!/usr/bin/env python3
"""Compare `asperity bem` with tamaas and ContactMechanics on the same rough surfaces.

For every grid size N the script generates one surface with `asperity surface`
(H = 0.8, roll-off q0·L/2π = 6, rms slope 1, seed 1, L = 1, E* = 1), then solves it at the
same mean pressures with every code and boundary condition, each solve cold (a new
solver) in its own process so that peak memory (VmHWM) is per solve:

  asperity      `asperity bem --pressures p --timing` (solve time from the CSV, excludes
                reading the surface and planning, like the peers' timings)
  tamaas        PolonskyKeerRey (periodic: default operator; free: the non-periodic
                Boussinesq operator registered by ModelFactory.registerNonPeriodic)
  ContactMech.  constrained_conjugate_gradients on PeriodicFFTElasticHalfSpace /
                FreeFFTElasticHalfSpace

Indentation of the peers is computed the same way as asperity's: apply the code's own
elastic operator to its pressure and average u + f over the contact set (f = max h − h).

results.json holds {"environment": ..., "results": [...]}: the environment records the
peers' installed versions, the asperity git commit (and whether the tree was dirty), the
date, `nproc` and the load average, so that a table can be traced to what produced it.

Usage: bench/bem_peers.py --asperity target/release/asperity --out bench/out
"""

import argparse
import csv
import datetime
import json
import os
import platform
import re
import subprocess
import sys
import time


def vm_hwm_mib():
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return float(line.split()[1]) / 1024.0
    return float("nan")


def indentation_from(u, f, contact):
    """d = mean of u + f on the contact set, with u's sign convention detected."""
    import numpy as np

    plus, minus = u[contact] + f[contact], -u[contact] + f[contact]
    return float(np.mean(plus)) if np.std(plus) <= np.std(minus) else float(np.mean(minus))


def worker(args):
    """One cold solve with a peer; prints one JSON line."""
    import numpy as np

    heights = np.load(args.surface)
    n_rows, n_cols = heights.shape
    size = 1.0
    f = heights.max() - heights
    baseline = vm_hwm_mib()
    if args.code == "tamaas":
        import tamaas as tm

        tm.set_log_level(tm.LogLevel.info)
        model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [size, size * n_rows / n_cols], [n_rows, n_cols])
        model.E, model.nu = 1.0, 0.0
        solver = tm.PolonskyKeerRey(model, heights, args.tol)
        solver.setMaxIterations(100000)
        if args.boundary == "free":
            tm.ModelFactory.registerNonPeriodic(model, "dcfft")
            solver.setIntegralOperator("dcfft")
        sys.stdout.flush()
        start = time.perf_counter()
        solver.solve(args.pressure)
        seconds = time.perf_counter() - start
        peak = vm_hwm_mib()
        pressure = np.array(model.traction, copy=True)
        u = np.zeros_like(pressure)
        if args.boundary == "free":
            model.operators["dcfft"](model.traction, u)
        else:
            model.solveNeumann()
            u = np.array(model.displacement, copy=True)
        iterations = None  # parsed from tamaas' log by the parent
    else:
        from ContactMechanics import FreeFFTElasticHalfSpace, PeriodicFFTElasticHalfSpace
        from ContactMechanics.Optimization import constrained_conjugate_gradients

        cls = FreeFFTElasticHalfSpace if args.boundary == "free" else PeriodicFFTElasticHalfSpace
        substrate = cls((n_rows, n_cols), 1.0, physical_sizes=(size * n_rows / n_cols, size))
        area = size * size * n_rows / n_cols
        rms = float(np.std(heights))
        start = time.perf_counter()
        result = constrained_conjugate_gradients(
            substrate, heights, external_force=args.pressure * area,
            pentol=args.tol * rms, forcetol=1e-12 * args.pressure * area / (n_rows * n_cols),
            thermotol=args.tol, maxiter=100000)
        seconds = time.perf_counter() - start
        peak = vm_hwm_mib()
        if not result.success:
            print(json.dumps({"error": str(result.message)}))
            return
        pixel_area = area / (n_rows * n_cols)
        pressure = np.asarray(result.jac) / pixel_area
        u = substrate.evaluate_disp(np.asarray(result.jac) if args.boundary == "periodic" else
                                    np.asarray(result.jac))
        u = np.asarray(u)[:n_rows, :n_cols]
        iterations = int(result.nit)
    contact = pressure > 0
    if args.boundary == "periodic":
        # Periodic displacements are defined up to a constant; use asperity's (zero mean).
        u = u - np.mean(u)
    print(json.dumps({
        "seconds": seconds,
        "iterations": iterations,
        "area_fraction": float(np.mean(contact)),
        "mean_pressure": float(np.mean(pressure)),
        "indentation": indentation_from(u, f, contact),
        "peak_rss_mib": peak,
        "baseline_rss_mib": baseline,
    }))


def run_asperity(exe, surface, boundary, pressure, tol, out_dir, threads=None):
    out = os.path.join(out_dir, "asperity_tmp.csv")
    env = dict(os.environ)
    if threads:
        env["RAYON_NUM_THREADS"] = str(threads)
    cmd = [exe, "bem", "--surface", surface, "--boundary", boundary, "--pressures", repr(pressure),
           "--tol", repr(tol), "--timing", "--no-stiffness", "--quiet", "--force", "--out", out]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        return {"error": proc.stderr.strip()}
    with open(out) as fh:
        row = next(csv.DictReader(fh))
    return {
        "seconds": float(row["solve_seconds"]),
        "iterations": int(row["iterations"]),
        "area_fraction": float(row["area_fraction"]),
        "mean_pressure": float(row["mean_pressure"]),
        "indentation": float(row["indentation"]),
        "peak_rss_mib": float(row["peak_rss_mib"]),
    }


def run_peer(code, surface, boundary, pressure, tol, timeout):
    cmd = [sys.executable, os.path.abspath(__file__), "worker", "--code", code, "--surface", surface,
           "--boundary", boundary, "--pressure", repr(pressure), "--tol", repr(tol)]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout} s"}
    lines = [l for l in proc.stdout.splitlines() if l.startswith("{")]
    if proc.returncode != 0 or not lines:
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
        return {"error": " | ".join(tail)}
    result = json.loads(lines[-1])
    if code == "tamaas":
        its = [int(m.group(1)) for m in re.finditer(r"^\s*(\d+)\s+\S+\s+\S+\s*$", proc.stdout + proc.stderr, re.M)]
        result["iterations"] = its[-1] if its else None
    return result


def command_output(cmd):
    """stdout of `cmd`, stripped; None when it cannot run or fails."""
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError):
        return None
    return proc.stdout.strip() if proc.returncode == 0 else None


def environment(asperity_exe):
    """What produced the results: versions, commit, date, cores."""
    from importlib import metadata

    def version(package):
        try:
            return metadata.version(package)
        except metadata.PackageNotFoundError:
            return None

    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    dirty = command_output(["git", "-C", repo, "status", "--porcelain", "--untracked-files=no"])
    nproc = command_output(["nproc"])
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "asperity_commit": command_output(["git", "-C", repo, "rev-parse", "HEAD"]),
        "asperity_tree_dirty": None if dirty is None else bool(dirty),
        "asperity_version": command_output([asperity_exe, "--version"]),
        "peers": {package: version(package) for package in ("tamaas", "ContactMechanics", "numpy")},
        "python": platform.python_version(),
        "nproc": int(nproc) if nproc and nproc.isdigit() else os.cpu_count(),
        "loadavg": list(os.getloadavg()),
        "platform": platform.platform(),
    }


def padded_minimum_mib(n, boundary):
    """Memory a padded-FFT Polonsky-Keer solve cannot do without: one half spectrum of the
    (padded) grid, the unique values of the real even kernel spectrum and four N² fields
    (profile, pressure, gap, direction)."""
    pad = 2 if boundary == "free" else 1
    rows, cols = pad * n, pad * n
    spectrum = (cols // 2 + 1) * rows * 16
    kernel = (cols // 2 + 1) * (rows // 2 + 1) * 8
    fields = 4 * n * n * 8
    return (spectrum + kernel + fields) / 2**20


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command")
    w = sub.add_parser("worker")
    w.add_argument("--code", required=True)
    w.add_argument("--surface", required=True)
    w.add_argument("--boundary", required=True)
    w.add_argument("--pressure", type=float, required=True)
    w.add_argument("--tol", type=float, required=True)
    parser.add_argument("--asperity", default="target/release/asperity")
    parser.add_argument("--out", default="bench/out")
    parser.add_argument("--sizes", default="256,512,1024")
    parser.add_argument("--pressures", default="0.01,0.05")
    parser.add_argument("--boundaries", default="free,periodic")
    parser.add_argument("--peers", default="tamaas,contactmechanics")
    parser.add_argument("--tol", type=float, default=1e-8, help="asperity's tolerance")
    parser.add_argument("--tamaas-tol", type=float, default=None,
                        help="tamaas' tolerance (its error measure differs; default: same value)")
    parser.add_argument("--timeout", type=float, default=1800)
    args = parser.parse_args()
    if args.command == "worker":
        worker(args)
        return
    os.makedirs(args.out, exist_ok=True)
    env = environment(args.asperity)
    print(json.dumps({"environment": env}), flush=True)
    results = []
    # asperity's fixed memory (binary, allocator): peak RSS of a 16² solve.
    tiny = os.path.join(args.out, "surface_16.npy")
    subprocess.run([args.asperity, "surface", "--n", "16", "--hurst", "0.8", "--rms-slope", "1",
                    "--out", tiny, "--force"], check=True, capture_output=True)
    baseline = run_asperity(args.asperity, tiny, "free", 0.01, args.tol, args.out)["peak_rss_mib"]
    for n in [int(s) for s in args.sizes.split(",")]:
        surface = os.path.join(args.out, f"surface_{n}.npy")
        subprocess.run([args.asperity, "surface", "--n", str(n), "--hurst", "0.8", "--rolloff", "6",
                        "--rms-slope", "1", "--seed", "1", "--out", surface, "--force"], check=True,
                       capture_output=True)
        for boundary in args.boundaries.split(","):
            for pressure in [float(p) for p in args.pressures.split(",")]:
                codes = ["asperity", "asperity-1thread"] + [p for p in args.peers.split(",") if p]
                for code in codes:
                    if code == "asperity":
                        r = run_asperity(args.asperity, surface, boundary, pressure, args.tol, args.out)
                        r["baseline_rss_mib"] = baseline
                    elif code == "asperity-1thread":
                        r = run_asperity(args.asperity, surface, boundary, pressure, args.tol, args.out, threads=1)
                        r["baseline_rss_mib"] = baseline
                    else:
                        tol = args.tamaas_tol if (code == "tamaas" and args.tamaas_tol) else args.tol
                        r = run_peer(code, surface, boundary, pressure, tol, args.timeout)
                    r.update({"n": n, "boundary": boundary, "pressure": pressure, "code": code,
                              "padded_minimum_mib": padded_minimum_mib(n, boundary)})
                    results.append(r)
                    print(json.dumps(r), flush=True)
    env["loadavg_end"] = list(os.getloadavg())
    with open(os.path.join(args.out, "results.json"), "w") as fh:
        json.dump({"environment": env, "results": results}, fh, indent=1)
    print_table(results)


def print_table(results):
    print("\n| N | boundary | p̄ | code | time/solve (s) | iterations | peak RSS (MiB) | RSS − start-up (MiB) | ÷ padded minimum | area fraction | indentation | Δarea rel. | Δd rel. | time ÷ asperity |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    ref = {}
    for r in results:
        key = (r["n"], r["boundary"], r["pressure"])
        if r["code"] == "asperity" and "error" not in r:
            ref[key] = r
    for r in results:
        key = (r["n"], r["boundary"], r["pressure"])
        if "error" in r:
            print(f"| {r['n']} | {r['boundary']} | {r['pressure']} | {r['code']} | error: {r['error']} |||||||||")
            continue
        a = ref.get(key)
        d_area = d_ind = speed = ""
        if a and r["code"] != "asperity":
            d_area = f"{abs(r['area_fraction'] / a['area_fraction'] - 1):.1e}"
            d_ind = f"{abs(r['indentation'] / a['indentation'] - 1):.1e}"
            speed = f"{r['seconds'] / a['seconds']:.1f}×"
        net = r["peak_rss_mib"] - r.get("baseline_rss_mib", 0.0)
        print(f"| {r['n']} | {r['boundary']} | {r['pressure']} | {r['code']} | {r['seconds']:.3f} | "
              f"{r['iterations']} | {r['peak_rss_mib']:.0f} | {net:.0f} | {net / r['padded_minimum_mib']:.2f} | "
              f"{r['area_fraction']:.5f} | {r['indentation']:.6e} | "
              f"{d_area} | {d_ind} | {speed} |")


if __name__ == "__main__":
    main()
