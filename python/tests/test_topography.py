"""Measured topographies through the front-end layer's one call: Python reads what
`asperity import` reads (heights bit for bit, sizes, provenance), levels and fills as the
CLI does and warns where it warns, bad files raise the CLI's one-line error, a measured map
with rectangular pixels goes straight to the Solver, and its statistics are the CLI's and
SurfaceTopography's."""

import json
import os
from pathlib import Path

import numpy as np
import pytest

import asperity

from conftest import REPO, cli_error

SHARED = Path(os.environ.get("ASPERITY_TOPOGRAPHIES", REPO.parent / "shared" / "topographies"))
FILES = ["x3p-2.x3p", "sur-2.sur", "sdf-1.sdf", "gwyddion-export-english.txt", "dektak-1.csv"]


def shared(name):
    path = SHARED / name
    if not path.exists():
        # CI has the shared files beside the repository: a skip there would hide a gap.
        if os.environ.get("CI"):
            pytest.fail(f"{path} not found, and CI needs the shared test files")
        pytest.skip(f"{path} not found (set ASPERITY_TOPOGRAPHIES)")
    return path


@pytest.mark.parametrize("name", FILES)
def test_python_reads_what_the_cli_imports(cli, tmp_path, name):
    path = shared(name)
    t = asperity.read_topography(path, detrend="none")
    out = tmp_path / "t.npy"
    undefined = np.isnan(t.heights)
    # The CLI refuses undefined points unless they are filled; filling keeps the others.
    fill = ["--fill", "harmonic"] if undefined.any() else []
    cli("import", path, "--out", out, "--detrend", "none", *fill)
    imported = np.load(out)
    sidecar = json.loads(Path(f"{out}.json").read_text())
    assert t.heights.dtype == np.float64 and t.heights.shape == imported.shape
    np.testing.assert_array_equal(t.heights[~undefined], imported[~undefined])
    assert list(t.physical_sizes) == sidecar["sizes"], (t.physical_sizes, sidecar["sizes"])
    assert t.provenance["format"] == sidecar["format"]
    assert t.provenance["source"].endswith(name)


def test_sizes_can_be_given_and_bad_files_raise_the_cli_line(cli, tmp_path):
    path = shared("x3p-2.x3p")
    t = asperity.read_topography(path, size=(2e-3, 1e-3))
    assert (t.size, t.size_y) == (2e-3, 1e-3)
    assert t.provenance["size_source"] == "given"
    bad = tmp_path / "bad.x3p"
    bad.write_bytes(path.read_bytes()[:200])
    with pytest.raises(ValueError) as python_error:
        asperity.read_topography(bad)
    message = cli_error(cli("stats", bad, ok=False))
    assert str(python_error.value) == message
    with pytest.raises(ValueError, match="size must be positive"):
        asperity.read_topography(path, size=-1.0)


def test_a_measured_map_with_rectangular_pixels_goes_to_the_solver(cli, tmp_path):
    t = asperity.read_topography(shared("x3p-2.x3p"))
    assert t.heights.ndim == 2 and not np.isnan(t.heights).any()
    rows, cols = t.heights.shape
    assert abs(t.size / cols - t.size_y / rows) > 1e-3 * t.size / cols, "square pixels"
    solver = asperity.Solver(t, modulus=1.0)
    result = solver.solve(pressure=1e-3)
    out = tmp_path / "bem.csv"
    cli("bem", "--surface", shared("x3p-2.x3p"), "--pressures", 1e-3, "--no-stiffness",
        "--quiet", "--out", out)
    header, row = out.read_text().splitlines()[:2]
    values = {k: float(v) for k, v in zip(header.split(","), row.split(",")) if v}
    assert result.area_fraction == values["area_fraction"]
    assert result.indentation == values["indentation"]


# ------------------------------------------- statistics on rectangular pixels (issue 36)


def test_stats_on_rectangular_pixels_equal_the_cli(cli):
    """Python's stats of a measured map with rectangular pixels are the CLI's, bit for bit
    (one code path); given the heights with one size, pixels are square by definition and
    the numbers differ, which is why the Topography (or size=(x, y)) must be passed."""
    path = shared("x3p-2.x3p")
    report = json.loads(cli("stats", path, "--json").stdout)
    t = asperity.read_topography(path)
    ours = asperity.stats(t)
    for key, value in report["stats"].items():
        assert ours[key] == value, key
    for key in ("psd_slope", "psd_slope_low", "psd_slope_high", "fit_from", "fit_to",
                "hurst_estimate", "iso"):
        assert ours[key] == report[key], key
    assert ours["rms_curvature"] is not None
    # size=(x, y) with the bare heights is the same request.
    assert asperity.stats(t.heights, size=t.physical_sizes) == ours
    spectrum = asperity.psd(t)
    assert spectrum.fit["exponent"] == report["psd_slope"]
    square = asperity.stats(t.heights, size=t.size)
    assert square["rms_slope"] > 1.3 * ours["rms_slope"], "the drift issue 36 reported"


def test_rms_slope_and_curvature_per_axis_equal_surface_topography():
    """Against SurfaceTopography 1.27 on the measured map with rectangular pixels
    (Δy/Δx = 2.46): along each axis alone (the map's own rows, or columns, repeated, so
    that only that axis' spacing enters), and on the whole map."""
    ST = pytest.importorskip("SurfaceTopography")
    t = asperity.read_topography(shared("x3p-2.x3p"))
    rows, cols = t.heights.shape
    along_x = np.tile(t.heights[rows // 2], (rows, 1))           # varies along x only
    along_y = np.tile(t.heights[:, cols // 2][:, None], (1, cols))  # along y only
    for h in (along_x, along_y, t.heights):
        theirs = ST.Topography(h.T.copy(), physical_sizes=t.physical_sizes, periodic=False)
        ours = asperity.stats(h, size=t.physical_sizes)
        # Half the rms five-point Laplacian on the interior points: the same definition.
        assert ours["rms_curvature"] == pytest.approx(theirs.rms_curvature_from_area(), rel=1e-12)
        if h is along_x:
            assert ours["rms_slope"] == pytest.approx(theirs.rms_slope_from_profile(), rel=1e-12)
        elif h is along_y:
            flipped = ST.Topography(h.copy(), physical_sizes=t.physical_sizes[::-1], periodic=False)
            assert ours["rms_slope"] == pytest.approx(flipped.rms_slope_from_profile(), rel=1e-12)
        else:
            # SurfaceTopography averages both differences over the same (rows-1)×(cols-1)
            # cells, asperity each over all its pairs: one row or column of 650 apart.
            assert ours["rms_slope"] == pytest.approx(theirs.rms_gradient(), rel=2e-3)
    whole = asperity.stats(t)
    assert whole["rms_curvature"] == asperity.stats(t.heights, size=t.physical_sizes)["rms_curvature"]


def test_sdq_and_sdr_on_rectangular_pixels_are_iso_25178s_cell_gradients(cli):
    """Issue 36 item 2, Sdq and Sdr: on the measured map with rectangular pixels (Δy/Δx =
    2.46), ISO 25178-2's discrete definitions, written out here in numpy (the gradient of
    each cell as the mean of its two edge differences per axis, each divided by its own
    spacing; Sdq the rms of its length, Sdr the mean of √(1 + |∇z|²) − 1), are asperity's,
    the CLI's and Python's alike. SurfaceTopography has no Sdr; its rms gradient (forward
    differences) is within 2 % of the cell-centred Sdq. Read with one size (square pixels)
    the map's Sdq would be far off: the wrong number of issue 36."""
    path = shared("x3p-2.x3p")
    t = asperity.read_topography(path, detrend="plane")
    h = t.heights
    dx, dy = t.size / h.shape[1], t.size_y / h.shape[0]
    assert dy / dx > 2
    gx = (h[:-1, 1:] - h[:-1, :-1] + h[1:, 1:] - h[1:, :-1]) / (2 * dx)
    gy = (h[1:, :-1] - h[:-1, :-1] + h[1:, 1:] - h[:-1, 1:]) / (2 * dy)
    sdq = np.sqrt(np.mean(gx**2 + gy**2))
    sdr = np.mean(np.sqrt(1 + gx**2 + gy**2) - 1)
    iso = asperity.stats(t)["iso"]
    assert iso["sdq"] == pytest.approx(sdq, rel=1e-12)
    assert iso["sdr"] == pytest.approx(sdr, rel=1e-12)
    report = json.loads(cli("stats", path, "--detrend", "plane", "--json").stdout)
    assert (report["iso"]["sdq"], report["iso"]["sdr"]) == (iso["sdq"], iso["sdr"])
    ST = pytest.importorskip("SurfaceTopography")
    theirs = ST.Topography(h.T.copy(), physical_sizes=t.physical_sizes, periodic=False)
    assert iso["sdq"] == pytest.approx(theirs.rms_gradient(), rel=2e-2)
    square = (h[:-1, 1:] - h[:-1, :-1] + h[1:, 1:] - h[1:, :-1]) / (2 * dx), \
        (h[1:, :-1] - h[:-1, :-1] + h[1:, 1:] - h[:-1, 1:]) / (2 * dx)
    assert np.sqrt(np.mean(square[0]**2 + square[1]**2)) > 1.3 * iso["sdq"]


def tilted_text_map(tmp_path):
    """A tilted map in a text matrix (no unit, no size in the file)."""
    rng = np.random.default_rng(5)
    y, x = np.mgrid[0:40, 0:50]
    path = tmp_path / "tilted.txt"
    np.savetxt(path, 1e-6 * (0.05 * x + 0.02 * y) + 1e-8 * rng.standard_normal((40, 50)))
    return path


def test_unlevelled_data_warn_in_python_as_in_the_cli(cli, tmp_path):
    path = tilted_text_map(tmp_path)
    err = cli("stats", path, "--size", "5e-5,4e-5").stderr
    theirs = [l[len("warning: "):].replace("--detrend", "detrend")
              for l in err.splitlines() if l.startswith("warning: ")]
    with pytest.warns(asperity.AsperityWarning) as caught:
        asperity.read_topography(path, size=(5e-5, 4e-5))
    assert [str(w.message) for w in caught] == theirs
    assert [w.category for w in caught] == [asperity.UnlevelledWarning, asperity.UnitWarning]
    assert "looks tilted" in theirs[0] and "(choose detrend)" in theirs[0]
    # A chosen levelling removes the tilt and the warning; the category can be filtered.
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error", asperity.UnlevelledWarning)
        warnings.simplefilter("ignore", asperity.UnitWarning)
        t = asperity.read_topography(path, size=(5e-5, 4e-5), detrend="plane")
        with pytest.raises(asperity.UnlevelledWarning):
            asperity.read_topography(path, size=(5e-5, 4e-5))
    report = json.loads(cli("stats", path, "--size", "5e-5,4e-5", "--detrend", "plane",
                            "--json").stdout)
    assert t.provenance["cleaning"] == report["measured"]["cleaning"] != []
    assert asperity.stats(t)["rms_slope"] == report["stats"]["rms_slope"]


def test_filling_undefined_points_is_the_cli_s(cli, tmp_path):
    path = shared("x3p-2.x3p")
    t = asperity.read_topography(path, detrend="plane", fill="harmonic")
    report = json.loads(cli("stats", path, "--detrend", "plane", "--fill", "harmonic",
                            "--json").stdout)
    assert t.provenance["cleaning"] == report["measured"]["cleaning"]
    assert asperity.stats(t)["iso"] == report["iso"]


@pytest.mark.parametrize("name,detrend,prefix", [
    ("x3p-2.x3p", "plane", "s"),        # a map: ISO 25178-2
    ("sur-2.sur", "poly2", "s"),
    ("dektak-1.csv", "mean", "r"),      # a profile: ISO 4287
    ("dektak-1.csv", "plane", "r"),
])
def test_iso_parameters_of_maps_and_profiles_equal_the_cli(cli, name, detrend, prefix):
    """Issue 36 item 1: the ISO parameters are one call in both front ends, after the same
    levelling: Sa/Sq/Ssk/Sku/Sz/Sdq/Sdr of a map, Ra/Rq/Rsk/Rku/Rz/Rdq of a profile, bit
    for bit (the CLI's --json against asperity.stats of the Topography)."""
    path = shared(name)
    fill = ["--fill", "harmonic"] if name == "sur-2.sur" else []
    report = json.loads(cli("stats", path, "--detrend", detrend, *fill, "--json").stdout)
    t = asperity.read_topography(path, detrend=detrend,
                                 fill="harmonic" if fill else None)
    ours = asperity.stats(t)
    assert report["iso"], "the CLI reports ISO parameters for a measured file"
    names = {"s": ["sa", "sq", "ssk", "sku", "sz", "sdq", "sdr"],
             "r": ["ra", "rq", "rsk", "rku", "rz", "rdq"]}[prefix]
    assert sorted(report["iso"]) == sorted(names)
    assert ours["iso"] == report["iso"]
    assert ours["iso"][prefix + "q"] > 0
    assert t.provenance["cleaning"] == report["measured"]["cleaning"]


@pytest.mark.parametrize("name,flags,kwargs,ext", [
    ("x3p-2.x3p", ["--detrend", "plane"], dict(detrend="plane"), "npy"),
    ("sur-2.sur", ["--detrend", "lines", "--fill", "harmonic"],
     dict(detrend="lines", fill="harmonic"), "npy"),
    ("gwyddion-export-english.txt", ["--detrend", "poly2", "--size", "1e-5,2e-5"],
     dict(detrend="poly2", size=(1e-5, 2e-5)), "x3p"),
    ("dektak-1.csv", ["--detrend", "mean"], dict(detrend="mean"), "npy"),
])
def test_import_topography_writes_what_the_cli_imports(cli, tmp_path, name, flags, kwargs, ext):
    """The one writer (asperity_app::import): the same heights, X3P and sidecar, byte for
    byte, and the same refusals."""
    path = shared(name)
    cli("import", path, "--out", tmp_path / f"cli.{ext}", *flags)
    t = asperity.import_topography(path, tmp_path / f"py.{ext}", **kwargs)
    assert (tmp_path / f"py.{ext}").read_bytes() == (tmp_path / f"cli.{ext}").read_bytes()
    if ext == "npy":
        theirs = (tmp_path / "cli.npy.json").read_bytes()
        assert (tmp_path / "py.npy.json").read_bytes() == theirs
        assert np.array_equal(np.load(tmp_path / "py.npy"), t.heights)
        assert json.loads(theirs)["sizes"] == list(t.physical_sizes)
    # An existing output is refused, as by the CLI, unless forced.
    theirs = cli_error(cli("import", path, "--out", tmp_path / f"cli.{ext}", *flags, ok=False))
    with pytest.raises(ValueError) as err:
        asperity.import_topography(path, tmp_path / f"py.{ext}", **kwargs)
    # The same words but for how each front end says to overwrite (--force, force=True).
    assert str(err.value).split(" (")[0] == theirs.replace("cli.", "py.").split(" (")[0]
    asperity.import_topography(path, tmp_path / f"py.{ext}", force=True, **kwargs)


def test_import_topography_refuses_as_the_cli(cli, tmp_path):
    path = shared("x3p-2.x3p")
    theirs = cli_error(cli("import", path, "--out", tmp_path / "t.csv", ok=False))
    with pytest.raises(ValueError) as err:
        asperity.import_topography(path, tmp_path / "t.csv")
    assert str(err.value) == theirs.replace("--out", "out")
    # A profile cannot be an X3P file; nothing is written.
    with pytest.raises(ValueError, match="a line profile cannot be written as X3P"):
        asperity.import_topography(shared("dektak-1.csv"), tmp_path / "p.x3p", detrend="mean")
    assert list(tmp_path.iterdir()) == []


def test_a_channel_name_two_channels_share_raises_and_an_index_chooses():
    # di-2.di (topographies-2) holds "Height", "Height" and "Deflection": the name is
    # ambiguous, so read_topography raises the CLI's words; the indices give two distinct
    # maps, the first being the default's (as crates/asperity-cli/tests/topography_cli.rs).
    path = shared("../topographies-2/di-2.di")
    with pytest.raises(ValueError, match=r'2 channels are named "Height" \(0: Height, 1: Height\)'):
        asperity.read_topography(path, channel="Height")
    first = asperity.read_topography(path, channel=0, detrend="none")
    second = asperity.read_topography(path, channel=1, detrend="none")
    default = asperity.read_topography(path, detrend="none")
    np.testing.assert_array_equal(first.heights, default.heights)
    assert first.heights.shape == second.heights.shape
    assert not np.array_equal(first.heights, second.heights)
