"""Importing a 4096² measured topography: asperity against SurfaceTopography's read (issue 34,
item 4: "reads a 4096² file in under a second, benchmark beside SurfaceTopography").

The files are made here (in --folder: keep it out of the repository and of ../shared, e.g.
/tmp) from one seeded random map (float64, 4096 × 4096, metres):
  * `.h5`: one dataset `heights` (the generic HDF5 layout both tools read; no size in the file,
    both are given 1 mm);
  * `.datx`: the Zygo layout of crates/asperity/tests/data/make_datx.py (MetaData links,
    surface with Unit, No Data and X/Y/Z converters; variable-length strings);
  * `.x3p`: written by `asperity import MAP.npy --out MAP.x3p` (float64 payload, stored), and
    the same archive with every member deflated (bench/topography_peers.py's `deflate_zip`);
  * `.sur`: bench/topography_peers.py's one-object Digital Surf writer (int32 samples).
Both tools are first checked to read the same heights: bit for bit for `.h5`, `.datx` and
`.x3p` (both return the stored float64 numbers, ours indexed (y, x), the peer's [x, y]); for
`.sur`, both to the writer's quantised heights within 1e-12 relative.

Timed (`--repeat` interleaved rounds, minimum reported), both as wall time and as CPU time
(user + system: the process's own for asperity, from its rusage; the Python process's
`time.process_time()` for the peer), CPU time being the fairer measure on a machine whose
cores are shared with other work:
  * asperity: `asperity import FILE --out OUT.npy --detrend none --force` in a fresh process
    (read, check, write the 128 MiB .npy and its sidecar to the output folder);
  * SurfaceTopography 1.27.1: `open_topography(FILE).topography(...)` (`.to_unit("m")` where
    the file has a unit) then `.heights()`, in one Python process (import time excluded).
"""

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

SIDE_M = 1e-3


def write_h5(path, z):
    import h5py
    with h5py.File(path, "w") as f:
        # The peer's generic reader takes the first index along x: store z (y, x) transposed.
        f.create_dataset("heights", data=z.T)


def write_datx(path, z):
    import h5py
    text = h5py.string_dtype("utf-8")
    params = h5py.vlen_dtype(np.float64)
    conv = np.dtype([("Category", text), ("BaseUnit", text), ("Unit", text), ("Parameters", params)])
    meta = np.dtype([("Source", text), ("Link", text), ("Destination", text)])
    guid = "{5AD3C1B8-0000-4000-8000-00000000A5E1}"
    step = SIDE_M / z.shape[1]
    with h5py.File(path, "w") as f:
        rows = [("Root", "Measurement", "{M}"), ("{M}", "Surface", "{S}"),
                ("{S}", "Path", f"/Measurement/Surface/{guid}")]
        table = np.empty(len(rows), dtype=meta)
        for i, r in enumerate(rows):
            table[i] = r
        f.create_dataset("MetaData", data=table)
        ds = f.create_dataset(f"Measurement/Surface/{guid}", data=z)
        ds.attrs["Unit"] = np.array(["Meters"], dtype=text)
        ds.attrs["No Data"] = np.array([1.7976931348623157e308])

        def converter(category, base, unit, values):
            c = np.empty(1, dtype=conv)
            c[0] = (category, base, unit, np.array(values, dtype=np.float64))
            return c
        ds.attrs["X Converter"] = converter("LateralCat", "Pixels", "Meters", [0, step, 0, 0])
        ds.attrs["Y Converter"] = converter("LateralCat", "Pixels", "Meters", [0, step, 0, 0])
        ds.attrs["Z Converter"] = converter("HeightCat", "Meters", "Meters", [0, 1, 0, 0])


def write_x3p(exe, folder, z):
    """The stored and the deflated X3P of `z`, written from a `.npy` by asperity."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from topography_peers import deflate_zip
    npy = os.path.join(folder, f"r{z.shape[0]}.npy")
    np.save(npy, z)
    x3p = npy[:-4] + ".x3p"
    subprocess.run([exe, "import", npy, "--out", x3p, "--size", repr(SIDE_M), "--detrend", "none",
                    "--force"], check=True, capture_output=True)
    deflated = npy[:-4] + "-deflated.x3p"
    deflate_zip(x3p, deflated)
    os.remove(npy)
    return x3p, deflated


def write_sur(path, z):
    """The SUR of `z` and the heights it holds (quantised)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from topography_peers import write_sur as sur
    heights, _ = sur(z, SIDE_M, path)
    return heights


def peer_read(path):
    from SurfaceTopography import open_topography
    reader = open_topography(path)
    if path.endswith(".h5"):
        t = reader.topography(physical_sizes=(SIDE_M, SIDE_M))
    else:
        # In metres, as asperity writes them (the SUR file's heights are in µm).
        t = reader.topography().to_unit("m")
    return t.heights()


def ours(exe, path, out):
    """Runs the import; returns its CPU time (user + system) in seconds."""
    import resource
    args = [exe, "import", path, "--out", out, "--detrend", "none", "--force"]
    if path.endswith(".h5"):
        args += ["--size", repr(SIDE_M)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(args, check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--asperity", required=True)
    p.add_argument("--n", type=int, default=4096)
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--folder", default="bench/out")
    p.add_argument("--out", help="where asperity writes its .npy (default: the folder; a "
                   "tmpfs such as /dev/shm keeps the disk out of the timing)")
    p.add_argument("--formats", default="h5,datx,x3p,x3p-deflated,sur",
                   help="comma-separated, of h5, datx, x3p, x3p-deflated, sur")
    a = p.parse_args()
    os.makedirs(a.folder, exist_ok=True)
    z = np.random.default_rng(1).standard_normal((a.n, a.n)) * 1e-6
    wanted = a.formats.split(",")
    files, expected = {}, {}
    if "h5" in wanted:
        files["h5"] = os.path.join(a.folder, f"r{a.n}.h5")
        write_h5(files["h5"], z)
    if "datx" in wanted:
        files["datx"] = os.path.join(a.folder, f"r{a.n}.datx")
        write_datx(files["datx"], z)
    if "x3p" in wanted or "x3p-deflated" in wanted:
        stored, deflated = write_x3p(a.asperity, a.folder, z)
        for kind, path in (("x3p", stored), ("x3p-deflated", deflated)):
            if kind in wanted:
                files[kind] = path
    if "sur" in wanted:
        files["sur"] = os.path.join(a.folder, f"r{a.n}.sur")
        expected["sur"] = write_sur(files["sur"], z)
    out = os.path.join(a.out or a.folder, "read.npy")
    results = {}
    for kind, path in files.items():
        ours(a.asperity, path, out)
        mine = np.load(out)
        peer = np.asarray(peer_read(path))
        want = expected.get(kind, z)
        if kind in expected:
            scale = np.abs(want).max()
            same = bool(np.abs(mine - want).max() <= 1e-12 * scale
                        and np.abs(peer.T - want).max() <= 1e-12 * scale)
        else:
            same = np.array_equal(mine, peer.T) and np.array_equal(mine, want)
        if not same:
            sys.exit(f"{kind}: the two readings differ")
        wall = {"asperity": [], "SurfaceTopography": []}
        cpu = {"asperity": [], "SurfaceTopography": []}
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            cpu["asperity"].append(ours(a.asperity, path, out))
            wall["asperity"].append(time.perf_counter() - t0)
            t0, c0 = time.perf_counter(), time.process_time()
            peer_read(path)
            cpu["SurfaceTopography"].append(time.process_time() - c0)
            wall["SurfaceTopography"].append(time.perf_counter() - t0)
        best_wall = {k: min(v) for k, v in wall.items()}
        best_cpu = {k: min(v) for k, v in cpu.items()}
        results[kind] = {"file_mib": os.path.getsize(path) / 2**20, "identical_heights": same,
                         "best_wall_s": best_wall, "best_cpu_s": best_cpu,
                         "all_wall_s": wall, "all_cpu_s": cpu}
        print(f"{kind}: {os.path.getsize(path) / 2**20:.0f} MiB; wall: asperity "
              f"{best_wall['asperity']:.3f} s, SurfaceTopography {best_wall['SurfaceTopography']:.3f} s; "
              f"CPU: asperity {best_cpu['asperity']:.3f} s, SurfaceTopography "
              f"{best_cpu['SurfaceTopography']:.3f} s", flush=True)
    results["environment"] = {"date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                              "nproc": os.cpu_count(), "loadavg": os.getloadavg()}
    with open(os.path.join(a.folder, "hdf5_read.json"), "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
