"""Time surface generation side by side: asperity vs SurfaceTopography vs tamaas.

Run through surface_peers.sh, which builds asperity and the venv. Same grid, same
spectrum (H = 0.8, roll-off at q0 L / 2pi = 6, rms slope 1), minimum over repeats.

Two figures per generator, so that like is compared with like:
- "with set-up": everything a one-shot call pays (FFT planning, buffers, the surface);
  for asperity a new SurfaceGenerator per repeat, for tamaas a new generator and spectrum
  per repeat, for SurfaceTopography one call of fourier_synthesis.
- "set-up reused": one more surface from an object that keeps its plans and buffers
  (asperity's generator, tamaas' generator). fourier_synthesis keeps nothing between
  calls, so its two figures are the same call.
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
    cold = float(re.search(r"cold_min_s=([0-9.]+)", out).group(1))
    steady = float(re.search(r"steady_min_s=([0-9.]+)", out).group(1))
    return cold, steady


def surface_topography():
    from SurfaceTopography.Generation import fourier_synthesis
    L = 1.0
    rng = np.random.default_rng(1)

    def run():
        t = fourier_synthesis((N, N), (L, L), HURST, rms_slope=1.0, long_cutoff=L / Q0, rolloff=1.0, rng=rng)
        t.heights()
    t = best_of(run)
    return t, t


def tamaas():
    import tamaas as tm
    tm.initialize(2)

    def make():
        spectrum = tm.Isopowerlaw2D()
        spectrum.q0, spectrum.q1, spectrum.q2, spectrum.hurst = int(Q0), int(Q0), N // 2, HURST
        gen = tm.SurfaceGeneratorRandomPhase2D([N, N])
        gen.spectrum = spectrum
        gen.random_seed = 1
        return gen

    def cold():
        make().buildSurface()

    gen = make()
    gen.buildSurface()  # first call: plans and buffers
    return best_of(cold), best_of(gen.buildSurface)


rows = [("asperity", asperity),
        ("SurfaceTopography.fourier_synthesis", surface_topography),
        ("tamaas.SurfaceGeneratorRandomPhase2D", tamaas)]

results = []
for name, fn in rows:
    try:
        results.append((name, fn()))
    except Exception as exc:  # report, do not hide, a peer that fails
        results.append((name, None))
        print(f"{name}: failed: {exc}", file=sys.stderr)

base = results[0][1]
print(f"| generator ({N}x{N}, min of {REPEAT}) | with set-up (s) | ratio | set-up reused (s) | ratio |")
print("|---|---|---|---|---|")
for name, t in results:
    if t is None:
        print(f"| {name} | failed | | failed | |")
    else:
        print(f"| {name} | {t[0]:.3f} | {t[0] / base[0]:.1f}x | {t[1]:.3f} | {t[1] / base[1]:.1f}x |")
