"""Cross-check against ContactMechanics (PyPI), the peer that SurfaceTopography users solve
with: the same surface and load solved by both agree in area fraction and indentation to
1e-6, on free and periodic boundaries; a SurfaceTopography `Topography` goes straight into
`asperity.Solver`. Skipped when the peers are not installed (python/ci.sh installs them).

ContactMechanics is driven as bench/bem_peers.py drives it: its Polonsky–Keer solver
(`constrained_conjugate_gradients`) on the same heights, E* = 1, with the same tolerance
on the gaps (pentol = tol · h_rms) and the force prescribed."""

import numpy as np
import pytest

import asperity

ContactMechanics = pytest.importorskip("ContactMechanics")


def indentation_from(u, f, contact):
    """d from a peer's state: the mean of u + f over the contact set, with u's sign
    convention detected (bench/bem_peers.py)."""
    plus, minus = u[contact] + f[contact], -u[contact] + f[contact]
    return float(np.mean(plus)) if np.std(plus) <= np.std(minus) else float(np.mean(minus))


def peer_solve(heights, boundary, pressure, tol):
    from ContactMechanics import FreeFFTElasticHalfSpace, PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients

    rows, cols = heights.shape
    cls = FreeFFTElasticHalfSpace if boundary == "free" else PeriodicFFTElasticHalfSpace
    substrate = cls((rows, cols), 1.0, physical_sizes=(rows / cols, 1.0))
    area = rows / cols
    result = constrained_conjugate_gradients(
        substrate, heights, external_force=pressure * area, pentol=tol * float(np.std(heights)),
        forcetol=1e-12 * pressure * area / (rows * cols), thermotol=tol, maxiter=100000)
    assert result.success, result.message
    pixel_area = area / (rows * cols)
    pressure_field = np.asarray(result.jac) / pixel_area
    u = np.asarray(substrate.evaluate_disp(np.asarray(result.jac)))[:rows, :cols]
    contact = pressure_field > 0
    if boundary == "periodic":
        u = u - np.mean(u)  # periodic displacements: zero mean, as asperity's
    f = heights.max() - heights
    return float(np.mean(contact)), indentation_from(u, f, contact)


@pytest.mark.parametrize("boundary", ["free", "periodic"])
def test_area_fraction_and_indentation_agree_with_contactmechanics(boundary):
    s = asperity.surface(64, hurst=0.8, rolloff=4, rms_slope=1.0, seed=11)
    tol = 1e-10
    ours = asperity.Solver(s, boundary=boundary, tolerance=tol).solve(pressure=0.01)
    area, indentation = peer_solve(s.heights, boundary, 0.01, tol)
    print(f"{boundary}: area {ours.area_fraction} vs {area}, indentation {ours.indentation} vs {indentation}")
    assert abs(ours.area_fraction - area) <= 1e-6, (ours.area_fraction, area)
    assert abs(ours.indentation - indentation) <= 1e-6 * abs(indentation), (ours.indentation, indentation)


def test_a_surfacetopography_topography_is_accepted():
    SurfaceTopography = pytest.importorskip("SurfaceTopography")
    s = asperity.surface(64, m=32, hurst=0.8, rolloff=4, rms_slope=1.0, seed=2, size=2.0)
    # SurfaceTopography indexes heights [x, y] with physical_sizes (sx, sy).
    topography = SurfaceTopography.Topography(s.heights.T.copy(), physical_sizes=(2.0, 1.0))
    r = asperity.Solver(topography, boundary="periodic").solve(pressure=0.01)
    reference = asperity.Solver(s, boundary="periodic").solve(pressure=0.01)
    assert r.force == reference.force and r.indentation == reference.indentation
    assert np.array_equal(r.pressure, reference.pressure)
    # The rms height agrees with SurfaceTopography's own reading of the same heights.
    ours = asperity.stats(s)
    assert ours["rms_height"] == pytest.approx(topography.rms_height_from_area(), rel=1e-12)
