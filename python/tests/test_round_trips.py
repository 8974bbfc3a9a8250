"""Round trips: everything asperity saves loads back as the same object (heights bit for
bit, sizes, metadata and provenance), in the field's formats (.npy + JSON sidecar, .npz +
sidecar, X3P), and what Python writes is what the CLI writes and reads."""

import json
from pathlib import Path

import numpy as np
import pytest

import asperity

from test_topography import shared


def test_a_saved_surface_is_read_back_with_its_size(cli, tmp_path):
    # The bug: read_topography refused Surface.save's file ("carries no physical size")
    # although the sidecar records spec.size; a 16 x 32 map of side 2 is 2 x 1.
    s = asperity.surface(32, m=16, hurst=0.8, size=2.0, seed=5)
    s.save(tmp_path / "s.npy")
    t = asperity.read_topography(tmp_path / "s.npy", detrend="none")
    assert (t.size, t.size_y) == (2.0, 1.0)
    np.testing.assert_array_equal(t.heights, s.heights)
    back = asperity.load(tmp_path / "s.npy")
    assert isinstance(back, asperity.Surface)
    np.testing.assert_array_equal(back.heights, s.heights)
    assert (back.size, back.metadata) == (s.size, s.metadata)
    # The CLI reads it too: its import gives the same heights and both sizes.
    cli("import", tmp_path / "s.npy", "--out", tmp_path / "i.npy", "--detrend", "none")
    sidecar = json.loads((tmp_path / "i.npy.json").read_text())
    assert sidecar["sizes"] == [2.0, 1.0]
    np.testing.assert_array_equal(np.load(tmp_path / "i.npy"), s.heights)


def test_a_saved_line_loads_back(tmp_path):
    line = asperity.line(256, hurst=0.5, size=3.0, seed=2)
    line.save(tmp_path / "l.npy")
    back = asperity.load(tmp_path / "l.npy")
    assert isinstance(back, asperity.Line)
    np.testing.assert_array_equal(back.heights, line.heights)
    assert (back.size, back.metadata) == (line.size, line.metadata)


@pytest.mark.parametrize("name,detrend", [("x3p-2.x3p", "plane"), ("dektak-1.csv", "mean")])
def test_topography_save_is_the_cli_import(cli, tmp_path, name, detrend):
    path = shared(name)
    t = asperity.read_topography(path, detrend=detrend)
    t.save(tmp_path / "py.npy")
    cli("import", path, "--out", tmp_path / "cli.npy", "--detrend", detrend)
    assert (tmp_path / "py.npy").read_bytes() == (tmp_path / "cli.npy").read_bytes()
    ours = json.loads((tmp_path / "py.npy.json").read_text())
    theirs = json.loads((tmp_path / "cli.npy.json").read_text())
    assert ours == theirs
    back = asperity.load(tmp_path / "py.npy")
    np.testing.assert_array_equal(back.heights, t.heights)
    assert back.physical_sizes == t.physical_sizes
    assert back.provenance == t.provenance
    # Read as a measured file, it keeps its sizes and its cleaning.
    again = asperity.read_topography(tmp_path / "py.npy", detrend="none")
    assert again.physical_sizes == t.physical_sizes
    assert again.provenance["cleaning"][: len(t.provenance["cleaning"])] == t.provenance["cleaning"]


def test_x3p_export_reads_back_bit_for_bit(cli, tmp_path):
    t = asperity.read_topography(shared("x3p-2.x3p"), detrend="plane")
    t.save(tmp_path / "py.x3p")
    cli("import", shared("x3p-2.x3p"), "--out", tmp_path / "cli.x3p", "--detrend", "plane")
    assert (tmp_path / "py.x3p").read_bytes() == (tmp_path / "cli.x3p").read_bytes()
    back = asperity.load(tmp_path / "py.x3p")
    np.testing.assert_array_equal(back.heights, t.heights)
    np.testing.assert_allclose(back.physical_sizes, t.physical_sizes, rtol=1e-15)
    assert back.provenance["format"] == "x3p"
    # A generated surface exports too (square pixels: y from x).
    s = asperity.surface(16, m=8, hurst=0.5, size=4e-6, seed=1)
    s.save(tmp_path / "s.x3p")
    g = asperity.load(tmp_path / "s.x3p")
    np.testing.assert_array_equal(g.heights, s.heights)
    np.testing.assert_allclose(g.physical_sizes, (4e-6, 2e-6), rtol=1e-15)


def test_a_profile_is_refused_as_x3p_and_nothing_is_written(tmp_path):
    t = asperity.read_topography(shared("dektak-1.csv"), detrend="mean")
    with pytest.raises(ValueError, match="cannot be written as X3P"):
        t.save(tmp_path / "p.x3p")
    with pytest.raises(ValueError, match="must end in .npy or .x3p"):
        t.save(tmp_path / "p.txt")
    assert list(tmp_path.iterdir()) == []


def test_sweeps_and_contact_results_load_back_identical(tmp_path):
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_slope=1.0, seed=4)
    solver = asperity.Solver(s, boundary="periodic")
    sweep = solver.sweep(nloads=3, pmin=1e-3, pmax=1e-2, fields=True, fd_stiffness=True)
    sweep.save(tmp_path / "sweep.npz")
    back = asperity.load(tmp_path / "sweep.npz")
    assert list(back.columns) == list(sweep.columns)
    for name, value in sweep.columns.items():
        if isinstance(value, list):
            assert len(back[name]) == len(value)
            for a, b in zip(back[name], value):
                np.testing.assert_array_equal(a, b)
        else:
            assert back[name].dtype == value.dtype, name
            np.testing.assert_array_equal(back[name], value)
    assert back.metadata == sweep.metadata
    assert back.metadata["surface"]["sidecar"]["seed"] == 4
    assert len(back.metadata["surface"]["heights_sha256"]) == 64

    result = solver.solve(pressure=5e-3)
    result.save(tmp_path / "r.npz")
    again = asperity.load(tmp_path / "r.npz")
    for name in ("force", "mean_pressure", "indentation", "area_fraction",
                 "contact_points", "iterations", "residual"):
        assert getattr(again, name) == getattr(result, name), name
    for name in ("pressure", "gap", "displacement"):
        np.testing.assert_array_equal(getattr(again, name), getattr(result, name))
    assert again.metadata == result.metadata
    assert again.metadata["load"] == {"quantity": "pressure", "value": 5e-3}


def test_contact_sweeps_carry_their_request(tmp_path):
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_height=1e-6, size=1e-4, seed=1)
    c = asperity.contact(s, young=210e9, poisson=0.3, pressures=[1e5, 1e6], boundary="periodic")
    c.save(tmp_path / "c.npz")
    back = asperity.load(tmp_path / "c.npz")
    np.testing.assert_array_equal(back.contact_area_m2, c.contact_area_m2)
    assert back.metadata == c.metadata and back.metadata["contact"]["young"] == 210e9


def test_outputs_are_not_overwritten_unless_forced(tmp_path):
    sweep = asperity.Solver(asperity.surface(16, hurst=0.8, seed=1)).sweep(
        nloads=2, pmin=1e-3, pmax=1e-2)
    sweep.save(tmp_path / "a.npz")
    before = (tmp_path / "a.npz").read_bytes()
    with pytest.raises(ValueError, match="exists"):
        sweep.save(tmp_path / "a.npz")
    assert (tmp_path / "a.npz").read_bytes() == before
    sweep.save(tmp_path / "a.npz", force=True)
    with pytest.raises(ValueError, match="must end in .npz"):
        sweep.save(tmp_path / "a.npy")


def test_a_study_result_loads_back_identical(tmp_path):
    r = asperity.study_alpha(method="mdr", n=[256], hurst=[0.5], samples=4,
                             out=tmp_path / "study")
    r.save(tmp_path / "r.npz")
    back = asperity.load(tmp_path / "r.npz")
    assert list(back.columns) == list(r.columns)
    for name, value in r.columns.items():
        assert back[name].dtype == value.dtype, name
        assert list(back[name]) == list(value) or np.array_equal(back[name], value, equal_nan=True)
    assert (back.rows, back.tasks, back.comparisons) == (r.rows, r.tasks, r.comparisons)
    assert back.metadata == r.metadata and back.metadata["spec"] is not None
    assert len(repr(back)) < 300, repr(back)
