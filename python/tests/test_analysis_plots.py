"""The plots of the surface analyses (issue 34 item 3): `asperity stats --acf acf.json` (and
each other analysis option with a figure's extension) and `asperity.plot.analysis` draw one
definition (`asperity_app::figure::analysis`): the same chart as data, whose one series is
the analysis' numbers; matplotlib draws exactly those points, on log–log axes for the
scale-dependent analyses, and the image files are written and non-empty."""

import json

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import asperity  # noqa: E402
import asperity.plot  # noqa: E402
from asperity.plot import _analysis_charts  # noqa: E402

LOG = {"acf", "acf_2d", "variable_bandwidth", "scale_dependent_slope",
       "scale_dependent_curvature"}


def _heights():
    rows, cols = np.mgrid[0:24, 0:40]
    return ((rows * 7 + cols * 13) % 17) + 0.01 * cols**2 + 0.3 * np.sin(rows)


def _shown(result, log):
    xy = np.column_stack([result.x, result.y])
    keep = np.isfinite(xy).all(axis=1)
    if log:
        keep &= (xy > 0).all(axis=1)
    return xy[keep]


@pytest.mark.parametrize("name", asperity.ANALYSES)
def test_each_analysis_figure_is_the_clis_and_shows_its_numbers(cli, tmp_path, name):
    np.save(tmp_path / "h.npy", _heights())
    flag = "--" + name.replace("_", "-")
    cli("stats", tmp_path / "h.npy", "--size", "2", flag, tmp_path / "a.json",
        flag, tmp_path / "a.svg")
    theirs = json.loads((tmp_path / "a.json").read_text())["charts"]
    result = asperity.analysis(_heights(), name, size=2.0)
    mine = _analysis_charts(result, "h.npy")
    assert mine == theirs
    chart = mine[0]
    log = name in LOG
    assert chart["log_x"] is log and chart["log_y"] is log
    points = np.array(chart["series"][0]["points"], dtype=float)
    shown = _shown(result, log)
    assert len(shown) > 2
    np.testing.assert_array_equal(points, shown)
    assert (tmp_path / "a.svg").stat().st_size > 1000
    ax = asperity.plot.analysis(result, name="h.npy")
    assert ax.get_title() == chart["title"]
    assert (ax.get_xlabel(), ax.get_ylabel()) == (chart["x_label"], chart["y_label"])
    assert ax.get_xscale() == ax.get_yscale() == ("log" if log else "linear")
    line = ax.get_lines()[0]
    np.testing.assert_array_equal(np.column_stack([line.get_xdata(), line.get_ydata()]),
                                  shown)
    path = tmp_path / f"{name}.png"
    ax.figure.savefig(path)
    assert path.stat().st_size > 5000
    matplotlib.pyplot.close(ax.figure)


def test_a_measured_topographys_axes_are_in_metres(tmp_path):
    heights = _heights() * 1e-6
    topography = asperity.Topography(heights, 2e-4, 1.2e-4, {"source": "made here"})
    result = asperity.analysis(topography, "scale_dependent_curvature")
    assert result.metres
    chart = _analysis_charts(result, "scan")[0]
    assert chart["x_label"] == "distance r  [m]"
    assert chart["y_label"] == "rms curvature  [1/m]"
    assert chart["title"] == "scan: scale-dependent rms curvature along x"
    # Saved and loaded, it keeps its unit.
    result.save(tmp_path / "c.npz")
    assert asperity.load(tmp_path / "c.npz").metres


def test_anything_but_an_analysis_is_refused_in_one_line():
    with pytest.raises(ValueError, match="expected an asperity.Analysis"):
        asperity.plot.analysis(np.zeros(4))
