"""Plotting helpers on matplotlib (an optional dependency: ``pip install matplotlib``).

Each function draws one of the figures the ``asperity`` command writes, from the objects
the package returns, onto a matplotlib ``Axes`` (a new figure when ``ax`` is None) and
returns the ``Axes``:

* :func:`surface` -- a height map in physical units, with a scale bar and a colour bar
  (``asperity surface --plot``);
* :func:`psd` -- the PSD against q·L/2π, log–log, with the fitted power law over its fit
  range (``asperity stats --plot``);
* :func:`stiffness`, :func:`area` -- k(F) and the contact area against force, k with the
  95 % interval of an ensemble mean as a band (``asperity study curve``, ``bem --plot``,
  ``contact --plot``);
* :func:`analysis` -- a surface analysis of :func:`asperity.analysis` (the ACFs, the
  scale-dependent slope and curvature and the variable-bandwidth rms height log–log
  against the length scale; the bearing-area curve and the distributions) as ``asperity
  stats --acf acf.png`` (and the other analysis options) draws it;
* :func:`contact_map` -- a contact set with its 4-connected patches coloured
  (``asperity contact --map``);
* :func:`alpha` -- α(H) with its 95 % intervals and the theory (``asperity study alpha``);
* :func:`load_path` -- a load path's loading–unloading loop (``bem --load-path --plot``);
* :func:`mdr` -- an MDR curve's F(d) and k(F), log–log (``asperity mdr --plot``);
* :func:`adhesion_loop` -- an adhesive run's force–approach loop with arrows and pull-offs
  (``bem|contact|mdr --work-of-adhesion --plot``);
  :func:`field` -- a field (the plastic or permanent displacement) as an image;
* :func:`figure` -- any figure the CLI wrote as data (``--plot FILE.json``).

Every figure here but :func:`field` is defined once, in the library's front-end layer,
for the CLI and the package: the same series, theory curves, intervals, images, scale
bars, labels and titles as the CLI's PNG (``asperity_app::figure``; ``--plot FILE.json``
writes that definition); the package draws it with matplotlib. (The ensemble-mean A/A₀(F)
of a study with its interval, :func:`area` of a ``study_curve`` result, is defined there
too, though the CLI tabulates it in ``curve.csv`` without drawing it.)

Example::

    >>> import asperity, asperity.plot
    >>> s = asperity.surface(128, hurst=0.8, rolloff=4, seed=1)
    >>> ax = asperity.plot.psd(asperity.psd(s))
    >>> ax.figure.savefig("psd.png")
"""

from __future__ import annotations

import math
import os
from typing import Any, Optional

import numpy as _np

__all__ = ["surface", "psd", "analysis", "stiffness", "area", "contact_map", "alpha", "figure",
           "load_path", "adhesion_loop", "mdr", "field"]


def __dir__() -> list:
    """The public names only: the helpers this module imports are not part of it."""
    return sorted(__all__)


def _pyplot():
    try:
        import matplotlib.pyplot as plt
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError("asperity.plot needs matplotlib: pip install matplotlib") from None
    return plt


def _axes(ax):
    if ax is not None:
        return ax
    _, ax = _pyplot().subplots()
    return ax


def _record(text: str) -> list:
    import json

    return _charts(json.loads(text))


def _surface_charts(values: Any, name: str = "surface") -> list:
    """``asperity surface --plot``'s chart of a :class:`~asperity.Surface` or
    :class:`~asperity.Topography` (the library's definition)."""
    from . import Surface, Topography, _asperity

    if isinstance(values, Surface):
        heights, (sx, sy), metres = values.heights, values.physical_sizes, False
    elif isinstance(values, Topography):
        if values.size_y is None:
            raise ValueError("surface: a profile is no map")
        heights, (sx, sy), metres = values.heights, values.physical_sizes, True
    else:
        raise ValueError("surface: expected an asperity.Surface or asperity.Topography")
    heights = _np.ascontiguousarray(heights, dtype=_np.float64)
    return _record(_asperity.surface_figure(heights, float(sx), float(sy), metres, name))


def surface(values: Any, ax=None, *, cmap: Optional[str] = None, scale_bar: bool = True,
            name: str = "surface"):
    """The height map of a :class:`~asperity.Surface` or :class:`~asperity.Topography`
    as ``asperity surface --plot`` draws it (one definition): rows along y, drawn with y
    up, in physical units (metres for a measured topography), a scale bar of a round
    length about a fifth of the width and a colour bar of the heights; undefined heights
    white. Maps above 512 points a side are sampled at every k-th point. ``cmap``: another
    matplotlib colour map than the definition's Viridis; ``name``: the title's name."""
    charts = _surface_charts(values, name)
    return _draw(charts[0], ax, cmap=cmap, scale_bar=scale_bar)


def _psd_charts(spectrum: Any, name: str = "surface") -> list:
    """``asperity stats --plot``'s chart of a :class:`~asperity.Psd`."""
    from . import _asperity

    fit = spectrum.fit
    fitted = None if fit is None else (float(fit["prefactor"]), float(fit["exponent"]))
    span = None if spectrum.fit_from is None else (float(spectrum.fit_from),
                                                   float(spectrum.fit_to))
    return _record(_asperity.psd_figure(
        spectrum.q.tolist(), spectrum.psd.tolist(), float(spectrum.size), int(spectrum.ndim),
        span, fitted, spectrum.hurst, name))


def psd(spectrum: Any, ax=None, *, name: Optional[str] = None):
    """A :class:`~asperity.Psd` (or anything :func:`asperity.psd` takes) as ``asperity
    stats --plot`` draws it (one definition): the PSD against q·L/2π, log–log, with the
    fitted power law over its fit range, its slope and Hurst estimate in the legend.
    ``name``: the title's name (default ``surface``, or ``line`` for a line)."""
    from . import Psd, psd as compute

    if not isinstance(spectrum, Psd):
        spectrum = compute(spectrum)
    if name is None:
        name = "line" if spectrum.ndim == 1 else "surface"
    return _draw(_psd_charts(spectrum, name)[0], ax)


def _analysis_charts(result: Any, name: str) -> list:
    """``asperity stats --acf FILE.png``'s chart (and the other analysis options') of an
    :class:`~asperity.Analysis`."""
    from . import Analysis, _asperity

    if not isinstance(result, Analysis):
        raise ValueError(f"analysis: expected an asperity.Analysis (asperity.analysis(...)), "
                         f"got {type(result).__name__}")
    return _record(_asperity.analysis_figure(result.name, result.x.tolist(), result.y.tolist(),
                                             bool(result.metres), name))


def analysis(result: Any, ax=None, *, name: str = "surface"):
    """An :class:`~asperity.Analysis` (of :func:`asperity.analysis`) as ``asperity stats
    --acf acf.png`` (and each other analysis option with a ``.png``/``.svg`` name) draws it
    (one definition, ``asperity_app::figure::analysis``): the ACF (1D and radially averaged
    2D), the scale-dependent rms slope and curvature and the variable-bandwidth rms height
    on log–log axes against the length scale (the points a log axis can show), the
    bearing-area (Abbott–Firestone) curve and the height, slope and curvature distributions
    on linear axes; lengths in metres for a :class:`~asperity.Topography`, else in the
    heights' unit (``length``). ``name``: the title's name.

    Example::

        >>> import asperity, asperity.plot
        >>> s = asperity.surface(64, hurst=0.8, seed=1)
        >>> ax = asperity.plot.analysis(asperity.analysis(s, "scale_dependent_slope"))
        >>> ax.get_xscale(), ax.get_xlabel()
        ('log', 'distance r  [length]')
    """
    return _draw(_analysis_charts(result, name)[0], ax)


def _color(color: Any, index: int):
    if color is None:
        return f"C{index % 10}"
    if "rgb" in color:
        return tuple(v / 255 for v in color["rgb"])
    return _pyplot().get_cmap("viridis")(min(max(float(color["ordered"]), 0.0), 1.0))


def _pairs(values: Any) -> Any:
    """``[[x, y], ...]`` with JSON nulls (missing values) as NaN, shape (n, 2)."""
    rows = [[_np.nan if v is None else v for v in pair] for pair in values]
    return _np.asarray(rows, dtype=_np.float64).reshape(-1, 2)


def _draw_series(ax, chart: dict, s: dict, color) -> None:
    xy = _pairs(s["points"])
    x, y = xy[:, 0], xy[:, 1]
    shown = lambda v, log: _np.isfinite(v) & ((v > 0) if log else True)  # noqa: E731
    keep = shown(x, chart["log_x"]) & shown(y, chart["log_y"])
    if s["style"] == "arrows":  # points in pairs, tail then head (an adhesive loop's way)
        for k in range(0, len(xy) - 1, 2):
            if keep[k] and keep[k + 1]:
                ax.annotate("", xy=tuple(xy[k + 1]), xytext=tuple(xy[k]),
                            arrowprops={"arrowstyle": "-|>", "color": color, "lw": 1.5})
        ax.plot([], [], "-", color=color, label=s["label"] or None)  # the legend's entry
        return
    fmt = {"line": "-", "dashed": "--", "points": "o", "line_points": "-o"}[s["style"]]
    ax.plot(x[keep], y[keep], fmt, color=color, label=s["label"] or None, markersize=4)
    if s.get("interval"):
        bounds = _pairs(s["interval"])
        lo, hi = bounds[:, 0], bounds[:, 1]
        ok = keep & shown(lo, chart["log_y"]) & shown(hi, chart["log_y"])
        if s["style"] in ("points", "line_points"):
            err = _np.vstack([_np.maximum(y[ok] - lo[ok], 0), _np.maximum(hi[ok] - y[ok], 0)])
            ax.errorbar(x[ok], y[ok], yerr=err, fmt="none", ecolor=color, alpha=0.5,
                        capsize=3)
        else:
            ax.fill_between(x[ok], lo[ok], hi[ok], color=color, alpha=0.2, linewidth=0)
    if s.get("tag") and keep.any():
        ax.annotate(s["tag"], (x[keep][-1], y[keep][-1]), color=color, xytext=(4, 0),
                    textcoords="offset points", va="center")


def _draw_image(ax, image: dict, cmap: Optional[str], scale_bar: bool) -> None:
    """An image series: cells over its extent, row 0 at the bottom; on the Viridis map
    with a colour bar, or as categories (0 the first colour, k ≥ 1 cycling through the
    rest); its scale bar in the lower left."""
    values = _np.array([_np.nan if v is None else v for v in image["values"]],
                       dtype=_np.float64).reshape(image["rows"], image["cols"])
    width, height = image["extent"]
    extent = (0, width, 0, height)
    colors = image["colors"]
    if "viridis" in colors:
        scale = colors["viridis"]
        drawn = ax.imshow(values, origin="lower", extent=extent, cmap=cmap or "viridis",
                          vmin=scale["low"], vmax=scale["high"], interpolation="nearest")
        ax.figure.colorbar(drawn, ax=ax, label=scale["label"])
    else:
        palette = _np.array([_color(c, 0) for c in colors["categories"]["colors"]])
        k = _np.nan_to_num(values).astype(_np.int64)
        index = _np.where(k <= 0, 0, 1 + (k - 1) % max(len(palette) - 1, 1))
        ax.imshow(palette[index], origin="lower", extent=extent, interpolation="nearest")
    bar = image.get("scale_bar")
    if bar and scale_bar:
        from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

        ax.add_artist(AnchoredSizeBar(ax.transData, bar["length"], bar["label"],
                                      "lower left", pad=0.4, color="black", frameon=True,
                                      size_vertical=height / 100))


def _draw(chart: dict, ax=None, *, cmap: Optional[str] = None, scale_bar: bool = True):
    """One chart of the library's figure definition (``asperity-figure/1``) on ``ax``."""
    ax = _axes(ax)
    for i, s in enumerate(chart["series"]):
        if s.get("image") is not None:
            _draw_image(ax, s["image"], cmap, scale_bar)
            continue
        _draw_series(ax, chart, s, _color(s.get("color"), i))
    if chart["log_x"]:
        ax.set_xscale("log")
    if chart["log_y"]:
        ax.set_yscale("log")
    ax.set_title(chart["title"])
    ax.set_xlabel(chart["x_label"])
    ax.set_ylabel(chart["y_label"])
    if any(s["label"] for s in chart["series"]):
        ax.legend()
    return ax


def _charts(figure_data: Any) -> list:
    if isinstance(figure_data, (str, bytes)) or hasattr(figure_data, "__fspath__"):
        import json
        from pathlib import Path

        figure_data = json.loads(Path(figure_data).read_text())
    if not isinstance(figure_data, dict) or figure_data.get("format") != "asperity-figure/1":
        raise ValueError("figure: expected an asperity-figure/1 record (asperity ... "
                         "--plot FILE.json)")
    return figure_data["charts"]


def figure(figure_data: Any, axes=None):
    """Draws a figure the CLI wrote as data (``asperity bem … --plot k.json``, any command's
    ``--plot`` with a ``.json`` name), or such a record as a dict: one panel per chart, side
    by side (``axes``: a sequence of as many ``Axes``; new ones when None). Returns the
    list of ``Axes``."""
    charts = _charts(figure_data)
    if axes is None:
        _, made = _pyplot().subplots(1, len(charts), figsize=(6.4 * len(charts), 4.8),
                                     squeeze=False)
        axes = list(made[0])
    if len(axes) != len(charts):
        raise ValueError(f"figure: {len(charts)} charts, {len(axes)} axes given")
    return [_draw(chart, ax) for chart, ax in zip(charts, axes)]


def _sweep_charts(sweep: Any) -> list:
    """The CLI's ``bem --plot`` panels of a ``Solver.sweep`` result."""
    from . import _asperity

    c, solver = sweep.columns, sweep.metadata.get("solver", {})
    nan = _np.full(len(c["force"]), _np.nan)
    text = _asperity.sweep_figure(
        c["force"].tolist(), c.get("stiffness", nan).tolist(),
        c["stiffness_fd"].tolist() if "stiffness_fd" in c else None,
        c["area_fraction"].tolist(), "surface", float(solver.get("modulus", 1.0)), False,
        solver.get("boundary", "free"))
    return _charts(__import__("json").loads(text))


def load_path(path: Any, axes=None):
    """The loading–unloading loop of a ``Solver.load_path`` result as ``asperity bem
    --load-path --plot`` draws it (one figure definition, ``asperity_app::figure::path``):
    force against indentation, the contact fraction against indentation and the stiffness
    against force, each step marked by its branch. ``axes``: three matplotlib axes, or
    None for a new figure. Returns the axes."""
    from . import _asperity

    c, solver, loads = path.columns, path.metadata.get("solver", {}), path.metadata.get("loads", {})
    text = _asperity.path_figure(
        [float(v) for v in loads.get("values", c["indentation"])], c["indentation"].tolist(),
        c["force"].tolist(), c["area_fraction"].tolist(), c["stiffness"].tolist(), "surface",
        solver.get("boundary", "free"), solver.get("hardness"))
    return figure(__import__("json").loads(text), axes)


def mdr(curve: Any, axes=None):
    """An :func:`asperity.mdr` curve as ``asperity mdr --plot`` draws it (one figure
    definition, ``asperity_app::figure::mdr``): F/E* against the indentation d and k/E*
    against F/E*, log–log (the row at zero force left out). ``axes``: two matplotlib axes,
    or None for a new figure. Returns the axes. An adhesive curve's loop is
    :func:`adhesion_loop`'s.

    Example::

        >>> import asperity, asperity.plot
        >>> c = asperity.mdr(profile="hertz", radius=1.0, n=2001, dx=0.01,
        ...                  indentations=[1e-4, 1e-3, 1e-2])
        >>> force_ax, stiffness_ax = asperity.plot.mdr(c)
        >>> force_ax.get_xscale(), stiffness_ax.get_ylabel()
        ('log', 'contact stiffness k / E*  [length]')
    """
    from . import _asperity

    if getattr(curve, "branch", None) is not None:
        raise ValueError("plot.mdr: an adhesive curve; draw its loop with "
                         "asperity.plot.adhesion_loop")
    modulus = 1.0 if getattr(curve, "modulus", None) is None else float(curve.modulus)
    text = _asperity.mdr_figure(
        [float(v) for v in curve.indentation], [float(v) for v in curve.force],
        [float(v) for v in curve.stiffness], str(curve.description), str(curve.spring),
        modulus)
    return figure(__import__("json").loads(text), axes)


def adhesion_loop(run: Any, ax=None, *, theory: Optional[tuple] = None):
    """The force–approach loop of an adhesive run as ``asperity bem|contact|mdr
    --work-of-adhesion --plot`` draws it (one figure definition,
    ``asperity_app::figure::adhesion``): the path and the retraction to pull-off, an arrow
    on every monotone run the way it was travelled (loading red, unloading blue), both
    pull-offs marked. ``run``: a :func:`asperity.bem_adhesion` result, an adhesive
    :func:`asperity.mdr` curve, or an adhesive :func:`asperity.contact` result (SI units);
    ``theory``: an optional ``(label, [(d, F), ...])`` curve, dashed. Returns the axes."""
    import json

    from . import _asperity

    if hasattr(run, "columns"):  # asperity.contact(work_of_adhesion=...): SI units
        c, pull = run.columns, run.metadata.get("pull_off")
        d, f, branch = c["indentation_m"], c["force_n"], c["branch"]
        labels = ("indentation d  [m]", "normal force F  [N]", " N")
        title = "adhesive contact"
    else:
        d, f, branch, pull = run.indentation, run.force, run.branch, run.pull_off
        labels = ("indentation d  [length]", "normal force F  [E*·length²]", "")
        title = "adhesive loop"
    if branch is None:
        raise ValueError("adhesion_loop: the run has no branches (not an adhesive run)")
    mark = None
    if pull is not None:
        point = lambda p: (float(p["indentation"]), float(p["force"]))  # noqa: E731
        mark = (point(pull["force_controlled"]), point(pull["displacement_controlled"]))
    text = _asperity.adhesion_loop_figure(
        [float(v) for v in d], [float(v) for v in f], [b == "retract" for b in branch],
        mark, title, *labels,
        None if theory is None else (str(theory[0]), [(float(x), float(y)) for x, y in theory[1]]))
    return _draw(json.loads(text)["charts"][0], ax)


def field(values: Any, ax=None, *, size: Optional[tuple] = None, label: str = "",
          cmap: str = "magma"):
    """A rows × cols field (the ``plastic_displacement`` of a capped solve, the
    ``permanent_displacement`` of a load path, a pressure or a gap) as an image with y up
    and a colour bar named ``label``; ``size``: (L_x, L_y) for the axes' extent."""
    data = _np.asarray(values, dtype=float)
    if data.ndim != 2:
        raise ValueError(f"field: expected a 2D array, got shape {data.shape}")
    ax = _axes(ax)
    rows, cols = data.shape
    extent = (0, size[0], 0, size[1]) if size is not None else (0, cols, 0, rows)
    image = ax.imshow(data, origin="lower", extent=extent, cmap=cmap, interpolation="nearest")
    ax.figure.colorbar(image, ax=ax, label=label)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    return ax


def _study_chart(result: Any, kind: str) -> dict:
    if not result.figures or kind not in result.figures:
        raise ValueError(f"this study result has no {kind} figure (a result saved before "
                         "figures were kept: rerun the study, which resumes from its folder)")
    return _charts(result.figures[kind])[0]


def _is_contact_sweep(result: Any) -> bool:
    from . import Sweep

    return isinstance(result, Sweep) and "force_n" in result.columns


def _contact_charts(sweep: Any) -> list:
    """``asperity contact --plot``'s panels of an :func:`asperity.contact` sweep: k(F), A(F)
    and the mean gap, in N, N/m, m² and m; titled by the measured file's name."""
    from . import _asperity

    c = sweep.columns
    source = sweep.metadata.get("surface", {}).get("provenance", {}).get("source")
    name = os.path.basename(source) if source else "surface"
    text = _asperity.contact_figure(
        c["force_n"].tolist(), c["stiffness_n_per_m"].tolist(), c["contact_area_m2"].tolist(),
        c["mean_gap_m"].tolist(), float(c["effective_modulus"]), name)
    return _record(text)


def _unplottable(result: Any, what: str) -> ValueError:
    return ValueError(f"{what}: expected a study_curve result, a Solver.sweep or an "
                      f"asperity.contact sweep, got {type(result).__name__}")


def _is_solver_sweep(result: Any) -> bool:
    from . import Sweep

    return isinstance(result, Sweep) and "force" in result.columns


def stiffness(result: Any, ax=None):
    """k(F), log–log, as the CLI draws it (one definition, ``asperity_app::figure``): a
    :func:`~asperity.study_curve` result's ensemble-mean curves with the 95 % interval of
    the mean as bands and a k ∝ F reference (``asperity study curve``'s figure), a
    ``Solver.sweep``'s frozen-set stiffness (and finite difference) as ``asperity bem
    --plot`` draws it, or an :func:`~asperity.contact` sweep's k(F) in N/m as ``asperity
    contact --plot`` draws it."""
    from . import StudyResult

    if isinstance(result, StudyResult):
        return _draw(_study_chart(result, "curve"), ax)
    if _is_solver_sweep(result):
        return _draw(_sweep_charts(result)[0], ax)
    if _is_contact_sweep(result):
        return _draw(_contact_charts(result)[0], ax)
    raise _unplottable(result, "stiffness")


def area(result: Any, ax=None):
    """The contact area against force, log–log, by the library's figure definitions: a
    ``Solver.sweep``'s fraction A/A₀ as ``asperity bem --plot`` draws it, an
    :func:`~asperity.contact` sweep's true area in m² as ``asperity contact --plot`` draws
    it, or a :func:`~asperity.study_curve` result's ensemble-mean A/A₀ per task with the
    95 % interval of the mean as a band (``area_fraction``, ``area_fraction_low`` and
    ``area_fraction_high`` of ``curve.csv``)."""
    from . import StudyResult

    if isinstance(result, StudyResult):
        return _draw(_study_chart(result, "area"), ax)
    if _is_solver_sweep(result):
        return _draw(_sweep_charts(result)[1], ax)
    if _is_contact_sweep(result):
        return _draw(_contact_charts(result)[1], ax)
    raise _unplottable(result, "area")


def _contact_map_charts(contact_set: Any, size: Optional[tuple] = None,
                        metres: Optional[bool] = None, name: str = "contact set") -> list:
    """``asperity contact --map``'s chart of a contact set (or a contact sweep's ``map``)."""
    from . import Sweep, _asperity

    if isinstance(contact_set, Sweep):
        if "map" not in contact_set.columns:
            raise ValueError("contact_map: the sweep has no map (asperity.contact(..., "
                             "map=True))")
        sizes = contact_set.metadata.get("sizes", [None, None])
        rows, cols = contact_set.map.shape
        if size is None and sizes[0] is not None:
            sx = float(sizes[0])
            size = (sx, sx * rows / cols if sizes[1] is None else float(sizes[1]))
        metres = True if metres is None else metres
        contact_set = contact_set.map
    array = _np.asarray(contact_set)
    if array.dtype != _np.bool_ or array.ndim != 2:
        raise ValueError(f"contact_map: expected a 2D boolean array, got {array.dtype} of "
                         f"shape {array.shape}")
    rows, cols = array.shape
    sx, sy = (float(cols), float(rows)) if size is None else (float(size[0]), float(size[1]))
    return _record(_asperity.contact_map_figure(_np.ascontiguousarray(array), sx, sy,
                                                bool(metres), name))


def contact_map(contact_set: Any, ax=None, *, size: Optional[tuple] = None,
                metres: Optional[bool] = None, name: str = "contact set"):
    """A contact set as ``asperity contact --map`` draws it (one definition): each
    4-connected patch (the rule of :func:`asperity.patches` and the ``patches`` column) in
    a colour of its own, free surface white, the patch count and the share in contact in
    the title, and a scale bar. ``contact_set``: a 2D boolean array (e.g. ``result.pressure
    > 0``) or a :func:`asperity.contact` sweep with ``map=True`` (its sizes, in metres);
    ``size`` ``(x, y)``: the extent (default: the sweep's sizes, or one unit a point);
    ``metres``: name the scale bar's unit (default: for a contact sweep)."""
    charts = _contact_map_charts(contact_set, size, metres, name)
    return _draw(charts[0], ax)


def alpha(result: Any, ax=None):
    """α(H) of a :func:`~asperity.study_alpha` result as ``asperity study alpha`` draws it:
    per (method, N) the ensemble α with the 2.5–97.5 % range of the per-sample α as error
    bars, the theory curves (6), 1/3 (Hertz) and (24) per N; a study of one H over several N
    as α(log₂ N) beside eq. (24)."""
    from . import StudyResult

    if not isinstance(result, StudyResult) or "alpha" not in result.columns:
        raise ValueError("alpha: expected the result of asperity.study_alpha")
    return _draw(_study_chart(result, "alpha"), ax)
