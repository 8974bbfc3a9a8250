#!/usr/bin/env python3
"""Compare `asperity bem` with tamaas and ContactMechanics on the same rough surfaces.

For every grid size N the script generates one surface with `asperity surface`
(H = 0.8, roll-off q0·L/2π = 6, rms slope 1, seed 1, L = 1, E* = 1), then solves it at the
same mean pressures with every code and boundary condition, each solve cold (a new
solver) in its own process so that peak memory (VmHWM) is per solve:

  asperity      `asperity bem --solver S --pressures p --timing` for every solver S of
                --solvers and every thread count of --threads (RAYON_NUM_THREADS); solve
                time from the CSV, excludes reading the surface and planning, like the
                peers' timings. A binary without `--solver` runs "pk" without the flag and
                skips the other solvers.
  tamaas        PolonskyKeerRey (periodic: default operator; free: the non-periodic
                Boussinesq operator registered by ModelFactory.registerNonPeriodic)
  contactmechanics
                constrained_conjugate_gradients (Polonsky-Keer) on
                PeriodicFFTElasticHalfSpace / FreeFFTElasticHalfSpace
  cm-ccg        ContactMechanics' CCG without restart (Bugnicourt et al. 2018):
                NonSmoothContactSystem.dual_minimize_proxy(offset,
                solver="ccg-without-restart", gtol=tol·h_rms) at the offset of
                ContactMechanics' own Polonsky-Keer solution of the same case where the
                contactmechanics run provided it, else at asperity's indentation converted
                to ContactMechanics' offset (free: d - max h; periodic: minus the mean of
                its displacement under the uniform load; both recorded where both exist),
                starting from the uniform pixel force p̄·A/n (unpadded shape)

Indentation of the peers is computed the same way as asperity's: apply the code's own
elastic operator to its pressure and average u + f over the contact set (f = max h − h).

The unit of cost: for every N and boundary, `asperity bench fft-pair` times one padded
forward + inverse real FFT pair (2N×2N free, N×N periodic) on each thread count used, in
the same run; a solve's cost per iteration is reported in those pairs (peers, which run on
one thread: in asperity's one-thread pair; their own numpy pair is recorded beside it).
Every asperity solve runs in --asperity-processes separate processes (default 3, each
cold) and the median time is reported, with all of them (`seconds_per_process`): one cold
512² solve of 0.19 s varies by up to 10 % between processes (measured: 0.189–0.206 s over
ten), which moved the per-iteration figure of a single process by as much; the peers, whose
solves take seconds to minutes, run once.
The pair is timed in --pair-processes separate processes (default 3) and the fastest kept:
on this machine one process in a few runs the pair (not the operator application) about
1.7× slower throughout (measured 6.2 against 3.6 ms at 512², 2 threads), which made the
per-iteration figures of one run swing by up to 60 %; the fastest pair makes them the
conservative ones.

results.json holds {"environment": ..., "fft_pairs": [...], "results": [...]}: the
environment records the peers' installed versions, the asperity git commit (and whether the
tree was dirty), the date, `nproc` and the load average, so that a table can be traced to
what produced it.

Usage: bench/bem_peers.py --asperity target/release/asperity --out bench/out
       [--sizes 256,512,1024] [--solvers bccg,pk] [--threads 2,1]
       [--peers tamaas,contactmechanics,cm-ccg]
"""

import argparse
import csv
import datetime
import json
import os
import platform
import re
import resource
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


def numpy_pair_seconds(shape, repeat=5):
    """Minimum time of one numpy rfft2 + irfft2 pair of a real grid of `shape`."""
    import numpy as np

    grid = np.random.default_rng(1).random(shape)
    best = float("inf")
    for _ in range(repeat + 1):
        start = time.perf_counter()
        np.fft.irfft2(np.fft.rfft2(grid), s=shape)
        best = min(best, time.perf_counter() - start)
    return best


def solve_tamaas(args, heights):
    """PolonskyKeerRey; returns (seconds, pressure, u, iterations=None, extra)."""
    import numpy as np
    import tamaas as tm

    n_rows, n_cols = heights.shape
    tm.set_log_level(tm.LogLevel.info)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, n_rows / n_cols], [n_rows, n_cols])
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
    pressure = np.array(model.traction, copy=True)
    u = np.zeros_like(pressure)
    if args.boundary == "free":
        model.operators["dcfft"](model.traction, u)
    else:
        model.solveNeumann()
        u = np.array(model.displacement, copy=True)
    return seconds, pressure, u, None, {}  # iterations parsed from tamaas' log by the parent


def cm_substrate(args, shape):
    from ContactMechanics import FreeFFTElasticHalfSpace, PeriodicFFTElasticHalfSpace

    cls = FreeFFTElasticHalfSpace if args.boundary == "free" else PeriodicFFTElasticHalfSpace
    n_rows, n_cols = shape
    return cls(shape, 1.0, physical_sizes=(n_rows / n_cols, 1.0))


def cm_polonsky_keer(args, heights, substrate):
    """ContactMechanics' Polonsky-Keer; returns (seconds, result) or raises on failure."""
    import numpy as np
    from ContactMechanics.Optimization import constrained_conjugate_gradients

    n_rows, n_cols = heights.shape
    area = n_rows / n_cols
    rms = float(np.std(heights))
    start = time.perf_counter()
    result = constrained_conjugate_gradients(
        substrate, heights, external_force=args.pressure * area,
        pentol=args.tol * rms, forcetol=1e-12 * args.pressure * area / (n_rows * n_cols),
        thermotol=args.tol, maxiter=100000)
    seconds = time.perf_counter() - start
    if not result.success:
        raise RuntimeError(f"Polonsky-Keer: {result.message}")
    return seconds, result


def solve_contactmechanics(args, heights):
    import numpy as np

    n_rows, n_cols = heights.shape
    substrate = cm_substrate(args, heights.shape)
    seconds, result = cm_polonsky_keer(args, heights, substrate)
    pixel_area = (n_rows / n_cols) / (n_rows * n_cols)
    force = np.asarray(result.jac)
    u = np.asarray(substrate.evaluate_disp(force))[:n_rows, :n_cols]
    return seconds, force / pixel_area, u, int(result.nit), {"offset": float(result.offset)}


def offset_from_indentation(args, heights, substrate):
    """ContactMechanics' offset of asperity's indentation d (--indentation): free boundaries
    d - max(h); periodic, where asperity's displacement has zero mean and ContactMechanics'
    carries the mean of its response to the uniform load (negative, its sign convention), d -
    max(h) minus that mean. Checked against ContactMechanics' own Polonsky-Keer offsets on
    the 256² surface (free and periodic, p = 0.01 and 0.05: equal within 3e-12)."""
    import numpy as np

    offset = args.indentation - float(heights.max())
    if args.boundary == "periodic":
        n_rows, n_cols = heights.shape
        uniform = np.full((n_rows, n_cols), args.pressure * (n_rows / n_cols) / (n_rows * n_cols))
        offset -= float(np.mean(np.asarray(substrate.evaluate_disp(uniform))[:n_rows, :n_cols]))
    return offset


def solve_cm_ccg(args, heights):
    """CCG without restart at ContactMechanics' Polonsky-Keer offset (--offset, or solved
    here untimed)."""
    import numpy as np
    from ContactMechanics.Systems import NonSmoothContactSystem
    from SurfaceTopography import Topography

    n_rows, n_cols = heights.shape
    substrate = cm_substrate(args, heights.shape)
    offset, extra = args.offset, {}
    if args.indentation is not None:
        extra["offset_from_asperity"] = offset_from_indentation(args, heights, substrate)
        if offset is None:
            offset = extra["offset_from_asperity"]
    if offset is None:
        offset = float(cm_polonsky_keer(args, heights, substrate)[1].offset)
        substrate = cm_substrate(args, heights.shape)
    topography = Topography(heights, physical_sizes=(n_rows / n_cols, 1.0),
                            periodic=args.boundary == "periodic")
    system = NonSmoothContactSystem(substrate=substrate, surface=topography)
    area = n_rows / n_cols
    init_force = np.full((n_rows, n_cols), args.pressure * area / (n_rows * n_cols))
    rms = float(np.std(heights))
    start, cpu_start = time.perf_counter(), time.process_time()
    result = system.dual_minimize_proxy(offset, init_force=init_force, solver="ccg-without-restart",
                                        gtol=args.tol * rms, maxiter=100000)
    seconds = time.perf_counter() - start
    extra["cpu_seconds"] = time.process_time() - cpu_start
    if not result.success:
        raise RuntimeError(f"CCG without restart: {result.message}")
    force = np.asarray(result.x).reshape(n_rows, n_cols)
    pixel_area = area / (n_rows * n_cols)
    u = np.asarray(substrate.evaluate_disp(force))[:n_rows, :n_cols]
    return seconds, force / pixel_area, u, int(result.nit), {"offset": offset, **extra}


def worker(args):
    """One cold solve with a peer; prints one JSON line."""
    import numpy as np

    heights = np.load(args.surface)
    n_rows, n_cols = heights.shape
    f = heights.max() - heights
    baseline = vm_hwm_mib()
    solve = {"tamaas": solve_tamaas, "contactmechanics": solve_contactmechanics,
             "cm-ccg": solve_cm_ccg}[args.code]
    try:
        seconds, pressure, u, iterations, extra = solve(args, heights)
    except RuntimeError as err:
        print(json.dumps({"error": str(err)}))
        return
    peak = vm_hwm_mib()
    contact = pressure > 0
    if args.boundary == "periodic":
        # Periodic displacements are defined up to a constant; use asperity's (zero mean).
        u = u - np.mean(u)
    pad = 2 if args.boundary == "free" else 1
    print(json.dumps({
        "seconds": seconds,
        "iterations": iterations,
        "area_fraction": float(np.mean(contact)),
        "mean_pressure": float(np.mean(pressure)),
        "indentation": indentation_from(u, f, contact),
        "peak_rss_mib": peak,
        "baseline_rss_mib": baseline,
        "numpy_pair_seconds": numpy_pair_seconds((pad * n_rows, pad * n_cols)),
        **extra,
    }))


def asperity_has_solver_flag(exe):
    """Whether `asperity bem` takes --solver (it arrives with the preconditioned solver)."""
    proc = subprocess.run([exe, "bem", "--help"], capture_output=True, text=True)
    return "--solver" in proc.stdout


def run_asperity(exe, surface, boundary, pressure, tol, out_dir, threads=None, solver=None):
    """One cold `asperity bem` solve; `solver` None runs the binary's default."""
    out = os.path.join(out_dir, "asperity_tmp.csv")
    env = dict(os.environ)
    if threads:
        env["RAYON_NUM_THREADS"] = str(threads)
    cmd = [exe, "bem", "--surface", surface, "--boundary", boundary, "--pressures", repr(pressure),
           "--tol", repr(tol), "--timing", "--no-stiffness", "--quiet", "--force", "--out", out]
    if solver:
        cmd += ["--solver", solver]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
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
        # The whole process's CPU time (reading the surface and planning included): on a
        # shared machine the comparable figure where wall times wait for a core.
        "process_cpu_seconds": (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime),
    }


def run_asperity_median(args, surface, boundary, pressure, threads, solver):
    """`run_asperity` in --asperity-processes processes: the record of the median time, with
    every process's seconds; an error if the runs disagree in anything but time (the solver
    is deterministic)."""
    runs = []
    for _ in range(max(args.asperity_processes, 1)):
        r = run_asperity(args.asperity, surface, boundary, pressure, args.tol, args.out, threads, solver)
        if "error" in r:
            return r
        runs.append(r)
    untimed = {(r["iterations"], r["area_fraction"], r["indentation"]) for r in runs}
    if len(untimed) > 1:
        return {"error": f"runs of the same case differ: {sorted(untimed)}"}
    runs.sort(key=lambda r: r["seconds"])
    median = dict(runs[len(runs) // 2])
    median["seconds_per_process"] = [r["seconds"] for r in runs]
    return median


def fft_pair_seconds(exe, n, boundary, threads, repeat, processes):
    """`asperity bench fft-pair` in `processes` separate processes: the minimum seconds of one
    padded forward + inverse pair and of one operator application (see the module docs);
    None where the binary lacks the kernel."""
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    pairs, applications = [], []
    for _ in range(max(processes, 1)):
        proc = subprocess.run([exe, "bench", "fft-pair", "--n", str(n), "--boundary", boundary,
                               "--repeat", str(repeat)], capture_output=True, text=True, env=env)
        if proc.returncode != 0:
            return None
        fields = dict(item.split("=", 1) for item in proc.stdout.split() if "=" in item)
        pairs.append(float(fields["pair_min_s"]))
        applications.append(float(fields["apply_min_s"]))
    return {"n": n, "boundary": boundary, "threads": threads, "pair_seconds": min(pairs),
            "apply_seconds": min(applications), "pair_seconds_per_process": pairs}


def run_peer(code, surface, boundary, pressure, tol, timeout, offset=None, indentation=None):
    cmd = [sys.executable, os.path.abspath(__file__), "worker", "--code", code, "--surface", surface,
           "--boundary", boundary, "--pressure", repr(pressure), "--tol", repr(tol)]
    if offset is not None:
        cmd += ["--offset", repr(offset)]
    if indentation is not None:
        cmd += ["--indentation", repr(indentation)]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout} s"}
    lines = [l for l in proc.stdout.splitlines() if l.startswith("{")]
    if proc.returncode != 0 or not lines:
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
        return {"error": " | ".join(tail)}
    result = json.loads(lines[-1])
    if code == "tamaas" and "error" not in result:
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
        "peers": {package: version(package) for package in ("tamaas", "ContactMechanics", "NuMPI", "SurfaceTopography", "numpy", "scipy")},
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


def asperity_configs(args):
    """(code name, solver flag or None, threads) for every asperity run of a case."""
    has_flag = asperity_has_solver_flag(args.asperity)
    configs = []
    for solver in [s for s in args.solvers.split(",") if s]:
        for threads in [int(t) for t in args.threads.split(",") if t]:
            name = f"asperity-{solver}-{threads}t"
            if has_flag:
                configs.append((name, solver, threads))
            elif solver == "pk":
                configs.append((name, None, threads))  # the only solver of such a binary
            else:
                configs.append((name, "unavailable", threads))
    return configs


def run_case(args, surface, n, boundary, pressure, configs, pairs):
    """Every code on one (surface, boundary, pressure); returns the result records."""
    results = []
    offset = None
    for name, solver, threads in configs:
        if solver == "unavailable":
            r = {"error": "skipped: this asperity binary has no --solver"}
        else:
            r = run_asperity_median(args, surface, boundary, pressure, threads, solver)
            r["baseline_rss_mib"] = args.baseline
        r.update({"code": name, "threads": threads})
        results.append(r)
    for code in [p for p in args.peers.split(",") if p]:
        tol = args.tamaas_tol if (code == "tamaas" and args.tamaas_tol) else args.tol
        # The CCG's offset: ContactMechanics' Polonsky-Keer's where it ran, else asperity's
        # indentation converted (`offset_from_indentation`; recorded beside it either way).
        indentation = next((a["indentation"] for a in results if "indentation" in a), None)
        r = run_peer(code, surface, boundary, pressure, tol, args.timeout,
                     offset=offset if code == "cm-ccg" else None,
                     indentation=indentation if code == "cm-ccg" else None)
        if code == "contactmechanics" and "offset" in r:
            offset = r["offset"]
        r.update({"code": code, "threads": 1})
        results.append(r)
    for r in results:
        pair = pairs.get((n, boundary, r["threads"]))
        if pair and "error" not in r and r.get("iterations"):
            r["pair_seconds"] = pair["pair_seconds"]
            r["iteration_in_pairs"] = r["seconds"] / r["iterations"] / pair["pair_seconds"]
        padded = pairs.get((n, "free", r["threads"]))
        if padded and "error" not in r and r.get("iterations"):
            # Issue 10's unit whatever the boundary: the 2N×2N pair.
            r["iteration_in_padded_pairs"] = r["seconds"] / r["iterations"] / padded["pair_seconds"]
        if "numpy_pair_seconds" in r and r.get("iterations"):
            r["iteration_in_numpy_pairs"] = r["seconds"] / r["iterations"] / r["numpy_pair_seconds"]
        r.update({"n": n, "boundary": boundary, "pressure": pressure,
                  "padded_minimum_mib": padded_minimum_mib(n, boundary)})
        print(json.dumps(r), flush=True)
    return results


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command")
    w = sub.add_parser("worker")
    w.add_argument("--code", required=True)
    w.add_argument("--surface", required=True)
    w.add_argument("--boundary", required=True)
    w.add_argument("--pressure", type=float, required=True)
    w.add_argument("--tol", type=float, required=True)
    w.add_argument("--offset", type=float, default=None)
    w.add_argument("--indentation", type=float, default=None)
    parser.add_argument("--asperity", default="target/release/asperity")
    parser.add_argument("--out", default="bench/out")
    parser.add_argument("--sizes", default="256,512,1024")
    parser.add_argument("--pressures", default="0.01,0.05")
    parser.add_argument("--boundaries", default="free,periodic")
    parser.add_argument("--solvers", default="bccg,pk",
                        help="asperity solvers (values of `asperity bem --solver`); the first that "
                             "ran is the reference of the agreement columns")
    parser.add_argument("--threads", default="2,1", help="asperity thread counts (RAYON_NUM_THREADS)")
    parser.add_argument("--peers", default="tamaas,contactmechanics,cm-ccg")
    parser.add_argument("--tol", type=float, default=1e-8, help="asperity's tolerance")
    parser.add_argument("--tamaas-tol", type=float, default=None,
                        help="tamaas' tolerance (its error measure differs; default: same value)")
    parser.add_argument("--pair-repeat", type=int, default=10, help="repetitions of the FFT pair timing")
    parser.add_argument("--pair-processes", type=int, default=3,
                        help="processes timing the FFT pair (the fastest is the unit; 0: no pair "
                             "timed, no per-pair columns)")
    parser.add_argument("--asperity-processes", type=int, default=3,
                        help="processes per asperity solve (the median is reported)")
    parser.add_argument("--timeout", type=float, default=1800)
    args = parser.parse_args()
    if args.command == "worker":
        worker(args)
        return
    os.makedirs(args.out, exist_ok=True)
    env = environment(args.asperity)
    print(json.dumps({"environment": env}), flush=True)
    configs = asperity_configs(args)
    # asperity's fixed memory (binary, allocator): peak RSS of a 16² solve.
    tiny = os.path.join(args.out, "surface_16.npy")
    subprocess.run([args.asperity, "surface", "--n", "16", "--hurst", "0.8", "--rms-slope", "1",
                    "--out", tiny, "--force"], check=True, capture_output=True)
    args.baseline = run_asperity(args.asperity, tiny, "free", 0.01, args.tol, args.out)["peak_rss_mib"]
    thread_counts = sorted({t for _, _, t in configs} | {1})
    results, pairs = [], {}
    for n in [int(s) for s in args.sizes.split(",")]:
        surface = os.path.join(args.out, f"surface_{n}.npy")
        subprocess.run([args.asperity, "surface", "--n", str(n), "--hurst", "0.8", "--rolloff", "6",
                        "--rms-slope", "1", "--seed", "1", "--out", surface, "--force"], check=True,
                       capture_output=True)
        for boundary in args.boundaries.split(","):
            for threads in thread_counts if args.pair_processes > 0 else []:
                pair = fft_pair_seconds(args.asperity, n, boundary, threads, args.pair_repeat,
                                        args.pair_processes)
                if pair:
                    pairs[(n, boundary, threads)] = pair
                    print(json.dumps({"fft_pair": pair}), flush=True)
            for pressure in [float(p) for p in args.pressures.split(",")]:
                results += run_case(args, surface, n, boundary, pressure, configs, pairs)
    env["loadavg_end"] = list(os.getloadavg())
    with open(os.path.join(args.out, "results.json"), "w") as fh:
        json.dump({"environment": env, "fft_pairs": list(pairs.values()), "results": results}, fh, indent=1)
    with open(os.path.join(args.out, "results.md"), "w") as fh:
        fh.write(tables(results, [name for name, _, _ in configs]))
    print(tables(results, [name for name, _, _ in configs]))


def fmt(value, spec):
    return "" if value is None else format(value, spec)


def tables(results, asperity_codes):
    """Markdown: one row per solve (agreement with the reference: the first asperity run of
    the case that succeeded), then the ratios of every peer's time to every asperity run's."""
    ok = {(r["n"], r["boundary"], r["pressure"], r["code"]): r for r in results if "error" not in r}
    lines = ["| N | boundary | p̄ | code | threads | time/solve (s) | iterations | iteration ÷ FFT pair "
             "| iteration ÷ numpy pair | peak RSS (MiB) | RSS − start-up (MiB) | ÷ padded minimum "
             "| area fraction | indentation | Δarea rel. | Δd rel. |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        head = f"| {r['n']} | {r['boundary']} | {r['pressure']} | {r['code']} | {r['threads']} |"
        if "error" in r:
            lines.append(f"{head} {r['error']} ||||||||||||")
            continue
        case = (r["n"], r["boundary"], r["pressure"])
        reference = next((c for c in asperity_codes if case + (c,) in ok), None)
        a = ok.get(case + (reference,))
        d_area = d_ind = ""
        if a and r["code"] != reference:
            d_area = f"{abs(r['area_fraction'] / a['area_fraction'] - 1):.1e}"
            d_ind = f"{abs(r['indentation'] / a['indentation'] - 1):.1e}"
        net = r["peak_rss_mib"] - r.get("baseline_rss_mib", 0.0)
        lines.append(f"{head} {r['seconds']:.3f} | {r['iterations']} | {fmt(r.get('iteration_in_pairs'), '.2f')} | "
                     f"{fmt(r.get('iteration_in_numpy_pairs'), '.2f')} | "
                     f"{r['peak_rss_mib']:.0f} | {net:.0f} | {net / r['padded_minimum_mib']:.2f} | "
                     f"{r['area_fraction']:.5f} | {r['indentation']:.6e} | {d_area} | {d_ind} |")
    lines += ["", "| N | boundary | p̄ | peer | time/solve (s) | " +
              " | ".join(f"÷ {c}" for c in asperity_codes) + " |",
              "|---|---|---|---|---|" + "---|" * len(asperity_codes)]
    for r in results:
        if r["code"] in asperity_codes or "error" in r:
            continue
        ratios = []
        for c in asperity_codes:
            a = ok.get((r["n"], r["boundary"], r["pressure"], c))
            ratios.append(f"{r['seconds'] / a['seconds']:.1f}×" if a else "")
        lines.append(f"| {r['n']} | {r['boundary']} | {r['pressure']} | {r['code']} | {r['seconds']:.3f} | " +
                     " | ".join(ratios) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
