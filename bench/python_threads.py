#!/usr/bin/env python3
"""Two BEM sweeps in two Python threads against the same two one after the other.

    RAYON_NUM_THREADS=1 python/.venv/bin/python bench/python_threads.py [--n 192] [--repeat 3]

With one library thread per solve, two sweeps in two threads on 2 idle cores take about
the time of one when the GIL is released during a solve (ratio ≈ 0.5), and at least the
serial time were it held (ratio ≥ 1). Serial and threaded runs alternate (minimum of
`--repeat` each) so that a change in the machine's load hits both. This is a measurement,
not a test: on a busy machine the ratio rises towards 1 (measured 0.58 at load average 4,
0.74 at 7.5 on 2 cores), which is why the test suite checks only that the two sweeps are in
flight together (python/tests/test_behaviour.py::test_two_sweeps_in_two_threads_run_at_once).
"""

import argparse
import threading
import time

import asperity


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=192)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    s = asperity.surface(args.n, hurst=0.8, rolloff=4, rms_slope=1.0, seed=3)
    solvers = [asperity.Solver(s) for _ in range(2)]

    def job(solver):
        solver.reset()
        solver.sweep(pressures=[0.002, 0.005, 0.01, 0.02, 0.05])

    job(solvers[0])
    job(solvers[1])  # warm up
    serial = parallel = float("inf")
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        job(solvers[0])
        job(solvers[1])
        serial = min(serial, time.perf_counter() - t0)
        threads = [threading.Thread(target=job, args=(sv,)) for sv in solvers]
        t0 = time.perf_counter()
        [t.start() for t in threads]
        [t.join() for t in threads]
        parallel = min(parallel, time.perf_counter() - t0)
    print(f"two sweeps one after the other {serial:.3f} s, in two threads {parallel:.3f} s, "
          f"ratio {parallel / serial:.2f}")


if __name__ == "__main__":
    main()
