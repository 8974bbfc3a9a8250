"""asperity's variable-bandwidth analysis against SurfaceTopography's, on shared real files.

Runs `asperity stats FILE --detrend none --variable-bandwidth OUT.csv` and SurfaceTopography
1.27.1's `variable_bandwidth_from_area` (maps) or `variable_bandwidth_from_profile`
(profiles) on the unlevelled topography, and prints, per file, the largest relative
difference of the rms heights and of the bandwidths.

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


def ours(path, binary):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "vb.csv")
        subprocess.run([binary, "stats", path, "--detrend", "none", "--variable-bandwidth", out],
                       check=True, capture_output=True)
        with open(out) as f:
            rows = list(csv.DictReader(f))
    return (np.array([float(r["bandwidth"]) for r in rows]),
            np.array([float(r["rms_height"]) for r in rows]))


def peer(path):
    t = read_topography(path)
    if t.unit is not None:
        t = t.to_unit("m")  # asperity works in metres
    if t.dim == 2:
        return t.variable_bandwidth_from_area(reliable=False)
    return t.variable_bandwidth_from_profile(reliable=False)


def main():
    binary = os.environ.get("ASPERITY_BIN", "target/release/asperity")
    for path in sys.argv[1:]:
        b_ours, h_ours = ours(path, binary)
        b_peer, h_peer = peer(path)
        if len(b_ours) != len(b_peer):
            print(f"{path}: {len(b_ours)} bandwidths, the peer {len(b_peer)}")
            continue
        dh = np.max(np.abs(h_ours - h_peer) / h_peer)
        db = np.max(np.abs(b_ours - b_peer) / b_peer)
        print(f"{os.path.basename(path)}: {len(b_ours)} magnifications, rms height "
              f"≤ {dh:.1e} rel., bandwidth ≤ {db:.1e} rel.")


if __name__ == "__main__":
    main()
