"""asperity's scale-dependent rms curvature (`stats --scale-dependent-curvature`) against
SurfaceTopography 1.27.1's `scale_dependent_statistical_property(n=2, scale_factor=s)` (the
rms of its x-derivative) on shared real files, unlevelled, in metres.

For a profile the two are the same definition. For a map the peer keeps only the points
where its y-stencil fits as well (it leaves out s rows at the top and bottom), asperity
pools every row; the script prints both the difference from the peer and from the
definition over every row (numpy, here).

    ASPERITY_BIN=target/release/asperity python bench/scale_dependent_curvature_peer.py \
        ../shared/topographies-3/mitutoyo_mock.xlsx ../shared/topographies/tmd-1.tmd ...
"""
import os
import subprocess
import sys
import tempfile

import numpy as np
from SurfaceTopography import open_topography
from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor


def main():
    binary = os.environ["ASPERITY_BIN"]
    for path in sys.argv[1:]:
        t = open_topography(path).topography()
        f = get_unit_conversion_factor(t.unit, "m")
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "c.csv")
            subprocess.run([binary, "stats", path, "--detrend", "none",
                            "--scale-dependent-curvature", out], check=True, capture_output=True)
            rows = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
        px = t.physical_sizes[0] / t.nb_grid_pts[0]  # file unit
        h = t.heights()
        lines = h.T if t.dim == 2 else h[None, :]
        worst_peer = worst_def = worst_crop = 0.0
        factors = []
        for r, c in rows:
            s = int(round(r / (2 * px * f)))
            factors.append(s)
            _, v = t.scale_dependent_statistical_property(
                lambda x, y=None: np.mean(x * x), n=2, scale_factor=s)
            peer = np.sqrt(v) * f / f**2  # heights × f, lengths × f: curvature × 1/f
            d2 = (lines[:, 2 * s:] - 2 * lines[:, s:-s] + lines[:, :-2 * s]) / (s * px) ** 2
            mine = np.sqrt(np.mean(d2 * d2)) / f
            worst_peer = max(worst_peer, abs(c - peer) / peer)
            worst_def = max(worst_def, abs(c - mine) / mine)
            # The peer's own definition on a map: only rows s..ny−s (its y-stencil fits).
            cropped = d2[s:-s] if t.dim == 2 else d2
            crop = np.sqrt(np.mean(cropped * cropped)) / f
            worst_crop = max(worst_crop, abs(peer - crop) / crop)
        print(f"{os.path.basename(path)}: scale factors {factors}; largest relative difference "
              f"from SurfaceTopography {worst_peer:.1e}, from the definition over every row "
              f"{worst_def:.1e}; the peer from the definition over its rows s..ny-s {worst_crop:.1e}")


if __name__ == "__main__":
    main()
