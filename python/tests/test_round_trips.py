"""Round trips: everything asperity saves loads back as the same object (heights bit for
bit, sizes, metadata and provenance), in the field's formats (.npy + JSON sidecar, .npz +
sidecar, X3P), and what Python writes is what the CLI writes and reads."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import asperity

from conftest import cli_error, cli_path
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


def _same_columns(back, saved):
    """Every column of a loaded sweep is the saved one: same names in the same order,
    same dtype, same values bit for bit (lists of fields element by element)."""
    assert list(back.columns) == list(saved.columns)
    for name, value in saved.columns.items():
        if isinstance(value, list):
            assert len(back[name]) == len(value), name
            for a, b in zip(back[name], value):
                assert a.dtype == b.dtype, name
                np.testing.assert_array_equal(a, b)
        elif isinstance(value, np.ndarray):
            assert back[name].dtype == value.dtype, name
            assert back[name].shape == value.shape, name
            np.testing.assert_array_equal(back[name], value)
        else:
            assert back[name] == value and type(back[name]) is type(value), name
    assert back.metadata == saved.metadata


def test_contact_fields_load_back_identical(tmp_path):
    """The contact fields (issue 36 item 3): pressure, gap, displacement and the plastic
    displacement of a capped solve; the field stacks of a sweep; a load path's permanent
    displacement and branch names; an SI contact's contact set, patch labels and patch
    areas. Each saved (.npz of .npy arrays + JSON sidecar) and loaded back identical."""
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_slope=1.0, seed=4)
    capped = asperity.Solver(s, boundary="periodic", hardness=0.3)
    result = capped.solve(pressure=0.03)
    assert result.plastic_points > 0 and result.plastic_displacement.max() > 0
    result.save(tmp_path / "r.npz")
    back = asperity.load(tmp_path / "r.npz")
    assert isinstance(back, asperity.ContactResult)
    for name in ("pressure", "gap", "displacement", "plastic_displacement"):
        saved, loaded = getattr(result, name), getattr(back, name)
        assert loaded.dtype == saved.dtype and loaded.shape == (32, 32), name
        np.testing.assert_array_equal(loaded, saved)
    for name in ("force", "mean_pressure", "indentation", "area_fraction", "contact_points",
                 "iterations", "residual", "plastic_fraction", "plastic_points"):
        assert getattr(back, name) == getattr(result, name), name
    assert back.metadata == result.metadata and back.metadata["solver"]["hardness"] == 0.3

    sweep = capped.sweep(pressures=[0.01, 0.03], fields=True)
    sweep.save(tmp_path / "fields.npz")
    _same_columns(asperity.load(tmp_path / "fields.npz"), sweep)

    path = asperity.Solver(s, boundary="periodic", hardness=0.3).load_path(
        pressures=[0.01, 0.03, 0.01])
    assert path.permanent_displacement.max() > 0
    path.save(tmp_path / "path.npz")
    _same_columns(asperity.load(tmp_path / "path.npz"), path)

    c = asperity.contact(s.heights * 1e-6, 1e-4, young=210e9, poisson=0.3,
                         pressures=[1e6, 1e7], map=True, hardness=3e9)
    assert c.map.dtype == np.bool_ and c.patch_labels.max() == c.patches[-1]
    c.save(tmp_path / "c.npz")
    _same_columns(asperity.load(tmp_path / "c.npz"), c)
    # The arrays are plain .npy members (no pickles): numpy alone reads them.
    with np.load(tmp_path / "c.npz", allow_pickle=False) as archive:
        np.testing.assert_array_equal(archive["patch_labels"], c.patch_labels)


def _results():
    """One of every other result object the package returns."""
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_slope=1.0, seed=4)
    x = (np.arange(40) - 20) * 5e-3
    sphere = -(x[:, None] ** 2 + x[None, :] ** 2) / 2
    hertz = dict(profile="hertz", radius=1.0, n=401, dx=0.01)
    return {
        "psd": asperity.psd(s),
        "patches": asperity.patches(asperity.Solver(s).solve(pressure=0.02).pressure > 0,
                                    pixel_area=1 / 32**2),
        "mdr": asperity.mdr(**hertz, nloads=5),
        "adhesive mdr": asperity.mdr(profile="hertz", radius=1.0, n=1001, dx=1e-3,
                                     work_of_adhesion=1e-3, indentations=[0.02, 0.09, 0.05]),
        "mdr slip": asperity.mdr_slip(**hertz, indentations=[1], tangential_force=1 / 3,
                                      friction=0.5, cycle_points=9),
        "bem adhesion": asperity.bem_adhesion(sphere, size=0.2, work_of_adhesion=2e-4,
                                              indentations=[0.002, 0.006, 0.004],
                                              retract_step=1e-4),
        "persson": asperity.persson(s, [0.005, 0.02]),
    }


def test_every_other_result_loads_back_identical(tmp_path):
    """The PSD, patches, MDR curves (adhesive with branches and pull-offs), slip cycles,
    adhesive BEM paths and Persson tables save too, and load back as the same object:
    every array bit for bit with its dtype, every other field equal."""
    import dataclasses

    for name, result in _results().items():
        path = tmp_path / (name.replace(" ", "_") + ".npz")
        result.save(path)
        back = asperity.load(path)
        assert type(back) is type(result), name
        arrays = 0
        for f in dataclasses.fields(result):
            mine, theirs = getattr(result, f.name), getattr(back, f.name)
            if isinstance(mine, np.ndarray):
                arrays += 1
                assert theirs.dtype == mine.dtype and theirs.shape == mine.shape, (name, f.name)
                assert theirs.tobytes() == mine.tobytes(), (name, f.name)
            else:
                assert theirs == mine, (name, f.name)
        assert arrays >= 2, name
        with pytest.raises(ValueError, match="exists"):
            result.save(path)


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


# `asperity.load` in a fresh interpreter: its ValueError's words on stdout, exit 3 (a hang
# is the timeout's failure, not this test's wait).
_LOAD = """import sys, asperity
try:
    asperity.load(sys.argv[1])
except ValueError as e:
    print(e)
    sys.exit(3)
"""


def _load_words(path) -> str:
    done = subprocess.run([sys.executable, "-c", _LOAD, str(path)], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 3, done.stderr
    return done.stdout.strip()


@pytest.mark.parametrize("fifo", ["sidecar", "file"])
@pytest.mark.parametrize("name", ["s.npy", "sweep.npz"])
def test_load_refuses_a_fifo_in_one_line_instead_of_waiting(tmp_path, fifo, name):
    # The bug: load opened the sidecar (and numpy the file) as they came, so a FIFO in
    # their place blocked it forever. Now the app layer's rules of every input apply
    # (asperity_app::argument::saved_sidecar): the CLI's words for the same file.
    path = tmp_path / name
    if name.endswith(".npy"):
        asperity.surface(16, hurst=0.8, seed=1).save(path)
    else:
        np.savez(path, force=np.zeros(2))
        (tmp_path / (name + ".json")).write_text('{"kind": "sweep"}')
    target = path if fifo == "file" else Path(str(path) + ".json")
    target.unlink()
    os.mkfifo(target)
    words = _load_words(path)
    assert words.startswith(str(target)), words
    assert "is a FIFO, socket or device, not a regular file" in words, words
    # The CLI reads a FIFO given as the surface itself with the measured reader, whose
    # words differ ("not a regular file", topography::read_file): the sidecar only here.
    if name.endswith(".npy") and fifo == "sidecar":
        done = subprocess.run([str(cli_path()), "stats", str(path)], capture_output=True,
                              text=True, timeout=60)
        assert cli_error(done) == words


def test_load_refuses_a_corrupt_sidecar_in_the_clis_words(cli, tmp_path):
    path = tmp_path / "s.npy"
    asperity.surface(16, hurst=0.8, seed=1).save(path)
    Path(str(path) + ".json").write_text('{"kind": "surface", "spec": ')
    words = _load_words(path)
    assert "is a corrupt sidecar (not JSON" in words, words
    assert cli_error(cli("stats", path, ok=False)) == words
    Path(str(path) + ".json").write_text('["surface"]')
    assert _load_words(path).endswith("is a corrupt sidecar (not a JSON object)")
