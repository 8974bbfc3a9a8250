"""One definition of what a figure shows (issue 36 item 4): the CLI's `--plot` and
`asperity.plot` draw the same charts, built once in the library's front-end layer. The CLI
writes a chart definition as JSON with `--plot FILE.json`; the package's charts must be
that JSON, and matplotlib must draw exactly its points, labels, scales and titles."""

import json

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import asperity  # noqa: E402
import asperity.plot  # noqa: E402
from asperity.plot import _sweep_charts  # noqa: E402


def _nan_to_none(charts):
    return json.loads(json.dumps(charts).replace("NaN", "null"))


def _finite(points):
    xy = np.array([[np.nan if v is None else v for v in p] for p in points], dtype=float)
    return xy[np.isfinite(xy).all(axis=1) & (xy > 0).all(axis=1)]


def test_a_sweeps_figure_is_the_clis_bit_for_bit(cli, tmp_path):
    cli("surface", "--n", "48", "--hurst", "0.6", "--seed", "5", "--out", tmp_path / "s.npy")
    cli("bem", "--surface", tmp_path / "s.npy", "--nloads", "5", "--pmin", "1e-3",
        "--pmax", "3e-2", "--fd-stiffness", "--modulus", "2", "--boundary", "periodic",
        "--quiet", "--out", tmp_path / "k.csv", "--plot", tmp_path / "k.json")
    theirs = json.loads((tmp_path / "k.json").read_text())
    assert theirs["format"] == "asperity-figure/1"
    solver = asperity.Solver(asperity.load(tmp_path / "s.npy"), modulus=2.0,
                             boundary="periodic")
    sweep = solver.sweep(nloads=5, pmin=1e-3, pmax=3e-2, fd_stiffness=True)
    mine = _sweep_charts(sweep)
    # The titles name the surface: its file in the CLI, "surface" in Python.
    for a, b in zip(mine, theirs["charts"]):
        assert a["title"].split(": ", 1)[1] == b["title"].split(": ", 1)[1]
        a["title"] = b["title"] = ""
    assert _nan_to_none(mine) == theirs["charts"]
    labels = [s["label"] for s in mine[0]["series"]]
    assert labels == ["frozen contact set", "finite difference dF/dd"]


def test_matplotlib_draws_the_definitions_points_scales_and_words(cli, tmp_path):
    cli("surface", "--n", "40", "--hurst", "0.8", "--seed", "2", "--out", tmp_path / "s.npy")
    cli("bem", "--surface", tmp_path / "s.npy", "--nloads", "4", "--pmin", "1e-3",
        "--pmax", "1e-2", "--quiet", "--out", tmp_path / "k.csv", "--plot", tmp_path / "k.json")
    record = json.loads((tmp_path / "k.json").read_text())
    axes = asperity.plot.figure(tmp_path / "k.json")
    assert len(axes) == 2
    for ax, chart in zip(axes, record["charts"]):
        assert ax.get_title() == chart["title"]
        assert (ax.get_xlabel(), ax.get_ylabel()) == (chart["x_label"], chart["y_label"])
        assert ax.get_xscale() == ("log" if chart["log_x"] else "linear")
        line = ax.get_lines()[0]
        drawn = np.column_stack([line.get_xdata(), line.get_ydata()])
        np.testing.assert_array_equal(drawn, _finite(chart["series"][0]["points"]))


def test_a_study_figure_is_the_one_the_cli_draws_from_the_same_folder(cli, tmp_path):
    # The Python study's figure is built from its task results by the CLI's builder; the
    # CLI resuming the same folder draws its alpha.png from the same results: the theory
    # series and the data points are what alpha.csv holds.
    study = asperity.study_alpha(method="mdr", n=[128, 256], hurst=[-0.5, 0.5], samples=3,
                                 out=tmp_path / "a")
    chart = study.figures["alpha"]["charts"][0]
    labels = [s["label"] for s in chart["series"]]
    assert labels == ["mdr N = 128", "mdr N = 256", "1/(1+H) (6)", "1/3 (Hertz)",
                      "(24), N = 128", "(24), N = 256"]
    cli("study", "alpha", "--method", "mdr", "--n", "128,256", "--hurst", "-0.5,0.5",
        "--samples", "3", "--out", tmp_path / "a")
    rows = (tmp_path / "a" / "alpha.csv").read_text().splitlines()
    header = rows[0].split(",")
    alpha = [float(r.split(",")[header.index("alpha")]) for r in rows[1:]]
    drawn = [y for s in chart["series"][:2] for _, y in s["points"]]
    assert sorted(drawn) == sorted(alpha)
    # Saved and loaded, the result keeps its figures.
    study.save(tmp_path / "r.npz")
    assert asperity.load(tmp_path / "r.npz").figures == study.figures


def test_a_figure_that_is_not_ours_is_refused(tmp_path):
    (tmp_path / "x.json").write_text('{"charts": []}')
    with pytest.raises(ValueError, match="asperity-figure/1"):
        asperity.plot.figure(tmp_path / "x.json")


def test_a_load_paths_figure_is_the_clis_and_draws_the_loop(cli, tmp_path):
    """`bem --load-path --plot FILE.json` and `asperity.plot.load_path` of the same path:
    the same three charts (F(d), A/A₀(d), k(F); titles aside, which name the file), and
    matplotlib draws the loop's points; the permanent displacement draws as an image."""
    cli("surface", "--n", "48", "--hurst", "0.8", "--rolloff", "3", "--rms-slope", "0.5",
        "--seed", "7", "--out", tmp_path / "s.npy")
    loads = [0.01, 0.03, 0.01, 0.02, 0.03]
    cli("bem", "--surface", tmp_path / "s.npy", "--boundary", "periodic", "--hardness", "0.2",
        "--load-path", "--pressures", ",".join(map(str, loads)), "--quiet",
        "--out", tmp_path / "p.csv", "--plot", tmp_path / "p.json")
    theirs = json.loads((tmp_path / "p.json").read_text())["charts"]
    solver = asperity.Solver(asperity.load(tmp_path / "s.npy"), boundary="periodic",
                             hardness=0.2)
    path = solver.load_path(pressures=loads)
    axes = asperity.plot.load_path(path)
    assert len(axes) == len(theirs) == 3
    for ax, chart in zip(axes, theirs):
        assert ax.get_xlabel() == chart["x_label"] and ax.get_ylabel() == chart["y_label"]
        labels = [s["label"] for s in chart["series"]]
        assert labels == ["path", "loading", "unloading", "reloading"]
        drawn = np.array(ax.lines[0].get_xydata())
        assert np.array_equal(drawn, np.array(chart["series"][0]["points"]))
    assert theirs[0]["series"][0]["points"] == [list(p) for p in zip(path.indentation, path.force)]
    assert "H = 0.2" in theirs[0]["title"]
    ax = asperity.plot.field(path.permanent_displacement, label="permanent displacement")
    assert ax.images[0].get_array().shape == path.permanent_displacement.shape
