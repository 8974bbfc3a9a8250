"""`asperity.analysis` is `asperity stats`'s analyses (--bearing-area, --acf, --acf-2d,
--variable-bandwidth, --scale-dependent-slope/-curvature, the distributions) by the same
code: the arrays Python returns are bit for bit the CSV columns the CLI writes, on generated
surfaces and lines (square pixels, the sidecar's size) and on measured files (rectangular
pixels, levelled and filled when read); refusals and warnings are the CLI's."""

import warnings

import numpy as np
import pytest

import asperity

from conftest import cli_error
from test_cli_identity import read_csv
from test_topography import shared, tilted_text_map


def flag(name):
    return "--" + name.replace("_", "-")


def cli_tables(cli, tmp_path, path, options, names):
    """Runs `asperity stats path options --<name> <name>.csv ...` once; the tables read back
    with their headers."""
    outputs = []
    for name in names:
        outputs += [flag(name), tmp_path / f"{name}.csv"]
    cli("stats", path, *options, *outputs)
    tables = {}
    for name in names:
        with open(tmp_path / f"{name}.csv") as fh:
            header = fh.readline().strip().split(",")
        tables[name] = (header, read_csv(tmp_path / f"{name}.csv"))
    return tables


def assert_identical(ours, header, columns):
    assert ours.columns == header
    assert ours.x.dtype == ours.y.dtype == np.float64
    # Exact: the CLI writes the shortest text that parses back to the same float64.
    assert ours.x.tolist() == columns[header[0]]
    assert ours.y.tolist() == columns[header[1]]
    assert ours[header[1]] is ours.y and list(ours.table) == header


MAP_ONLY = {"acf_2d"}


def generated(kind, tmp_path):
    if kind == "surface":
        value = asperity.surface(48, m=32, hurst=0.8, rolloff=2, seed=4, size=3.0)
    else:
        value = asperity.line(512, hurst=0.3, seed=2, size=2.0)
    value.save(tmp_path / f"{kind}.npy")
    return value, tmp_path / f"{kind}.npy"


@pytest.mark.parametrize("kind", ["surface", "line"])
def test_the_analyses_of_a_generated_surface_or_line_are_the_cli_s(cli, tmp_path, kind):
    value, path = generated(kind, tmp_path)
    names = [n for n in asperity.ANALYSES if kind == "surface" or n not in MAP_ONLY]
    tables = cli_tables(cli, tmp_path, path, [], names)
    for name in names:
        ours = asperity.analysis(value, name)
        assert ours.name == name and len(ours) > 1
        assert_identical(ours, *tables[name])
        # The heights as an array with the sidecar's L give the same rows.
        plain = asperity.analysis(value.heights, name, size=value.size)
        assert plain.x.tolist() == ours.x.tolist() and plain.y.tolist() == ours.y.tolist()


@pytest.mark.parametrize("name, options, keywords", [
    # A map with rectangular pixels and undefined points, levelled and filled.
    ("x3p-2.x3p", ["--detrend", "plane", "--fill", "harmonic"],
     dict(detrend="plane", fill="harmonic")),
    # A stylus profile.
    ("dektak-1.csv", ["--detrend", "mean"], dict(detrend="mean")),
])
def test_the_analyses_of_a_measured_file_are_the_cli_s(cli, tmp_path, name, options,
                                                        keywords):
    path = shared(name)
    t = asperity.read_topography(path, **keywords)
    names = [n for n in asperity.ANALYSES if t.heights.ndim == 2 or n not in MAP_ONLY]
    tables = cli_tables(cli, tmp_path, path, options, names)
    if t.heights.ndim == 2:
        assert t.size / t.heights.shape[1] != t.size_y / t.heights.shape[0]
    for analysis in names:
        assert_identical(asperity.analysis(t, analysis), *tables[analysis])


def test_refusals_are_the_cli_s(cli, tmp_path):
    _, path = generated("line", tmp_path)
    theirs = cli_error(cli("stats", path, "--acf-2d", tmp_path / "a.csv", ok=False))
    with pytest.raises(ValueError) as ours:
        asperity.analysis(asperity.load(path), "acf_2d")
    assert str(ours.value) == theirs.replace("--acf-2d", "acf_2d").replace("--acf", "acf")
    # A distribution of no width: nothing to bin.
    flat = np.zeros((16, 16))
    np.save(tmp_path / "flat.npy", flat)
    theirs = cli_error(cli("stats", tmp_path / "flat.npy", "--height-distribution",
                           tmp_path / "h.csv", ok=False))
    with pytest.raises(ValueError) as ours:
        asperity.analysis(flat, "height_distribution")
    assert str(ours.value) == theirs
    with pytest.raises(ValueError, match=r'unknown analysis "acf2d": expected one of '
                                         r"bearing_area, acf, acf_2d, "):
        asperity.analysis(flat, "acf2d")


def test_python_warns_where_the_cli_warns(cli, tmp_path):
    # The analyses themselves warn of nothing, in either front end: the CLI's warnings
    # come from reading the file, and so do Python's (read_topography), word for word.
    path = tilted_text_map(tmp_path)
    err = cli("stats", path, "--size", "5e-5,4e-5", "--acf", tmp_path / "acf.csv",
              "--bearing-area", tmp_path / "b.csv").stderr
    theirs = [l[len("warning: "):].replace("--detrend", "detrend")
              for l in err.splitlines() if l.startswith("warning: ")]
    with pytest.warns(asperity.AsperityWarning) as caught:
        t = asperity.read_topography(path, size=(5e-5, 4e-5))
    assert [str(w.message) for w in caught] == theirs and len(theirs) == 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        acf = asperity.analysis(t, "acf")
        bearing = asperity.analysis(t, "bearing_area")
    assert acf.y.tolist() == read_csv(tmp_path / "acf.csv")["acf"]
    assert bearing.y.tolist() == read_csv(tmp_path / "b.csv")["height"]


def test_an_analysis_saves_and_loads_back_identical(tmp_path):
    a = asperity.analysis(asperity.surface(32, hurst=0.5, seed=1), "variable_bandwidth")
    a.save(tmp_path / "vb.npz")
    back = asperity.load(tmp_path / "vb.npz")
    assert isinstance(back, asperity.Analysis) and back.columns == a.columns
    assert back.name == a.name and (back.x == a.x).all() and (back.y == a.y).all()
    assert repr(back) == "Analysis(variable_bandwidth, %d rows: bandwidth, rms_height)" % len(a)
