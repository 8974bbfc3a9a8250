#!/usr/bin/env python3
"""Python overhead of a BEM solve: the same cold 256² solve timed from Python and from Rust.

    python/.venv/bin/python bench/python_overhead.py [--n 256] [--repeat 7] [--pressure 0.01]

Rust: `asperity bem --surface s.npy --pressures P --timing --no-stiffness` (the CSV's
`solve_seconds`: the library's `ContactSolver::solve` on a freshly built solver). Python:
`asperity.Solver(s).solve(pressure=P, fields=False)` from cold (see python_solve), timed around
the call (so it includes the binding: argument conversion, the GIL release, the helper
thread that lets Ctrl-C through, the result dict), and with `fields=True` (copies of
pressure and gap, plus one operator application for the displacement). Both solve the same
surface (H = 0.8, roll-off 6, rms slope 1, seed 0) from cold to the same numbers (checked).
A second Rust figure comes from inside one warm process, like the Python one:
`asperity bench bem-solve` (the same surface and solver, minimum over its repeats; its
indentation is checked against the others too).
Minimum over the repeats; free and periodic boundaries. Needs the binary
(ASPERITY_BIN, else target/release/asperity) and the package installed (`pip install ./python`).
"""

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import asperity

REPO = Path(__file__).resolve().parents[1]


def rust_solve(exe, surface, boundary, pressure):
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "r.csv"
        subprocess.run([str(exe), "bem", "--surface", str(surface), "--boundary", boundary,
                        "--pressures", repr(pressure), "--timing", "--no-stiffness", "--quiet",
                        "--out", str(out)], check=True)
        with open(out, newline="") as fh:
            row = next(csv.DictReader(fh))
    return float(row["solve_seconds"]), float(row["indentation"]), int(row["iterations"])


def rust_warm_solve(exe, n, boundary, pressure, repeat):
    out = subprocess.run([str(exe), "bench", "bem-solve", "--n", str(n), "--pressures",
                          repr(pressure), "--solvers", "bccg", "--boundaries", boundary,
                          "--repeat", str(repeat)], check=True, capture_output=True, text=True)
    line = next(l for l in out.stdout.splitlines() if l.startswith("kernel=bem-solve"))
    fields = dict(item.split("=", 1) for item in line.split())
    return float(fields["solve_min_s"]), float(fields["indentation"]), int(fields["iterations"])


def python_solve(heights, boundary, pressure, fields):
    solver = asperity.Solver(heights, boundary=boundary)
    # The CLI's timed solve follows its full-contact check, whose operator applications
    # have touched the FFT buffers once; here one solve does that, and reset() makes the
    # timed solve start cold again (the same iterations and numbers as a fresh solver).
    solver.solve(pressure=pressure, fields=False)
    solver.reset()
    start = time.perf_counter()
    result = solver.solve(pressure=pressure, fields=fields)
    return time.perf_counter() - start, result.indentation, result.iterations


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=256)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--pressure", type=float, default=0.01)
    parser.add_argument("--json", help="also write the figures to this file")
    args = parser.parse_args()
    exe = Path(os.environ.get("ASPERITY_BIN", REPO / "target" / "release" / "asperity"))
    if not exe.exists():
        sys.exit(f"no asperity binary at {exe}: cargo build --release -p asperity-cli")
    surface = asperity.surface(args.n, hurst=0.8, rolloff=6, rms_slope=1.0, seed=0)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s.npy"
        surface.save(path)
        for boundary in ("free", "periodic"):
            # Interleaved, so that a change in the machine's load hits all three alike.
            rust, bare, full = [], [], []
            for _ in range(args.repeat):
                rust.append(rust_solve(exe, path, boundary, args.pressure))
                bare.append(python_solve(surface.heights, boundary, args.pressure, False))
                full.append(python_solve(surface.heights, boundary, args.pressure, True))
            same = {r[1:] for r in rust} == {b[1:] for b in bare} == {f[1:] for f in full}
            if not same:
                sys.exit(f"{boundary}: Python and Rust solves differ: {rust[0]} {bare[0]}")
            t_rust, t_bare, t_full = (min(t for t, *_ in x) for x in (rust, bare, full))
            t_warm, warm_indentation, _ = rust_warm_solve(exe, args.n, boundary, args.pressure,
                                                          args.repeat)
            # bench prints 10 significant digits: equal to that precision.
            if abs(warm_indentation / rust[0][1] - 1) > 1e-9:
                sys.exit(f"{boundary}: bench bem-solve solved another problem: {warm_indentation}")
            results.append(dict(n=args.n, boundary=boundary, iterations=rust[0][2],
                                rust_s=t_rust, rust_warm_s=t_warm, python_s=t_bare,
                                python_fields_s=t_full, overhead=t_bare / t_rust - 1,
                                overhead_warm=t_bare / t_warm - 1,
                                overhead_fields=t_full / t_rust - 1))
    print(f"{'N':>5} {'boundary':>9} {'iter':>5} {'Rust CLI (s)':>12} {'Rust warm (s)':>13} "
          f"{'Python (s)':>10} {'vs CLI':>8} {'vs warm':>8} {'+fields (s)':>11} {'vs CLI':>8}")
    for r in results:
        print(f"{r['n']:5d} {r['boundary']:>9} {r['iterations']:5d} {r['rust_s']:12.4f} "
              f"{r['rust_warm_s']:13.4f} {r['python_s']:10.4f} {100 * r['overhead']:7.2f}% "
              f"{100 * r['overhead_warm']:7.2f}% {r['python_fields_s']:11.4f} "
              f"{100 * r['overhead_fields']:7.2f}%")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
