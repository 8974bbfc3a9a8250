"""Time surface generation side by side: asperity vs SurfaceTopography vs tamaas.

Run through surface_peers.sh, which builds asperity and the venv. Same grid, same
spectrum (H = 0.8, roll-off at q0 L / 2pi = 6, rms slope 1), minimum over repeats.
"""
import os
import re
import subprocess
import sys
import time

import numpy as np

N = int(os.environ.get("N", "4096"))
REPEAT = int(os.environ.get("REPEAT", "5"))
HURST, Q0 = 0.8, 6.0
ASPERITY = os.environ.get("ASPERITY", "target/release/asperity")


def best_of(fn):
    times = []
    for _ in range(REPEAT):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def asperity():
    out = subprocess.run([ASPERITY, "bench", "surface", "--n", str(N), "--repeat", str(REPEAT),
                          "--hurst", str(HURST)], check=True, capture_output=True, text=True).stdout
    return float(re.search(r"min_s=([0-9.]+)", out).group(1))


def surface_topography():
    from SurfaceTopography.Generation import fourier_synthesis
    L = 1.0
    rng = np.random.default_rng(1)

    def run():
        t = fourier_synthesis((N, N), (L, L), HURST, rms_slope=1.0, long_cutoff=L / Q0, rolloff=1.0, rng=rng)
        t.heights()
    return best_of(run)


def tamaas():
    import tamaas as tm
    tm.initialize(2)
    spectrum = tm.Isopowerlaw2D()
    spectrum.q0, spectrum.q1, spectrum.q2, spectrum.hurst = int(Q0), int(Q0), N // 2, HURST
    gen = tm.SurfaceGeneratorRandomPhase2D([N, N])
    gen.spectrum = spectrum
    gen.random_seed = 1

    def run():
        gen.buildSurface()
    return best_of(run)


rows = [("asperity", asperity)]
for name, fn in [("SurfaceTopography.fourier_synthesis", surface_topography),
                 ("tamaas.SurfaceGeneratorRandomPhase2D", tamaas)]:
    rows.append((name, fn))

results = []
for name, fn in rows:
    try:
        results.append((name, fn()))
    except Exception as exc:  # report, do not hide, a peer that fails
        results.append((name, None))
        print(f"{name}: failed: {exc}", file=sys.stderr)

base = results[0][1]
print(f"| generator ({N}x{N}, min of {REPEAT}) | seconds | ratio to asperity |")
print("|---|---|---|")
for name, t in results:
    print(f"| {name} | {t:.3f} | {t / base:.1f}x |" if t else f"| {name} | failed | |")
