"""Measured topographies through the library's readers: Python reads what
`asperity import` reads (heights bit for bit, sizes, provenance), bad files raise the CLI's
one-line error, and a measured map with rectangular pixels goes straight to the Solver."""

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
    t = asperity.read_topography(path)
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
