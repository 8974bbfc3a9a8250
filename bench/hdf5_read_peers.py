"""Reading a 4096² HDF5 (.h5) and Zygo .datx file: asperity against SurfaceTopography (issue 34,
item 4: "reads a 4096² file in under a second").

The files are made here with h5py from one seeded random map (float64, 4096 × 4096, metres):
  * `.h5`: one dataset `heights` (the generic HDF5 layout both tools read; no size in the file,
    both are given 1 mm);
  * `.datx`: the Zygo layout of crates/asperity/tests/data/make_datx.py (MetaData links,
    surface with Unit, No Data and X/Y/Z converters; variable-length strings).
Both tools are first checked to read the same heights (bit for bit: both return the stored
float64 numbers, ours indexed (y, x), the peer's [x, y]).

Timed (`--repeat` interleaved rounds, minimum reported), both as wall time and as CPU time
(user + system: the process's own for asperity, from its rusage; the Python process's
`time.process_time()` for the peer), CPU time being the fairer measure on a machine whose
cores are shared with other work:
  * asperity: `asperity import FILE --out OUT.npy --detrend none --force` in a fresh process
    (read, check, write the 128 MiB .npy and its sidecar to the output folder);
  * SurfaceTopography 1.27.1: `open_topography(FILE).topography(...)` then `.heights()`, in
    one Python process (import time excluded).
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


def peer_read(path):
    from SurfaceTopography import open_topography
    reader = open_topography(path)
    if path.endswith(".h5"):
        t = reader.topography(physical_sizes=(SIDE_M, SIDE_M))
    else:
        t = reader.topography()
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
    a = p.parse_args()
    os.makedirs(a.folder, exist_ok=True)
    z = np.random.default_rng(1).standard_normal((a.n, a.n)) * 1e-6
    files = {"h5": os.path.join(a.folder, f"r{a.n}.h5"), "datx": os.path.join(a.folder, f"r{a.n}.datx")}
    write_h5(files["h5"], z)
    write_datx(files["datx"], z)
    out = os.path.join(a.out or a.folder, "read.npy")
    results = {}
    for kind, path in files.items():
        ours(a.asperity, path, out)
        mine = np.load(out)
        peer = np.asarray(peer_read(path))
        same = np.array_equal(mine, peer.T) and np.array_equal(mine, z)
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
    with open(os.path.join(a.folder, "hdf5_read.json"), "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
