"""Measured-topography benchmark: read a 4096² X3P and SUR file and compute its statistics,
asperity against SurfaceTopography, side by side in one run (issue 11).

The files are made here, from one asperity surface (H 0.8, roll-off 6, rms slope 1, seed 1,
side 1 mm):
  * X3P by `asperity import s.npy --out s.x3p` (float64 payload, stored in the zip), and
    the same archive with every member deflated (as many instruments write it);
  * SUR by a minimal Digital Surf writer below (one object, 32-bit samples), following the
    header layout documented in crates/asperity/src/topography/sur.rs.
Both tools are first checked to read the same heights (to 1e-12 relative, SUR to its
quantisation), so the timings compare like with like.

Timed work (wall time, the minimum of --repeat runs, each a fresh process for asperity):
  * asperity: `asperity stats FILE --detrend none` (read, rms height/slope/curvature, ISO
    25178 parameters, radial PSD and its fit);
  * SurfaceTopography: `read_topography(FILE).topography()`, then rms height, rms gradient,
    rms curvature, Sa, skewness, kurtosis and the radial PSD from the area (its
    `power_spectrum_from_area`), in one Python process whose import time is excluded.
"""

import argparse
import json
import os
import struct
import subprocess
import sys
import time

import numpy as np

SIDE_M = 1e-3


def make_surface(exe, n, folder):
    npy = os.path.join(folder, f"s{n}.npy")
    if not os.path.exists(npy):
        subprocess.run([exe, "surface", "--n", str(n), "--hurst", "0.8", "--rolloff", "6",
                        "--rms-slope", "1", "--seed", "1", "--size", repr(SIDE_M),
                        "--out", npy, "--force"], check=True)
    return npy


def make_x3p(exe, npy, folder):
    x3p = npy[:-4] + ".x3p"
    if not os.path.exists(x3p):
        subprocess.run([exe, "import", npy, "--out", x3p, "--size", repr(SIDE_M), "--detrend", "none", "--force"],
                       check=True)
    return x3p


def deflate_zip(source, target):
    import zipfile
    with zipfile.ZipFile(source) as src, \
            zipfile.ZipFile(target, "w", compression=zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            dst.writestr(info.filename, src.read(info.filename))


def write_sur(heights, side_m, path):
    """One-object Digital Surf SUR: 512-byte header, int32 samples, heights in µm."""
    rows, cols = heights.shape
    # The header stores the steps as float32: use those values for the expected heights.
    dz_um = float(np.float32(np.abs(heights).max() * 1e6 / 2.0e9))  # int32, with headroom
    samples = np.round(heights * 1e6 / dz_um).astype("<i4")
    h = bytearray(512)
    h[0:12] = b"DIGITAL SURF"
    struct.pack_into("<HH", h, 12, 0, 1)          # format (PC), number of objects
    struct.pack_into("<H", h, 18, 2)              # object type: surface
    h[20:50] = b"bench".ljust(30)                 # object name
    struct.pack_into("<H", h, 86, 0)              # no non-measured points
    struct.pack_into("<H", h, 98, 32)             # bits per point
    struct.pack_into("<ii", h, 100, int(samples.min()), int(samples.max()))
    struct.pack_into("<iiI", h, 108, cols, rows, cols * rows)
    dx_um = float(np.float32(side_m * 1e6 / cols))
    struct.pack_into("<fff", h, 120, dx_um, dx_um, dz_um)
    h[132:180] = b"X".ljust(16) + b"Y".ljust(16) + b"Z".ljust(16)  # axis names
    for offset in range(180, 276, 16):  # steps' then axes' units (x, y, z each)
        h[offset:offset + 16] = "µm".encode("latin-1").ljust(16, b"\0")
    struct.pack_into("<fff", h, 276, 1.0, 1.0, 1.0)  # unit ratios
    struct.pack_into("<H", h, 290, 0)             # no inversion
    struct.pack_into("<HH", h, 334, 0, 0)         # comment and private zone sizes
    with open(path, "wb") as f:
        f.write(h)
        f.write(samples.tobytes())
    return samples.astype(float) * dz_um * 1e-6, dx_um * cols * 1e-6


def st_stats(path):
    from SurfaceTopography import read_topography
    start = time.perf_counter()
    t = read_topography(path).to_unit("m")
    h = t.heights()
    values = {
        "rms_height": t.rms_height_from_area(),
        "rms_slope": t.rms_gradient(),
        "rms_curvature": t.rms_curvature_from_area(),
        "sa": float(np.mean(np.abs(h - h.mean()))),
        "skewness": float(np.mean((h - h.mean()) ** 3) / h.std() ** 3),
        "kurtosis": float(np.mean((h - h.mean()) ** 4) / h.std() ** 4),
    }
    q, c = t.power_spectrum_from_area()
    values["psd_bins"] = int(len(q))
    return time.perf_counter() - start, values


def asperity_stats(exe, path):
    start = time.perf_counter()
    out = subprocess.run([exe, "stats", path, "--detrend", "none"], check=True,
                         capture_output=True, text=True)
    return time.perf_counter() - start, out.stdout


def check_same_heights(path, expected, side):
    from SurfaceTopography import read_topography
    t = read_topography(path).to_unit("m")
    # SurfaceTopography indexes [x, y]; asperity (row, col) = (y, x).
    theirs = np.asarray(t.heights()).T
    scale = np.abs(expected).max()
    err = float(np.abs(theirs - expected).max() / scale)
    size_err = abs(t.physical_sizes[0] - side) / side
    if err > 1e-12 or size_err > 1e-6:
        sys.exit(f"{path}: SurfaceTopography reads other heights (max rel. diff {err:.2e}, "
                 f"size rel. diff {size_err:.1e})")
    return err


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--asperity", default="target/release/asperity")
    parser.add_argument("--n", type=int, default=4096)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default="bench/out")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    npy = make_surface(args.asperity, args.n, args.out)
    heights = np.load(npy)
    x3p = make_x3p(args.asperity, npy, args.out)
    sur = npy[:-4] + ".sur"
    sur_heights, sur_side = write_sur(heights, SIDE_M, sur)
    x3p_deflated = npy[:-4] + "-deflated.x3p"
    if not os.path.exists(x3p_deflated):
        deflate_zip(x3p, x3p_deflated)
    checks = {"x3p": check_same_heights(x3p, heights, SIDE_M),
              "x3p (deflated)": check_same_heights(x3p_deflated, heights, SIDE_M),
              "sur": check_same_heights(sur, sur_heights, sur_side)}
    rows = []
    for fmt, path in (("x3p", x3p), ("x3p (deflated)", x3p_deflated), ("sur", sur)):
        ours = min(asperity_stats(args.asperity, path)[0] for _ in range(args.repeat))
        theirs = min(st_stats(path)[0] for _ in range(args.repeat))
        rows.append({"format": fmt, "n": args.n, "bytes": os.path.getsize(path),
                     "asperity_s": ours, "surfacetopography_s": theirs,
                     "ratio": theirs / ours, "heights_agree_to": checks[fmt]})
    environment = {"date": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "nproc": os.cpu_count(),
                   "loadavg": os.getloadavg(),
                   "threads": os.environ.get("RAYON_NUM_THREADS", "all")}
    with open(os.path.join(args.out, "topography_results.json"), "w") as f:
        json.dump({"environment": environment, "rows": rows}, f, indent=1)
    print(f"| file ({args.n}²) | size | asperity read + stats | SurfaceTopography | ratio |")
    print("|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['format'].upper()} | {r['bytes'] / 2**20:.0f} MiB | {r['asperity_s']:.2f} s "
              f"| {r['surfacetopography_s']:.2f} s | {r['ratio']:.1f}× |")
    print(f"(load average at the end: {environment['loadavg'][0]:.2f})")


if __name__ == "__main__":
    main()
