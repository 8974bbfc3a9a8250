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
* :func:`alpha` -- α(H) with its 95 % intervals and the theory (``asperity study alpha``).

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

__all__ = ["surface", "psd", "stiffness", "area", "contact_map", "alpha"]


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


def _curves(result: Any, column: str):
    """``(label, force, values, low, high)`` per curve of a study or a sweep."""
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


def stiffness(result: Any, ax=None):
    """k(F), log–log: each curve of a :func:`~asperity.study_curve` result with its 95 %
    interval of the mean as a band, or a :class:`~asperity.Sweep`'s frozen-set stiffness."""
    return _against_force(result, "stiffness", "contact stiffness k", ax)


def area(result: Any, ax=None):
    """The contact fraction A/A₀ against force, log–log (a study's mean curves or a
    sweep)."""
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
    """α(H) of a :func:`~asperity.study_alpha` result: per grid size the ensemble α with
    the 2.5–97.5 % range of the per-sample α as error bars, and the theory (dashed)."""
    from . import StudyResult

    if not isinstance(result, StudyResult) or "alpha" not in result.columns:
        raise ValueError("alpha: expected the result of asperity.study_alpha")
    c = result.columns
    ax = _axes(ax)
    for n in dict.fromkeys(c["n"].tolist()):
        rows = c["n"] == n
        h, a = c["hurst"][rows], c["alpha"][rows]
        err = _np.vstack([a - c["alpha_low"][rows], c["alpha_high"][rows] - a])
        ax.errorbar(h, a, yerr=_np.where(_np.isfinite(err), err, 0.0), fmt="o",
                    capsize=3, label=f"{c['method'][rows][0]} n={n}")
    theory = _np.isfinite(c["alpha_theory"])
    if theory.any():
        order = _np.argsort(c["hurst"][theory])
        ax.plot(c["hurst"][theory][order], c["alpha_theory"][theory][order], "--",
                color="black", label="theory")
    ax.set_xlabel("Hurst exponent H")
    ax.set_ylabel("α in k ∝ F^α")
    ax.legend()
    return ax
