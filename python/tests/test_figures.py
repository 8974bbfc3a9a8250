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


def _same_but_the_name(mine, theirs):
    """The charts are equal once the titles' names (a file name in the CLI, what the caller
    calls it in Python) are set aside."""
    assert len(mine) == len(theirs)
    for a, b in zip(mine, theirs):
        assert a["title"].split(": ", 1)[1] == b["title"].split(": ", 1)[1]
        a["title"] = b["title"] = ""
    assert _nan_to_none(mine) == theirs


def test_a_surfaces_image_is_the_clis_bit_for_bit(cli, tmp_path):
    # A rectangular map (y 24 rows, x 40 columns) in its own unit: heights, extent, colour
    # range, scale bar and words are the CLI's `surface --plot FILE.json`.
    cli("surface", "--n", "40", "--m", "24", "--hurst", "0.7", "--size", "2", "--seed", "3",
        "--out", tmp_path / "s.npy", "--plot", tmp_path / "s.json")
    theirs = json.loads((tmp_path / "s.json").read_text())["charts"]
    surface = asperity.load(tmp_path / "s.npy")
    mine = asperity.plot._surface_charts(surface)
    image = mine[0]["series"][0]["image"]
    assert (image["rows"], image["cols"], image["extent"]) == (24, 40, [2.0, 1.2])
    assert image["scale_bar"] == {"length": 0.2, "label": "0.2"}
    np.testing.assert_array_equal(np.reshape(image["values"], (24, 40)), surface.heights)
    _same_but_the_name(mine, theirs)
    # matplotlib draws the definition's cells over its extent, with its colour range.
    ax = asperity.plot.surface(surface)
    drawn = ax.get_images()[0]
    assert drawn.get_extent() == [0, 2.0, 0, 1.2]
    np.testing.assert_array_equal(drawn.get_array(), surface.heights)
    assert drawn.get_clim() == (surface.heights.min(), surface.heights.max())
    assert ax.get_title() == "surface: heights (24×40, 2 × 1.2)"


def test_a_psd_figure_is_the_clis_bit_for_bit(cli, tmp_path):
    cli("surface", "--n", "64", "--hurst", "0.8", "--rolloff", "4", "--seed", "2",
        "--out", tmp_path / "s.npy")
    cli("stats", tmp_path / "s.npy", "--plot", tmp_path / "p.json")
    theirs = json.loads((tmp_path / "p.json").read_text())["charts"]
    spectrum = asperity.psd(asperity.load(tmp_path / "s.npy"))
    mine = asperity.plot._psd_charts(spectrum)
    assert [s["label"] for s in mine[0]["series"]][1].startswith("fit: slope")
    _same_but_the_name(mine, theirs)
    # A line: C1D, same fit range words.
    cli("line", "--n", "1024", "--hurst", "0.5", "--seed", "4", "--out", tmp_path / "l.npy")
    cli("stats", tmp_path / "l.npy", "--plot", tmp_path / "l.json")
    theirs = json.loads((tmp_path / "l.json").read_text())["charts"]
    mine = asperity.plot._psd_charts(asperity.psd(asperity.load(tmp_path / "l.npy")))
    assert mine[0]["y_label"] == "PSD C1D(q)  [length³]"
    _same_but_the_name(mine, theirs)


def test_a_contact_map_is_the_clis_bit_for_bit(cli, tmp_path):
    # A measured map in metres (rectangular pixels), pressed by the CLI and by Python: the
    # patches of the last load, their count in the title, the extent and scale bar in m.
    rng = np.random.default_rng(0)
    heights = rng.standard_normal((30, 44)).cumsum(0).cumsum(1) * 1e-9
    np.savetxt(tmp_path / "m.txt", heights)
    cli("import", tmp_path / "m.txt", "--size", "8e-6,6e-6", "--detrend", "plane",
        "--out", tmp_path / "m.npy")
    cli("contact", tmp_path / "m.npy", "--modulus", "1e9", "--pressures", "1e6,1e7",
        "--quiet", "--out", tmp_path / "c.csv", "--map", tmp_path / "map.json")
    theirs = json.loads((tmp_path / "map.json").read_text())["charts"]
    sweep = asperity.contact(asperity.load(tmp_path / "m.npy"), modulus=1e9,
                             pressures=[1e6, 1e7], map=True)
    mine = asperity.plot._contact_map_charts(sweep)
    image = mine[0]["series"][0]["image"]
    assert image["extent"] == [8e-6, 6e-6]
    assert image["scale_bar"]["label"] == "1 µm"
    np.testing.assert_array_equal(np.reshape(image["values"], (30, 44)),
                                  asperity.patches(sweep.map).labels)
    assert f"{int(sweep.patches[-1])} contact patches" in mine[0]["title"]
    _same_but_the_name(mine, theirs)
    # Drawn: one colour per patch, the definition's; free surface white.
    ax = asperity.plot.contact_map(sweep)
    rgb = ax.get_images()[0].get_array()
    labels = asperity.patches(sweep.map).labels
    palette = image["colors"]["categories"]["colors"]
    for label in range(1, labels.max() + 1):
        colour = palette[1 + (label - 1) % (len(palette) - 1)]["rgb"]
        drawn = np.asarray(rgb[labels == label])
        np.testing.assert_allclose(drawn, np.broadcast_to(np.array(colour) / 255, drawn.shape))
    assert (rgb[labels == 0] == 1.0).all()


def test_a_contact_sweeps_panels_are_the_clis_bit_for_bit(cli, tmp_path):
    # `asperity contact --plot FILE.json` and asperity.plot.stiffness / area of the same
    # contact sweep (SI units, E* from E and ν): k(F), A(F) and the mean gap, one definition
    # (asperity_app::figure::contact).
    rng = np.random.default_rng(1)
    heights = rng.standard_normal((32, 32)).cumsum(0).cumsum(1) * 1e-9
    np.savetxt(tmp_path / "m.txt", heights)
    cli("import", tmp_path / "m.txt", "--size", "8e-6,8e-6", "--detrend", "plane",
        "--out", tmp_path / "m.npy")
    loads = [1e6, 3e6, 1e7]
    cli("contact", tmp_path / "m.npy", "--young", "210e9", "--poisson", "0.3",
        "--pressures", ",".join(map(str, loads)), "--quiet", "--out", tmp_path / "c.csv",
        "--plot", tmp_path / "c.json")
    theirs = json.loads((tmp_path / "c.json").read_text())["charts"]
    sweep = asperity.contact(asperity.load(tmp_path / "m.npy"), young=210e9, poisson=0.3,
                             pressures=loads)
    mine = asperity.plot._contact_charts(sweep)
    assert [c["y_label"] for c in mine] == ["stiffness k  [N/m]", "contact area A  [m²]",
                                           "mean gap  [m]"]
    assert mine[1]["series"][0]["points"] == [list(p) for p in zip(sweep.force_n,
                                                                  sweep.contact_area_m2)]
    _same_but_the_name(mine, theirs)
    # matplotlib draws those points on log axes.
    for draw, column, chart in ((asperity.plot.stiffness, "stiffness_n_per_m", theirs[0]),
                                (asperity.plot.area, "contact_area_m2", theirs[1])):
        ax = draw(sweep)
        assert (ax.get_xscale(), ax.get_yscale()) == ("log", "log")
        assert ax.get_ylabel() == chart["y_label"]
        np.testing.assert_array_equal(ax.get_lines()[0].get_xydata(),
                                      np.column_stack([sweep.force_n, sweep[column]]))


def test_a_study_curves_k_and_area_are_curve_csv_with_its_intervals(cli, tmp_path):
    # The Python study's k(F) and A/A₀(F) are built by the CLI's builder module from the
    # task results; the CLI resuming the same folder writes curve.csv from the same
    # results: the drawn points and their bands (95 % intervals of the means) are that
    # table's columns.
    study = asperity.study_curve(method="mdr", n=256, hurst=[0.25, 0.75], samples=3,
                                 out=tmp_path / "c")
    cli("study", "curve", "--method", "mdr", "--n", "256", "--hurst", "0.25,0.75",
        "--samples", "3", "--out", tmp_path / "c")
    lines = (tmp_path / "c" / "curve.csv").read_text().splitlines()
    header = lines[0].split(",")
    rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
    k_chart = study.figures["curve"]["charts"][0]
    area_chart = study.figures["area"]["charts"][0]
    for h, k_series, a_series in zip(("0.25", "0.75"), k_chart["series"], area_chart["series"]):
        mine = [r for r in rows if float(r["hurst"]) == float(h)]
        assert k_series["label"] == a_series["label"] == f"mdr N = 256 H = {h}"
        assert k_series["points"] == [[float(r["force"]), float(r["stiffness"])] for r in mine]
        assert k_series["interval"] == [[float(r["stiffness_low"]), float(r["stiffness_high"])]
                                        for r in mine]
        assert a_series["points"] == [[float(r["force"]), float(r["area_fraction"])]
                                      for r in mine]
        assert a_series["interval"] == [[float(r["area_fraction_low"]),
                                         float(r["area_fraction_high"])] for r in mine]
        widths = [float(r["area_fraction_high"]) - float(r["area_fraction_low"]) for r in mine]
        assert min(widths) >= 0 and sum(w > 0 for w in widths) > len(widths) // 2
    assert k_chart["series"][-1]["label"] == "slope 1 (k ∝ F)"
    # Drawn: one band per curve under k(F) and under A/A₀(F); the lines are the means.
    ax = asperity.plot.stiffness(study)
    assert len(ax.collections) == 2
    ax = asperity.plot.area(study)
    assert len(ax.collections) == 2
    assert ax.get_yscale() == "log" and ax.get_ylabel() == area_chart["y_label"]
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(),
                                  [p[1] for p in area_chart["series"][0]["points"]])


def test_an_mdr_curves_figure_is_the_clis_bit_for_bit(cli, tmp_path):
    """`asperity mdr --plot FILE.json` and `asperity.plot.mdr` of the same curve: the same
    two charts (F/E* against d, k/E* against F/E*, log–log; titles included, both name the
    indenter and its springs), the forces over E* as the table holds them, and matplotlib
    draws the charts' points."""
    d = [1e-4, 3e-4, 1e-3, 3e-3, 1e-2]
    cli("mdr", "--profile", "hertz", "--radius", "1", "--n", "2001", "--dx", "0.01",
        "--modulus", "2.5", "--indentations", ",".join(map(str, d)),
        "--out", tmp_path / "c.csv", "--plot", tmp_path / "c.json")
    theirs = json.loads((tmp_path / "c.json").read_text())["charts"]
    curve = asperity.mdr(profile="hertz", radius=1.0, n=2001, dx=0.01, modulus=2.5,
                         indentations=d)
    assert curve.modulus == 2.5
    from asperity import _asperity

    mine = json.loads(_asperity.mdr_figure(
        curve.indentation.tolist(), curve.force.tolist(), curve.stiffness.tolist(),
        curve.description, curve.spring, curve.modulus))["charts"]
    assert _nan_to_none(mine) == _nan_to_none(theirs)
    shown = curve.force > 0
    assert theirs[0]["series"][0]["points"] == [
        [x, f / 2.5] for x, f in zip(curve.indentation[shown], curve.force[shown])]
    axes = asperity.plot.mdr(curve)
    assert len(axes) == 2
    for ax, chart in zip(axes, theirs):
        assert ax.get_xscale() == ax.get_yscale() == "log"
        assert ax.get_xlabel() == chart["x_label"] and ax.get_ylabel() == chart["y_label"]
        assert np.array_equal(ax.lines[0].get_xydata(), np.array(chart["series"][0]["points"]))
    adhesive = asperity.mdr(profile="hertz", radius=1.0, n=1001, dx=1e-3,
                            work_of_adhesion=1e-3, indentations=[0.09])
    with pytest.raises(ValueError, match="adhesion_loop"):
        asperity.plot.mdr(adhesive)


@pytest.mark.parametrize("function, columns, rest", [
    ("mdr_figure", ["indentation", "force", "stiffness"], ("hertz", "harmonic", 1.0)),
    ("contact_figure", ["force", "stiffness", "area", "mean_gap"], (2e11, "m.npy")),
])
def test_a_figures_column_of_another_length_is_refused_by_name(function, columns, rest):
    """The figures' one length check (python/src/figure.rs `same_length`): each column in
    turn one value short is a ValueError naming that column, its length and the first's."""
    from asperity import _asperity

    draw = getattr(_asperity, function)
    draw(*[[1.0, 2.0, 3.0]] * len(columns), *rest)  # equal lengths draw
    for short in columns[1:]:
        values = [[1.0, 2.0] if name == short else [1.0, 2.0, 3.0] for name in columns]
        with pytest.raises(ValueError) as refused:
            draw(*values, *rest)
        assert str(refused.value) == (
            f"{function}: the column {short} has 2 values, {columns[0]} has 3")
    # The first column short: the others are named against it.
    values = [[1.0]] + [[1.0, 2.0, 3.0]] * (len(columns) - 1)
    with pytest.raises(ValueError, match=f"{function}: the column {columns[1]} has 3 values, "
                                         f"{columns[0]} has 1"):
        draw(*values, *rest)
