"""The PSD's convention and window: asperity's normalisation stated and tested (Parseval),
SurfaceTopography's convention reported on request and equal to SurfaceTopography's own
PSD on the shared measured files, with and without its Hann window; the CLI's --window and
--psd-convention give the same numbers."""

import json

import numpy as np
import pytest

import asperity

from test_topography import shared

ST = pytest.importorskip("SurfaceTopography")


def test_asperity_convention_integrates_to_the_rms_height():
    # Parseval on a line: Σ_k C1D(q_k) · 2π/L over both signs of q (no mean) = rms².
    line = asperity.line(1024, hurst=0.5, size=3.0, seed=1)
    p = asperity.psd(line)
    dq = 2 * np.pi / line.size
    total = 2 * p.psd[:-1].sum() * dq + p.psd[-1] * dq  # the Nyquist mode has one sign
    assert total == pytest.approx(np.var(line.heights), rel=1e-12)
    st = asperity.psd(line, convention="surface-topography")
    np.testing.assert_allclose(st.psd, 2 * np.pi * p.psd, rtol=1e-15)
    assert st.hurst == pytest.approx(p.hurst, abs=1e-12)  # the log of a scaled prefactor


def st_map(heights, sizes, periodic):
    # SurfaceTopography holds heights[x, y]; asperity (rows, cols) = (y, x).
    return ST.Topography(heights.T.copy(), physical_sizes=tuple(sizes), periodic=periodic)


@pytest.mark.parametrize("window", ["none", "hann"])
@pytest.mark.parametrize("name", ["x3p-2.x3p", "sdf-1.sdf"])
def test_map_psd_equals_surface_topography(name, window):
    t = asperity.read_topography(shared(name), detrend="plane", fill="harmonic")
    t.heights[...] -= t.heights.mean()  # SurfaceTopography windows the heights as they are
    ours = asperity.psd(t, window=window, convention="surface-topography")
    topo = st_map(t.heights, t.physical_sizes, periodic=(window == "none"))
    # The same rings: width 2π/Lx centred on whole q·Lx/2π (from 1).
    kappa = np.rint(ours.wavenumber).astype(int)
    edges = (np.arange(kappa[-1] + 1) + 0.5) * 2 * np.pi / t.size
    q, c = topo.power_spectrum_from_area(
        window=None if window == "none" else "hann", reliable=False, collocation=edges)
    c = np.ma.filled(c, np.nan)
    theirs = dict(zip(range(1, len(c) + 1), c))
    expected = np.array([theirs[k] for k in kappa])
    np.testing.assert_allclose(ours.psd, expected, rtol=1e-10)


@pytest.mark.parametrize("window", ["none", "hann"])
def test_profile_psd_equals_surface_topography(window):
    t = asperity.read_topography(shared("dektak-1.csv"), detrend="mean")
    ours = asperity.psd(t, window=window, convention="surface-topography")
    scan = ST.UniformLineScan(t.heights.copy(), physical_sizes=t.size,
                              periodic=(window == "none"))
    q, c = scan.power_spectrum_from_profile(
        window=None if window == "none" else "hann", reliable=False, resampling_method=None)
    # SurfaceTopography: k = 0 .. n/2 - 1; asperity: k = 1 .. n/2.
    n = len(c)
    np.testing.assert_allclose(ours.q[: n - 1], q[1:], rtol=1e-13)
    # Both are FFTs of the same windowed heights: the smallest values (1e-9 of the largest)
    # carry the largest's rounding, hence an absolute floor at 1e-13 of the largest.
    np.testing.assert_allclose(ours.psd[: n - 1], c[1:], rtol=1e-10, atol=1e-13 * c.max())


def test_the_cli_reports_the_same_spectrum(cli, tmp_path):
    path = shared("x3p-2.x3p")
    t = asperity.read_topography(path, detrend="plane")
    ours = asperity.psd(t, window="hann", convention="surface-topography")
    cli("stats", path, "--detrend", "plane", "--window", "hann",
        "--psd-convention", "surface-topography", "--psd", tmp_path / "psd.csv")
    table = np.genfromtxt(tmp_path / "psd.csv", delimiter=",", names=True)
    np.testing.assert_array_equal(table["psd"], ours.psd)
    out = cli("stats", path, "--detrend", "plane", "--window", "hann", "--psd-convention",
              "surface-topography", "--json").stdout
    assert json.loads(out)["psd_slope"] == ours.fit["exponent"]
    with pytest.raises(ValueError, match="window must be none or hann"):
        asperity.psd(t, window="hamming")
    bad = cli("stats", path, "--window", "hamming", ok=False)
    assert "--window must be none or hann" in bad.stderr
