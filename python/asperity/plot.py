"""Plotting helpers on matplotlib (an optional dependency: ``pip install matplotlib``).

Each function draws one of the figures the ``asperity`` command writes, from the objects
the package returns, onto a matplotlib ``Axes`` (a new figure when ``ax`` is None) and
returns the ``Axes``:

* :func:`surface` -- a height map in physical units, with a scale bar and a colour bar
  (``asperity surface --png``, ``import``);
* :func:`psd` -- the PSD against q·L/2π, log–log, with the fitted power law over its fit
  range (``asperity stats --plot``);
* :func:`stiffness`, :func:`area` -- k(F) and the contact fraction against force, with the
  95 % interval of an ensemble mean as a band (``asperity study curve``, ``bem --plot``,
  ``contact --plot``);
* :func:`contact_map` -- a contact set with its 4-connected patches coloured
  (``asperity contact --map``);
* :func:`alpha` -- α(H) with its 95 % intervals and the theory (``asperity study alpha``);
* :func:`load_path` -- a load path's loading–unloading loop (``bem --load-path --plot``);
  :func:`field` -- a field (the plastic or permanent displacement) as an image;
* :func:`figure` -- any figure the CLI wrote as data (``--plot FILE.json``).

The sweep and study figures (:func:`stiffness` and :func:`area` of a ``Solver.sweep``,
:func:`stiffness` of ``study_curve``, :func:`alpha`) are defined once, in the library's
front-end layer, for the CLI and the package: the same series, theory curves, intervals,
labels and titles as the CLI's PNG (``asperity_app::figure``); the package draws that
definition with matplotlib.

Example::

    >>> import asperity, asperity.plot
    >>> s = asperity.surface(128, hurst=0.8, rolloff=4, seed=1)
    >>> ax = asperity.plot.psd(asperity.psd(s))
    >>> ax.figure.savefig("psd.png")
"""

from __future__ import annotations

import math
from typing import Any, Optional

import numpy as _np

__all__ = ["surface", "psd", "stiffness", "area", "contact_map", "alpha", "figure"]


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


def _round_length(length: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above ``length``."""
    exponent = math.floor(math.log10(length))
    for mantissa in (5, 2, 1):
        if mantissa * 10 ** exponent <= length:
            return mantissa * 10 ** exponent
    return 10 ** exponent


def _length_label(length: float, metres: bool) -> str:
    if not metres:
        return f"{length:g}"
    for unit, scale in (("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9)):
        if length >= scale:
            return f"{length / scale:g} {unit}"
    return f"{length / 1e-12:g} pm"


def surface(values: Any, ax=None, *, cmap: str = "viridis", scale_bar: bool = True):
    """The height map of a :class:`~asperity.Surface` or :class:`~asperity.Topography`
    (rows along y, drawn with y up), in physical units (``extent``), with a scale bar of
    a round length about a fifth of the width (metres named for a measured topography)
    and a colour bar of the heights."""
    from . import Surface, Topography

    if isinstance(values, Surface):
        heights, (sx, sy), metres = values.heights, values.physical_sizes, False
    elif isinstance(values, Topography):
        if values.size_y is None:
            raise ValueError("surface: a profile is no map")
        heights, (sx, sy), metres = values.heights, values.physical_sizes, True
    else:
        raise ValueError("surface: expected an asperity.Surface or asperity.Topography")
    ax = _axes(ax)
    image = ax.imshow(heights, origin="lower", extent=(0, sx, 0, sy), cmap=cmap,
                      interpolation="nearest")
    ax.figure.colorbar(image, ax=ax, label="height" + (" (m)" if metres else ""))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if scale_bar:
        from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

        length = _round_length(sx / 5)
        bar = AnchoredSizeBar(ax.transData, length, _length_label(length, metres),
                              "lower left", pad=0.4, color="white", frameon=False,
                              size_vertical=sy / 100)
        ax.add_artist(bar)
        ax.set_xticks([])
        ax.set_yticks([])
    return ax


def psd(spectrum: Any, ax=None, *, label: Optional[str] = None):
    """A :class:`~asperity.Psd` (or anything :func:`asperity.psd` takes) against q·L/2π,
    log–log, with the fitted power law drawn over its fit range and its exponent and Hurst
    estimate in the legend."""
    from . import Psd, psd as compute

    if not isinstance(spectrum, Psd):
        spectrum = compute(spectrum)
    ax = _axes(ax)
    keep = spectrum.psd > 0
    ax.loglog(spectrum.wavenumber[keep], spectrum.psd[keep], ".", label=label or "PSD")
    if spectrum.fit is not None:
        k = spectrum.wavenumber
        inside = (_np.rint(k) >= spectrum.fit_from) & (_np.rint(k) <= spectrum.fit_to)
        q = spectrum.q[inside]
        fit = spectrum.fit["prefactor"] * q ** spectrum.fit["exponent"]
        ax.loglog(k[inside], fit, "--", color="black",
                  label=f"fit: slope {spectrum.fit['exponent']:.3f}, H ≈ {spectrum.hurst:.3f}")
    ax.set_xlabel("q·L/2π (wavelengths per side)")
    ax.set_ylabel("PSD C(q)")
    ax.legend()
    return ax


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


def _draw(chart: dict, ax=None):
    """One chart of the library's figure definition (``asperity-figure/1``) on ``ax``."""
    ax = _axes(ax)
    for i, s in enumerate(chart["series"]):
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


def _curves(result: Any, column: str):
    """``(label, force, values, low, high)`` per curve of a study or a contact sweep."""
    from . import StudyResult, Sweep

    if isinstance(result, StudyResult):
        keys = list(zip(result.columns["method"], result.columns["n"], result.columns["hurst"]))
        out = []
        for key in dict.fromkeys(keys):
            rows = _np.array([k == key for k in keys])
            low = result.columns.get(f"{column}_low")
            high = result.columns.get(f"{column}_high")
            out.append((f"{key[0]} n={key[1]} H={key[2]:g}", result.columns["force"][rows],
                        result.columns[column][rows],
                        None if low is None else low[rows], None if high is None else high[rows]))
        return out
    if isinstance(result, Sweep):
        force = result.columns.get("force", result.columns.get("force_n"))
        names = {"stiffness": ("stiffness", "stiffness_n_per_m"),
                 "area_fraction": ("area_fraction",)}[column]
        values = next(result.columns[n] for n in names if n in result.columns)
        return [(column, force, values, None, None)]
    raise ValueError(f"expected a StudyResult (study_curve) or a Sweep, got {type(result).__name__}")


def _against_force(result: Any, column: str, ylabel: str, ax):
    ax = _axes(ax)
    for label, force, values, low, high in _curves(result, column):
        keep = (force > 0) & (values > 0)
        (line,) = ax.loglog(force[keep], values[keep], "-", label=label)
        if low is not None and high is not None:
            ax.fill_between(force[keep], low[keep], high[keep], color=line.get_color(),
                            alpha=0.25, linewidth=0)
    ax.set_xlabel("force F")
    ax.set_ylabel(ylabel)
    ax.legend()
    return ax


def _is_solver_sweep(result: Any) -> bool:
    from . import Sweep

    return isinstance(result, Sweep) and "force" in result.columns


def stiffness(result: Any, ax=None):
    """k(F), log–log: a :func:`~asperity.study_curve` result's ensemble-mean curves with
    the 95 % interval of the mean as bands and a k ∝ F reference (``asperity study curve``'s
    figure), or a ``Solver.sweep``'s frozen-set stiffness (and finite difference) as
    ``asperity bem --plot`` draws it; a :func:`~asperity.contact` sweep's k(F) in N/m."""
    from . import StudyResult

    if isinstance(result, StudyResult) and result.figures:
        return _draw(_study_chart(result, "curve"), ax)
    if _is_solver_sweep(result):
        return _draw(_sweep_charts(result)[0], ax)
    return _against_force(result, "stiffness", "contact stiffness k", ax)


def area(result: Any, ax=None):
    """The contact fraction A/A₀ against force, log–log: a ``Solver.sweep`` as
    ``asperity bem --plot`` draws it, or a study's mean curves (with their bands) or a
    :func:`~asperity.contact` sweep."""
    if _is_solver_sweep(result):
        return _draw(_sweep_charts(result)[1], ax)
    return _against_force(result, "area_fraction", "contact fraction A/A₀", ax)


def contact_map(contact_set: Any, ax=None, *, size: Optional[tuple] = None):
    """A contact set (2D boolean array, e.g. ``sweep.map`` of :func:`asperity.contact` or
    ``result.pressure > 0``) with each 4-connected patch in its own colour (free surface
    white) and the patch count in the title; ``size`` ``(x, y)`` sets the axes' extent."""
    from . import patches

    found = patches(_np.asarray(contact_set, dtype=bool))
    ax = _axes(ax)
    plt = _pyplot()
    rng = _np.random.default_rng(0)  # distinct, repeatable colours per patch
    colours = _np.vstack([[1.0, 1.0, 1.0], plt.get_cmap("tab20")(
        rng.integers(0, 20, size=len(found)))[:, :3] if len(found) else _np.zeros((0, 3))])
    image = colours[found.labels]
    rows, cols = found.labels.shape
    extent = (0, cols, 0, rows) if size is None else (0, size[0], 0, size[1])
    ax.imshow(image, origin="lower", extent=extent, interpolation="nearest")
    ax.set_title(f"{len(found)} contact patches, {found.points.sum() / found.labels.size:.2%} "
                 "in contact")
    return ax


def alpha(result: Any, ax=None):
    """α(H) of a :func:`~asperity.study_alpha` result as ``asperity study alpha`` draws it:
    per (method, N) the ensemble α with the 2.5–97.5 % range of the per-sample α as error
    bars, the theory curves (6), 1/3 (Hertz) and (24) per N; a study of one H over several N
    as α(log₂ N) beside eq. (24)."""
    from . import StudyResult

    if not isinstance(result, StudyResult) or "alpha" not in result.columns:
        raise ValueError("alpha: expected the result of asperity.study_alpha")
    return _draw(_study_chart(result, "alpha"), ax)
