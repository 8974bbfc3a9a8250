"""Issue 33, item 11: stats and psd of an array whose copy cannot fit (a broadcast array of
a few bytes standing for terabytes), also under an address-space limit (ulimit -v), raise
MemoryError instead of aborting the interpreter. Item 5: statistics of heights in any
units are the statistics of the heights times the factor, or a ValueError; never inf or 0."""

import subprocess
import sys

import numpy as np
import pytest

import asperity


def test_stats_and_psd_of_a_huge_broadcast_array_raise_memory_error():
    huge = np.broadcast_to(np.float64(1.5), (1_000_000, 1_000_000))  # 8 TB once copied
    with pytest.raises(MemoryError):
        asperity.stats(huge, size=1.0)
    with pytest.raises(MemoryError):
        asperity.psd(huge, size=1.0)


LIMITED = """
import resource, numpy as np, asperity
in_use = int([l for l in open('/proc/self/status') if l.startswith('VmSize')][0].split()[1]) * 1024
resource.setrlimit(resource.RLIMIT_AS, (in_use + (1 << 30), resource.RLIM_INFINITY))
big = np.broadcast_to(np.float64(1.5), (20000, 20000))  # 3.2 GB once copied
for f in (asperity.stats, asperity.psd):
    try:
        f(big, size=1.0)
    except MemoryError:
        print("MemoryError")
"""


def test_under_an_address_space_limit_a_large_copy_is_refused_not_aborted():
    out = subprocess.run([sys.executable, "-c", LIMITED], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    assert out.stdout.split() == ["MemoryError", "MemoryError"], out.stdout


def test_statistics_of_heights_in_extreme_units_scale_or_are_refused():
    rng = np.random.default_rng(4)
    h = rng.standard_normal((32, 32))
    reference = asperity.stats(h, size=1.0)
    for factor in (1e100, 1e-100):
        got = asperity.stats(h * factor, size=1.0)
        for key in ("rms_height", "rms_slope", "rms_curvature"):
            assert got[key] / factor == pytest.approx(reference[key], rel=1e-13), key
    # Beyond, the PSD (height² × length²) leaves float64: stats, which fits it, and psd
    # refuse, as `asperity stats` does.
    for factor in (1e200, 1e-170):
        for f in (asperity.stats, asperity.psd):
            with pytest.raises(ValueError, match="beyond the range"):
                f(h * factor, size=1.0)
