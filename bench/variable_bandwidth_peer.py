"""asperity's variable-bandwidth analysis and scale-dependent slope against
SurfaceTopography's, on shared real files.

Runs `asperity stats FILE --detrend none --variable-bandwidth OUT.csv
--scale-dependent-slope OUT2.csv` and SurfaceTopography 1.27.1's
`variable_bandwidth_from_area` (maps) or `variable_bandwidth_from_profile` (profiles) and
`scale_dependent_slope_from_profile(resampling_method=None)` on the unlevelled topography
(in metres), and prints, per file, the largest relative differences.

    ASPERITY_BIN=target/release/asperity python bench/variable_bandwidth_peer.py \
        ../shared/topographies/tmd-1.tmd ../shared/topographies/x3p-2.x3p ...
"""
import csv
import os
import subprocess
import sys
import tempfile

import numpy as np
from SurfaceTopography import read_topography


def table(path, a, b):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return np.array([float(r[a]) for r in rows]), np.array([float(r[b]) for r in rows])


def ours(path, binary):
    with tempfile.TemporaryDirectory() as d:
        vb, sds = os.path.join(d, "vb.csv"), os.path.join(d, "sds.csv")
        subprocess.run([binary, "stats", path, "--detrend", "none", "--variable-bandwidth", vb,
                        "--scale-dependent-slope", sds], check=True, capture_output=True)
        return table(vb, "bandwidth", "rms_height"), table(sds, "distance", "slope")


def peer(path):
    t = read_topography(path)
    if t.unit is not None:
        t = t.to_unit("m")  # asperity works in metres
    slope = t.scale_dependent_slope_from_profile(resampling_method=None, reliable=False)
    if t.dim == 2:
        return t.variable_bandwidth_from_area(reliable=False), slope
    return t.variable_bandwidth_from_profile(reliable=False), slope


def main():
    binary = os.environ.get("ASPERITY_BIN", "target/release/asperity")
    for path in sys.argv[1:]:
        (b_ours, h_ours), (r_ours, s_ours) = ours(path, binary)
        (b_peer, h_peer), (r_peer, s_peer) = peer(path)
        if len(r_ours) == len(r_peer):
            ds = np.max(np.abs(s_ours - s_peer) / s_peer)
            dr = np.max(np.abs(r_ours - r_peer) / r_peer)
            print(f"{os.path.basename(path)}: scale-dependent slope at {len(r_ours)} distances "
                  f"≤ {ds:.1e} rel., distances ≤ {dr:.1e} rel.")
        else:
            print(f"{path}: {len(r_ours)} slope distances, the peer {len(r_peer)}")
        if len(b_ours) != len(b_peer):
            print(f"{path}: {len(b_ours)} bandwidths, the peer {len(b_peer)}")
            continue
        dh = np.max(np.abs(h_ours - h_peer) / h_peer)
        db = np.max(np.abs(b_ours - b_peer) / b_peer)
        print(f"{os.path.basename(path)}: {len(b_ours)} magnifications, rms height "
              f"≤ {dh:.1e} rel., bandwidth ≤ {db:.1e} rel.")


if __name__ == "__main__":
    main()
