#!/usr/bin/env python3
"""Two `asperity` binaries timed against each other on `asperity bench bem-solve`,
interleaved (A B A B …), so that a loaded machine slows both alike (docs/performance.md).

Each run is one process, `bench bem-solve --n N --boundaries B --solvers S --pressures P
--repeat R` (seed 0, the default); its CPU time (user + sys of the child, from getrusage) and wall time
are recorded beside the solve times the bench prints (minimum and median of R cold solves)
and its iterations, which must be the same for both binaries (a run whose iterations
differ is reported as such: then the two binaries do not compute the same thing).

  python3 bench/bem_solve_ab.py --a OLD_BINARY --b NEW_BINARY [--n 512,1024] \
      [--boundaries free,periodic] [--pairs 5] [--repeat 3] [--threads 1] \
      [--pressure 0.05] [--solver bccg] [--out ab.json]

Prints one JSON line per run and, per (N, boundary), the medians and ranges of B ÷ A
(CPU time, solve minimum, wall), pair by pair.
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time


def run(exe, n, boundary, args):
    env = dict(os.environ, RAYON_NUM_THREADS=str(args.threads))
    cmd = [exe, "bench", "bem-solve", "--n", str(n), "--boundaries", boundary, "--solvers",
           args.solver, "--pressures", repr(args.pressure), "--repeat", str(args.repeat)]
    if args.seed:  # binaries before 80b4e3c know only the surface of seed 0, without --seed
        cmd += ["--seed", str(args.seed)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    load = os.getloadavg()[0]
    start = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    fields = dict(kv.split("=", 1) for kv in out.split() if "=" in kv)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"n": n, "boundary": boundary, "cpu_s": cpu, "wall_s": wall,
            "solve_min_s": float(fields["solve_min_s"]),
            "solve_median_s": float(fields["solve_median_s"]),
            "iterations": int(fields["iterations"]),
            "operator_applications": int(fields["operator_applications"]),
            "load_1min": load}


def spread(values):
    return {"median": statistics.median(values), "min": min(values), "max": max(values)}


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--a", required=True, help="the binary before")
    parser.add_argument("--b", required=True, help="the binary after")
    parser.add_argument("--n", default="512,1024")
    parser.add_argument("--boundaries", default="free,periodic")
    parser.add_argument("--pairs", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--pressure", type=float, default=0.05)
    parser.add_argument("--solver", default="bccg")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out")
    args = parser.parse_args()
    runs, summary = [], []
    for n in map(int, args.n.split(",")):
        for boundary in args.boundaries.split(","):
            pairs = []
            for k in range(args.pairs):
                pair = {}
                for name, exe in (("a", args.a), ("b", args.b)):
                    record = {"binary": name, "pair": k, **run(exe, n, boundary, args)}
                    print(json.dumps(record), flush=True)
                    runs.append(record)
                    pair[name] = record
                pairs.append(pair)
            same = all(p["a"]["iterations"] == p["b"]["iterations"] for p in pairs)
            row = {"n": n, "boundary": boundary, "iterations_identical": same,
                   "iterations": sorted({p[x]["iterations"] for p in pairs for x in "ab"})}
            for key in ("cpu_s", "solve_min_s", "wall_s"):
                row[key] = {x: spread([p[x][key] for p in pairs]) for x in "ab"}
                row[key]["b_over_a"] = spread([p["b"][key] / p["a"][key] for p in pairs])
            row["load_1min"] = spread([p[x]["load_1min"] for p in pairs for x in "ab"])
            print(json.dumps({"summary": row}), flush=True)
            summary.append(row)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump({"a": args.a, "b": args.b, "threads": args.threads,
                       "pressure": args.pressure, "solver": args.solver,
                       "repeat": args.repeat, "summary": summary, "runs": runs}, fh, indent=1)


if __name__ == "__main__":
    sys.exit(main())
