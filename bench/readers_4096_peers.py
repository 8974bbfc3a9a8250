"""Every binary reader that can be written at 4096² here, timed beside SurfaceTopography
(issue 34, item 4: "reads a 4096² file in under a second, benchmark beside
SurfaceTopography").

A sibling of bench/hdf5_read_peers.py (whose `.h5`, `.datx`, `.x3p` (stored and deflated)
and `.sur` writers it reuses) with the formats whose layout is simple enough to write from
Python, or that SurfaceTopography 1.27.1 itself writes, all from the same seeded 4096²
map (metres, 1 mm a side), in --folder (keep it out of the repository: /tmp):
  * `.nc`: SurfaceTopography's own `to_netcdf` (NetCDF 3, 64-bit offsets, float64);
  * `.gwy`: SurfaceTopography's own `to_gwy` (Gwyddion, float64);
  * `.sdf`: ISO 25178-71 binary (`bISO-1.0`, 81-byte header, float64, Zscale 1);
  * `.tmd`: TrueMap v2 (32-byte signature, 24-byte comment, float32 heights in mm);
  * `.bcrf`: SPIP BCRF (2048-character ASCII header, float32 heights in nm);
  * `.mi`: PicoView MI (text header, one `Topography` buffer of int32 samples in µm);
  * the instrument formats neither tool writes (DI, PLU, MetroPro, OPDx, NID, IBW, AL3D,
    VK4, VK6, ZON, LEXT, OPD, FRT, NMS, WSxM, JPK, Park TIFF, MNT), by
    bench/readers_4096_layouts.py: each from the real file of the shared folders where
    there is one (its header kept, the grid's dimensions and offsets changed), else in the
    layout the readers document; their heights computed there from the header's scale.
Before timing, each file is read by both tools and both readings are checked against the
heights the file holds (float32 files: the map rounded to float32, times the unit's
factor), to 1e-12 of the largest height; where the peer fails or reads other heights, it
says so (and the peer is timed only where it reads the file).

Timed (`--repeat` interleaved rounds; the median reported, every run in the JSON): asperity as
`asperity import FILE --out OUT.npy --detrend none --force` in a fresh process (CPU =
user + system and the peak RSS by /usr/bin/time; wall around it); the
peer as `open_topography(FILE).topography()` (`.to_unit("m")`), `.heights()` in this
Python process (CPU from `time.process_time()`; import time excluded).
"""

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hdf5_read_peers as h5b  # noqa: E402
import readers_4096_layouts as layouts  # noqa: E402

SIDE_M = h5b.SIDE_M


def st_topography(z):
    from SurfaceTopography import Topography
    # The peer indexes [x, y]; our map is (y, x).
    return Topography(np.ascontiguousarray(z.T), (SIDE_M, SIDE_M), unit="m")


def write_nc(path, z):
    st_topography(z).to_netcdf(path)
    return z


def write_gwy(path, z):
    st_topography(z).to_gwy(path)
    return z


def write_sdf(path, z):
    import struct
    ny, nx = z.shape
    head = struct.pack("<8s10s12s12sHHddddBBB", b"bISO-1.0", b"asperity", b"010120260000",
                       b"010120260000", nx, ny, SIDE_M / nx, SIDE_M / ny, 1.0, 1.0, 0, 7, 0)
    assert len(head) == 81
    with open(path, "wb") as f:
        f.write(head)
        f.write(np.ascontiguousarray(z, dtype="<f8").tobytes())
    return z


def write_tmd(path, z):
    import struct
    ny, nx = z.shape
    mm = (z * 1e3).astype("<f4")
    with open(path, "wb") as f:
        f.write(b"Binary TrueMap Data File v2.0\r\n\0")
        f.write(b"Created by TrueMap v6\r\n\0")
        f.write(struct.pack("<IIffff", nx, ny, SIDE_M * 1e3, SIDE_M * 1e3, 0.0, 0.0))
        f.write(mm.tobytes())
    return mm.astype(np.float64) * 1e-3


def write_bcrf(path, z):
    ny, nx = z.shape
    nm = (z * 1e9).astype("<f4")
    header = (f"fileformat = bcrf\nheadersize = 2048\nxpixels = {nx}\nypixels = {ny}\n"
              f"xlength = {SIDE_M * 1e9!r}\nylength = {SIDE_M * 1e9!r}\nxunit = nm\nyunit = nm\n"
              f"zunit = nm\nintelmode = 1\n").encode("ascii")
    with open(path, "wb") as f:
        f.write(header.ljust(2048, b" "))
        f.write(nm.tobytes())
    return nm.astype(np.float64) * 1e-9


def write_mi(path, z):
    """PicoView MI: text header (keys in 14 columns), one buffer, int32 samples stored from
    the bottom line up; a sample s stands for s · bufferRange / 2³¹ µm."""
    ny, nx = z.shape
    range_um = float(2.0 * np.abs(z).max() * 1e6)
    samples = np.round(z * 1e6 / range_um * 2**31).astype("<i4")
    lines = [("fileType", "Image"), ("xPixels", nx), ("yPixels", ny),
             ("xLength", repr(SIDE_M)), ("yLength", repr(SIDE_M)), ("scanUp", "TRUE"),
             ("bufferLabel", "Topography"), ("bufferRange", repr(range_um)),
             ("bufferUnit", "um"), ("data", "BINARY_32")]
    header = "".join(f"{k:<14}{v}\n" for k, v in lines).encode("ascii")
    with open(path, "wb") as f:
        f.write(header)
        f.write(samples[::-1].tobytes())
    return samples.astype(np.float64) * range_um / 2**31 * 1e-6


WRITERS = {"nc": write_nc, "gwy": write_gwy, "sdf": write_sdf, "tmd": write_tmd,
           "bcrf": write_bcrf, "mi": write_mi}


def make_files(a, z):
    """{kind: (path, the heights it holds in metres, (y, x))} for the kinds asked for."""
    wanted = a.formats.split(",")
    files = {}
    for kind in ("h5", "datx"):
        if kind in wanted:
            path = os.path.join(a.folder, f"r{a.n}.{kind}")
            (h5b.write_h5 if kind == "h5" else h5b.write_datx)(path, z)
            files[kind] = (path, z)
    if "x3p" in wanted or "x3p-deflated" in wanted:
        stored, deflated = h5b.write_x3p(a.asperity, a.folder, z)
        for kind, path in (("x3p", stored), ("x3p-deflated", deflated)):
            if kind in wanted:
                files[kind] = (path, z)
    if "sur" in wanted:
        path = os.path.join(a.folder, f"r{a.n}.sur")
        files["sur"] = (path, h5b.write_sur(path, z))
    for kind, write in WRITERS.items():
        if kind in wanted:
            path = os.path.join(a.folder, f"r{a.n}.{kind}")
            files[kind] = (path, write(path, z))
    rng = np.random.default_rng(2)
    for kind, write in layouts.WRITERS.items():
        if kind in wanted:
            path = os.path.join(a.folder, f"r{a.n}.{layouts.SUFFIX.get(kind, kind)}")
            files[kind] = (path, write(path, a.n, rng))
    return files


def ours(exe, path, out):
    """Runs the import; returns (CPU s, wall s, peak RSS MB) of that process, from
    /usr/bin/time (a child forked from this Python process would start its peak RSS from
    this process's size)."""
    args = [exe, "import", path, "--out", out, "--detrend", "none", "--force"]
    if path.endswith(".h5") or path.endswith(".nms"):
        args += ["--size", repr(SIDE_M)]  # the file gives none
    stats = out + ".time"
    t0 = time.perf_counter()
    p = subprocess.run(["/usr/bin/time", "-f", "%U %S %M", "-o", stats] + args,
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit(f"asperity import {path}: exit {p.returncode}: {p.stderr.decode()}")
    with open(stats) as f:
        user, system, rss_kb = f.read().split()[-3:]
    return float(user) + float(system), wall, float(rss_kb) / 1024


def peer(path):
    t0, c0 = time.perf_counter(), time.process_time()
    h = h5b.peer_read(path)
    return np.asarray(h), time.process_time() - c0, time.perf_counter() - t0


def check(kind, exe, path, want, out):
    """Both readings against the heights the file holds; returns None where the peer reads
    them too, else (why, whether the peer still reads the file: it is then timed)."""
    ours(exe, path, out)
    scale = np.abs(want).max()

    def same(got):
        return got.shape == want.shape and np.abs(got - want).max() <= 1e-12 * scale

    if not same(np.load(out)):
        sys.exit(f"{kind}: asperity's reading differs from the heights written")
    try:
        theirs, _, _ = peer(path)
    except Exception as e:  # noqa: BLE001 (any failure of the peer's reader is reported)
        return f"SurfaceTopography fails: {type(e).__name__}: {str(e)[:200]}", False
    theirs = np.asarray(theirs).T
    if not same(theirs):
        if theirs.shape != want.shape:
            return f"SurfaceTopography reads a {theirs.shape} map", True
        ratio = np.median(theirs[want != 0] / want[want != 0])
        return (f"SurfaceTopography's reading differs from the heights written: largest "
                f"difference {np.abs(theirs - want).max() / scale:.3g} of the largest height, "
                f"median ratio {ratio:.6g}"), True
    return None


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--asperity", required=True)
    p.add_argument("--n", type=int, default=4096)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--folder", default="/tmp/asperity-readers")
    p.add_argument("--out", help="where asperity writes its .npy (default: the folder)")
    p.add_argument("--formats", default="h5,datx,x3p,x3p-deflated,sur,nc,gwy,sdf,tmd,bcrf,mi,"
                   + ",".join(layouts.WRITERS))
    p.add_argument("--json", help="where to write the results (default: FOLDER/readers.json)")
    p.add_argument("--no-check", action="store_true", help="skip the readings' check (only "
                   "where a run with the same binary and --n has checked the same seeded files)")
    p.add_argument("--baseline", help="a second asperity binary (e.g. main's) timed in the "
                   "same rounds, interleaved, for a before/after comparison")
    a = p.parse_args()
    os.makedirs(a.folder, exist_ok=True)
    z = np.random.default_rng(1).standard_normal((a.n, a.n)) * 1e-6
    files = make_files(a, z)
    out = os.path.join(a.out or a.folder, "read.npy")
    peer_fails, peer_differs = {}, {}
    for kind, (path, want) in (files.items() if not a.no_check else ()):
        result = check(kind, a.asperity, path, want, out)
        if result:
            why, reads = result
            (peer_differs if reads else peer_fails)[kind] = why
            print(f"{kind}: {why}", flush=True)
    runs = {kind: {"ours_cpu": [], "ours_wall": [], "ours_rss_mb": [], "st_cpu": [],
                   "st_wall": [], "base_cpu": [], "base_wall": [], "base_rss_mb": []}
            for kind in files}
    loads = [os.getloadavg()[0]]
    for _ in range(a.repeat):
        for kind, (path, _) in files.items():
            cpu, wall, rss = ours(a.asperity, path, out)
            _, st_cpu, st_wall = (None, None, None) if kind in peer_fails else peer(path)
            r = runs[kind]
            if a.baseline:
                b_cpu, b_wall, b_rss = ours(a.baseline, path, out)
                r["base_cpu"].append(b_cpu)
                r["base_wall"].append(b_wall)
                r["base_rss_mb"].append(b_rss)
            r["ours_cpu"].append(cpu)
            r["ours_wall"].append(wall)
            r["ours_rss_mb"].append(rss)
            r["st_cpu"].append(st_cpu)
            r["st_wall"].append(st_wall)
        loads.append(os.getloadavg()[0])
        with open((a.json or os.path.join(a.folder, "readers.json")) + ".partial", "w") as f:
            json.dump({"runs": runs, "loadavg_1min": loads}, f)
    print("| 4096² file | MiB | asperity CPU / wall (median) | SurfaceTopography CPU / wall "
          "(median) | asperity peak RSS |")
    print("|---|---|---|---|---|")

    def med(xs):
        return f"{np.median(xs):.2f}"

    for kind, (path, _) in files.items():
        r = runs[kind]
        st = (f"{med(r['st_cpu'])} / {med(r['st_wall'])} s" if kind not in peer_fails
              else "does not read it") + (" (reads other heights)" if kind in peer_differs
                                          else "")
        base = (f" (baseline: {med(r['base_cpu'])} / {med(r['base_wall'])} s, "
                f"{max(r['base_rss_mb']):.0f} MB)" if a.baseline else "")
        print(f"| `{kind}` | {os.path.getsize(path) / 2**20:.0f} | {med(r['ours_cpu'])} / "
              f"{med(r['ours_wall'])} s | {st} | {max(r['ours_rss_mb']):.0f} MB |{base}",
              flush=True)
    print(f"load average (1 min) over the rounds: {min(loads):.1f}–{max(loads):.1f}")
    results = {"runs": runs, "peer_fails": peer_fails, "peer_differs": peer_differs, "sizes_mib": {k: os.path.getsize(p) / 2**20 for k, (p, _) in
                                          files.items()},
               "environment": {"date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                               "nproc": os.cpu_count(), "loadavg_1min": loads}}
    with open(a.json or os.path.join(a.folder, "readers.json"), "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
