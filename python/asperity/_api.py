"""The implementation of asperity's public API (private: import from ``asperity``).

``asperity/__init__.py`` re-exports the public names listed in its ``__all__``; this module
also holds the helpers (numpy, os, json, ...) that must not appear in the package's
namespace. See the package docstring for the conventions."""

from __future__ import annotations

import json
import os
import sys
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _asperity as _core
from . import _mpi
from ._asperity import __version__

# The defaults shared with the CLI, written once in the front-end layer (asperity_app):
# modulus, boundary, solver, tolerance, max_iterations, fd_step, gamma, kappa, size.
_DEFAULTS: Dict[str, Any] = _core.defaults()
_EXACT_INT = 2**53  # integers above this do not convert to float64 without loss


def _float64(values: Any, what: str) -> np.ndarray:
    """``values`` as a float64 array in native byte order: the array itself when it already
    is one (any strides: no copy here), else a converted copy. Refuses dtypes that do not
    convert without loss (complex, object, strings, float128, integers beyond 2^53)."""
    array = np.asarray(values)
    if array.dtype == np.float64:
        return array
    if array.dtype.kind not in "biuf":
        raise ValueError(f"{what}: expected real numbers, got dtype {array.dtype}")
    if not np.can_cast(array.dtype, np.float64, casting="safe"):
        raise ValueError(f"{what}: dtype {array.dtype} does not convert to float64 without loss")
    if array.dtype.kind in "iu" and array.dtype.itemsize >= 8 and array.size:
        if max(abs(int(array.min())), abs(int(array.max()))) > _EXACT_INT:
            raise ValueError(f"{what}: integers beyond 2^53 do not convert to float64 without loss")
    return array.astype(np.float64)


def _sizes(size: Union[None, float, Sequence[float]]) -> Tuple[Optional[float], Optional[float]]:
    """``size=`` of a surface or line argument: None, ``x`` or ``(x, y)``, by the rule of the
    CLI's ``--size`` (the front-end layer's ``argument::sizes``: one or two, positive and
    finite)."""
    if size is None:
        return None, None
    values = [float(v) for v in size] if isinstance(size, (tuple, list)) else [float(size)]
    x, y = _core.sizes(values)
    return x, y


class _Saved:
    """``save`` for a result dataclass: its numpy arrays as ``.npy`` members of ``path``
    (``.npz``) and every other field (numbers, strings, lists, dicts, None) in the JSON
    sidecar, both or neither; :func:`load` gives back the same object (arrays bit for bit,
    dtypes kept). A non-finite number outside the arrays is refused (JSON has none)."""

    _kind = ""

    def save(self, path: Union[str, os.PathLike], *, force: bool = False) -> None:
        """Writes ``path`` (``.npz``: the arrays) and ``path.json`` (the other fields),
        both or neither (an existing file is refused unless ``force``); :func:`load`
        gives back the same object."""
        import dataclasses

        arrays, values = {}, {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, np.ndarray):
                arrays[f.name] = value
            else:
                values[f.name] = value
        _save_bundle(path, self._kind, arrays, {"values": values}, force)


# --------------------------------------------------------------------------------------
# Progress
# --------------------------------------------------------------------------------------

ProgressArg = Union[None, bool, str, Callable[[int, int], Any]]


class _Progress:
    """What a ``progress=`` argument asks for: nothing (None/False), a tqdm bar (True or
    ``"tqdm"``; a plain line on stderr when tqdm is not installed) or a callable
    ``progress(done, total)``.

    A study hands its ETA over (:meth:`weigh`, the front-end layer's arithmetic that the
    CLI's bar uses: samples read back from checkpoints do not count towards the rate, each
    sample weighs its cost); the bar and the plain line then show it instead of a rate
    that counts restored samples as done at once."""

    def __init__(self, progress: ProgressArg, description: str):
        import time

        self.bar = None
        self.callback: Optional[Callable[[int, int], Any]] = None
        self.description = description
        self.eta = None
        self.start = time.monotonic()
        if progress is None or progress is False:
            return
        if callable(progress):
            self.callback = progress
            return
        if progress is True or progress == "tqdm":
            try:
                from tqdm.auto import tqdm
            except ImportError:
                self.callback = _plain_progress(self)
                return
            self.bar = tqdm(desc=description, total=None)
            self.callback = self._update
            return
        raise ValueError(f"progress: expected None, True, 'tqdm' or a callable, got {progress!r}")

    def weigh(self, eta: Any) -> None:
        """Takes a study's ETA (``_core.StudyEta``); the clock of this run starts here."""
        import time

        self.eta, self.start = eta, time.monotonic()
        if self.bar is not None:
            self.bar.bar_format = "{l_bar}{bar}| {n_fmt}/{total_fmt} [{elapsed}{postfix}]"

    def remaining(self, done: int) -> Optional[float]:
        """Seconds left by the study's ETA, or None (no ETA handed over, or none yet)."""
        import time

        if self.eta is None:
            return None
        return self.eta.remaining(done, time.monotonic() - self.start)

    def _update(self, done: int, total: int) -> None:
        if self.bar.total != total:
            self.bar.total = total
        self.bar.n = done
        if self.eta is not None:
            left = self.remaining(done)
            self.bar.set_postfix_str("ETA ?" if left is None else f"ETA {left:.0f} s",
                                     refresh=False)
        self.bar.refresh()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _plain_progress(state: _Progress) -> Callable[[int, int], None]:
    """Progress on stderr without tqdm: one line rewritten in place on a terminal, else a
    line at most every 5 s and at the end; a study's with the CLI's words and ETA."""
    import time

    tty = sys.stderr.isatty()
    last = [float("-inf")]

    def report(done: int, total: int) -> None:
        now = time.monotonic()
        if done < total and (now - last[0] < (0.1 if tty else 5.0)):
            return
        last[0] = now
        text = f"{state.description}: {done}/{total}"
        if state.eta is not None:
            text = state.eta.line(state.description, done, now - state.start) or text
        if tty:
            print("\r" + text, end="\n" if done >= total else "", file=sys.stderr, flush=True)
        else:
            print(text, file=sys.stderr, flush=True)

    return report


# --------------------------------------------------------------------------------------
# Surfaces and lines
# --------------------------------------------------------------------------------------


@dataclass
class Surface:
    """A rough surface: ``heights`` (rows × cols = y × x, float64) with its metadata.

    ``metadata`` is the JSON sidecar ``asperity surface`` writes (kind, generator, shape,
    seed, spec with the PSD and normalisation, stats). The object also looks like a
    SurfaceTopography topography (``physical_sizes``; ``np.asarray(surface)`` gives the
    heights), and :meth:`save` writes the CLI's ``.npy`` + ``.npy.json`` pair.

    Example::

        >>> s = asperity.surface(64, hurst=0.5, rms_height=1e-3, seed=3)
        >>> s.heights.shape, s.size, round(s.stats["rms_height"], 12)
        ((64, 64), 1.0, 0.001)
    """

    heights: np.ndarray
    size: float = _DEFAULTS["size"]
    metadata: Dict[str, Any] = field(default_factory=dict)

    @property
    def shape(self) -> Tuple[int, int]:
        return self.heights.shape

    @property
    def size_y(self) -> float:
        """Side along y (rows); pixels are square."""
        rows, cols = self.heights.shape
        return self.size * rows / cols

    @property
    def physical_sizes(self) -> Tuple[float, float]:
        """``(size_x, size_y)``."""
        return (self.size, self.size_y)

    @property
    def seed(self) -> Optional[int]:
        return self.metadata.get("seed")

    @property
    def stats(self) -> Dict[str, Any]:
        """rms height, slope, curvature (recorded at generation)."""
        return self.metadata.get("stats", {})

    def __array__(self, dtype=None, copy=None):
        return self.heights if dtype is None else self.heights.astype(dtype)

    def save(self, path: Union[str, os.PathLike], *, force: bool = False) -> None:
        """Writes ``path`` (.npy, float64) and its sidecar ``path.json``, as ``asperity
        surface`` does (both or neither; an existing file is refused unless ``force``):
        :func:`load` gives back the same surface, and :func:`read_topography` and every
        CLI command read its size from the sidecar. A path ending in ``.x3p`` writes an
        ISO 25178-72 X3P file instead (heights and both sizes; the seed and spec are not
        kept), which :func:`load` reads back as a :class:`Topography`.

        Example::

            >>> s = asperity.surface(32, hurst=0.8, size=2.0, seed=1)
            >>> s.save("s.npy")
            >>> back = asperity.load("s.npy")
            >>> bool((back.heights == s.heights).all()), back.size, back.seed
            (True, 2.0, 1)
        """
        if _is_x3p(path):
            provenance = _generated_provenance(self.metadata)
            _core.save_topography(os.fspath(path), self.heights, [self.size, self.size_y],
                                  json.dumps(provenance), bool(force))
            return
        _core.save_heights(os.fspath(path), self.heights, json.dumps(self.metadata), force)

    def __repr__(self) -> str:
        rows, cols = self.heights.shape
        return f"Surface({rows}x{cols}, size={self.size}, seed={self.seed})"


def _is_x3p(path: Union[str, os.PathLike]) -> bool:
    return os.fspath(path).lower().endswith(".x3p")


def _generated_provenance(metadata: Dict[str, Any]) -> Dict[str, Any]:
    """The provenance record of a generated surface written to a file format that carries
    no asperity sidecar (X3P)."""
    return {"source": "", "format": metadata.get("generator", "asperity"),
            "channel": "heights", "channel_index": 0, "channels": ["heights"],
            "file_unit": None, "unit": None, "size_source": "given", "cleaning": []}


@dataclass
class Line:
    """A rough line: ``heights`` (n, float64), its length ``size`` and the metadata of
    ``asperity line`` (see :class:`Surface`)."""

    heights: np.ndarray
    size: float = _DEFAULTS["size"]
    metadata: Dict[str, Any] = field(default_factory=dict)

    @property
    def seed(self) -> Optional[int]:
        return self.metadata.get("seed")

    @property
    def stats(self) -> Dict[str, Any]:
        return self.metadata.get("stats", {})

    def __len__(self) -> int:
        return len(self.heights)

    def __array__(self, dtype=None, copy=None):
        return self.heights if dtype is None else self.heights.astype(dtype)

    def save(self, path: Union[str, os.PathLike], *, force: bool = False) -> None:
        """Writes ``path`` (.npy) and ``path.json`` as ``asperity line`` does; :func:`load`
        gives back the same line."""
        _core.save_heights(os.fspath(path), self.heights, json.dumps(self.metadata), force)

    def __repr__(self) -> str:
        return f"Line({len(self.heights)}, size={self.size}, seed={self.seed})"


def surface(
    n: int,
    *,
    hurst: float,
    m: Optional[int] = None,
    rolloff: Optional[float] = None,
    cutoff: Optional[float] = None,
    short_cutoff: Optional[float] = None,
    rms_height: Optional[float] = None,
    rms_slope: Optional[float] = None,
    size: float = _DEFAULTS["size"],
    seed: int = _DEFAULTS["seed"],
) -> Surface:
    """A self-affine rough surface, as ``asperity surface`` (bit-identical for a seed).

    Parameters (the CLI's options): ``n`` points along x (columns), ``m`` along y (rows,
    default n); ``hurst`` H in [-1, 3], ``C2D(q) ∝ q^(-2H-2)``; ``rolloff`` q0·L/2π (flat
    below q0, paper eq. 7) or ``cutoff`` q0·L/2π (no power below, eq. 8); ``short_cutoff``
    q1·L/2π (no power above); ``rms_height`` or ``rms_slope`` (default: unit rms height);
    ``size`` L along x; ``seed``.

    Example::

        >>> s = asperity.surface(256, hurst=0.8, rolloff=6, rms_slope=1.0, seed=1)
        >>> round(s.stats["rms_slope"], 9)
        1.0
    """
    heights, meta = _core.generate_surface(
        n, m, float(hurst), _opt(rolloff), _opt(cutoff), _opt(short_cutoff),
        _opt(rms_height), _opt(rms_slope), float(size), _seed(seed),
    )
    return Surface(heights, float(size), json.loads(meta))


def line(
    n: int,
    *,
    hurst: float,
    rolloff: Optional[float] = None,
    cutoff: Optional[float] = None,
    rms_height: Optional[float] = None,
    rms_slope: Optional[float] = None,
    size: float = _DEFAULTS["size"],
    seed: int = _DEFAULTS["seed"],
) -> Line:
    """A self-affine rough line (``C1D = π q C2D``, paper eqs. 9-11), as ``asperity line``.

    Example::

        >>> l = asperity.line(4096, hurst=0.5, seed=3)
        >>> len(l), round(l.stats["rms_height"], 9)
        (4096, 1.0)
    """
    heights, meta = _core.generate_line(
        n, float(hurst), _opt(rolloff), _opt(cutoff), _opt(rms_height), _opt(rms_slope),
        float(size), _seed(seed),
    )
    return Line(heights, float(size), json.loads(meta))


def _seed(seed: Any) -> str:
    """A seed as the front-end layer reads it: an integer's digits; anything else (1.5,
    True) as written, which the layer refuses in the CLI's words."""
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_)):
        return str(int(seed))
    return str(seed)


def _opt(value: Optional[float]) -> Optional[float]:
    return None if value is None else float(value)


def _text(value: Any) -> Optional[str]:
    return None if value is None else str(value)


def _tangential(tangential: Union[bool, str]) -> Tuple[bool, Optional[str]]:
    """:func:`contact`'s ``tangential``: False (none), True (both directions) or the
    directions ``"x"``, ``"y"``, ``"both"`` (checked by the front-end layer), as the CLI's
    ``--tangential[=DIR]``."""
    if isinstance(tangential, str):
        return True, tangential
    return bool(tangential), None


def _stats_source(values: Any, size: Union[None, float, Tuple[float, float]]
                  ) -> Tuple[np.ndarray, float, Optional[float], bool, Optional[str]]:
    """What :func:`stats` and :func:`psd` hand to the front-end layer: heights, size along x,
    size along y (rectangular pixels), whether they are measured (ISO parameters, a size per
    axis) and a generated surface's metadata (JSON: its spectrum sets the default fit
    range)."""
    if isinstance(values, (Surface, Line)):
        if isinstance(size, (tuple, list)):
            raise ValueError("size: a generated surface has square pixels; give one size")
        size_x = values.size if size is None else _sizes(size)[0]
        return values.heights, size_x, None, False, json.dumps(values.metadata)
    if isinstance(values, Topography):
        if size is not None:
            raise ValueError("size: the topography has its own sizes")
        return values.heights, values.size, values.size_y, True, None
    heights_of = getattr(values, "heights", None)
    if callable(heights_of) and hasattr(values, "physical_sizes"):
        # SurfaceTopography: heights()[x, y] with physical_sizes (sx,) or (sx, sy).
        if size is not None:
            raise ValueError("size: the topography has its own physical_sizes")
        sizes = [float(v) for v in np.atleast_1d(values.physical_sizes)]
        heights = _float64(heights_of(), "heights")
        if heights.ndim == 2:
            if len(sizes) != 2:
                raise ValueError(f"heights: expected two physical sizes (sx, sy), got {sizes!r}")
            return heights.T, sizes[0], sizes[1], True, None
        return heights, sizes[0], None, True, None
    if np.asarray(values).dtype == object:
        raise ValueError(
            f"values: expected an asperity Surface, Line or Topography, a SurfaceTopography "
            f"topography or an array of heights, got {type(values).__name__}")
    heights = _float64(values, "heights")
    size_x, size_y = _sizes(size)
    if size_y is not None:
        if heights.ndim != 2:
            raise ValueError(f"size: give L, or (x, y) for a 2D map, got {size!r}")
        return heights, size_x, size_y, True, None
    return heights, _DEFAULTS["size"] if size_x is None else size_x, None, False, None


def _statistics(values: Any, size, fit_from, fit_to, window: str = _DEFAULTS["window"],
                convention: str = _DEFAULTS["convention"]) -> Dict[str, Any]:
    heights, size_x, size_y, measured, metadata = _stats_source(values, size)
    result = _core.statistics(heights, size_x, size_y, measured, metadata,
                              _opt(fit_from), _opt(fit_to), str(window), str(convention))
    if result["iso"] is not None:
        result["iso"] = json.loads(result["iso"])
    result["ndim"] = heights.ndim
    return result


_PSD_KEYS = ("q", "psd", "modes", "size", "ndim", "fit_prefactor", "fit_stderr",
             "fit_points")


def stats(values: Any, *, size: Union[None, float, Tuple[float, float]] = None,
          fit_from: Optional[float] = None, fit_to: Optional[float] = None,
          window: str = _DEFAULTS["window"]) -> Dict[str, Any]:
    """The statistics ``asperity stats`` prints, by the same code: ``rms_height``,
    ``rms_slope`` (forward differences), ``rms_curvature`` (half the rms five-point
    Laplacian; per-axis spacings on rectangular pixels), the PSD's power-law fit
    (``psd_slope`` with its 95 % interval ``psd_slope_low`` .. ``psd_slope_high``, over the
    rings ``fit_from`` .. ``fit_to`` in q·L/2π, ``fit_note`` when there is none, and
    ``hurst_estimate``) and, for a measured topography, ``iso``: the ISO 25178 (map) or
    ISO 4287 (profile) parameters.

    ``values``: a :class:`Surface` or :class:`Line` (their spec sets the default fit range,
    as the sidecar does for the CLI), a :class:`Topography` (both sizes: rectangular pixels
    are handled), a SurfaceTopography topography, or an array with ``size`` = L along x
    (square pixels; default 1) or ``(x, y)`` for a map with rectangular pixels.
    ``fit_from``/``fit_to`` default to 2 (or the spec's roll-off or cut-off) and Nyquist
    (or below the spec's short cut-off). ``window``: the window of the PSD whose slope is
    fitted (see :func:`psd`; the rms values are of the heights as they are).

    Example::

        >>> asperity.stats(asperity.line(1024, hurst=0.5, rms_slope=2.0))["rms_slope"]
        2.0...
    """
    result = _statistics(values, size, fit_from, fit_to, window)
    for key in _PSD_KEYS:
        del result[key]
    return result


@dataclass
class Analysis(_Saved):
    """One analysis of ``asperity stats`` (:func:`analysis`): ``name`` (the CLI's option
    without its dashes and with underscores: ``acf_2d`` for ``--acf-2d``), ``columns`` (the
    names of the two columns of the CSV the CLI writes) and their values ``x`` and ``y``
    (float64, bit for bit the CLI's). ``a["distance"]`` is a column by name, ``a.table`` both
    as a dict (``pandas.DataFrame(a.table)`` copies nothing). ``metres``: lengths and
    heights in metres (of a :class:`Topography`), else in the heights' own unit (the
    axes of :func:`asperity.plot.analysis`)."""

    name: str
    columns: List[str]
    x: np.ndarray
    y: np.ndarray
    metres: bool = False

    @property
    def table(self) -> Dict[str, np.ndarray]:
        return dict(zip(self.columns, (self.x, self.y)))

    def __getitem__(self, column: str) -> np.ndarray:
        table = self.table
        if column not in table:
            raise KeyError(f"{column!r}: the columns of {self.name} are {self.columns}")
        return table[column]

    def __len__(self) -> int:
        return len(self.x)

    def __repr__(self) -> str:
        return f"Analysis({self.name}, {len(self.x)} rows: {', '.join(self.columns)})"


ANALYSES: Tuple[str, ...] = tuple(_core.analysis_names())
"""The names :func:`analysis` takes, in the order of ``asperity stats --help``."""


def analysis(values: Any, name: str, *,
             size: Union[None, float, Tuple[float, float]] = None) -> Analysis:
    """One analysis of ``asperity stats`` by the same code and numbers (the front-end
    layer's ``stats::analysis``), from the heights as they are (level and fill a measured
    file when reading it: :func:`read_topography`'s ``detrend`` and ``fill``). ``name`` is
    the option without its dashes (see :data:`ANALYSES`):

    * ``bearing_area`` -- the bearing-area (Abbott-Firestone) curve: ``material_ratio``
      (0 to 1 in 101 steps) and ``height`` above which that fraction of the defined heights
      lies (ISO 25178-2's Smr(c), inverted);
    * ``acf`` -- the height-difference ACF along x: ``distance`` r = kΔx and ``acf``
      ½⟨(h(x + r) − h(x))²⟩ over the pairs of defined points in a row, pooled over the rows;
    * ``acf_2d`` -- its radial average over every direction on a map (``distance``, the
      mean distance of a bin's pairs, and ``acf``); refused for a profile;
    * ``variable_bandwidth`` -- ``bandwidth`` ℓ and ``rms_height`` after a plane (a line on a
      profile) is removed in each of 1, 2, 4, ... sections a side;
    * ``scale_dependent_slope`` -- ``distance`` and ``slope`` √(2A(r))/r from the ACF;
    * ``scale_dependent_curvature`` -- ``distance`` 2sΔx and ``curvature``, the rms of
      (h[i+s] − 2h[i] + h[i−s])/(sΔx)²;
    * ``height_distribution``, ``slope_distribution``, ``curvature_distribution`` -- the
      value (bin centre) and its ``density`` (integrating to 1) over ⌊√n⌋ bins (10 to 100).

    ``values`` and ``size`` as for :func:`stats` (a :class:`Topography` brings its sizes;
    an array takes ``size`` = L along x, or ``(x, y)``). Units: the heights' (metres for a
    measured file). See docs/topography.md for each definition and its check against
    SurfaceTopography.

    Example::

        >>> ramp = asperity.analysis(np.arange(64.0), "scale_dependent_slope", size=4.0)
        >>> ramp.columns, round(float(ramp["slope"][0]), 6)
        (['distance', 'slope'], 16.0)
    """
    heights, size_x, size_y, measured, metadata = _stats_source(values, size)
    ((first, x), (second, y)), = _core.analyses(heights, size_x, size_y, measured, metadata,
                                                [str(name)])
    return Analysis(str(name), [first, second], x, y, isinstance(values, Topography))


@dataclass
class Psd(_Saved):
    """A power spectrum: wavenumbers ``q`` (rad/length), values ``psd`` (C2D for a surface,
    radially averaged; C1D for a line), ``modes`` per bin and ``wavenumber`` = q·L/2π; the
    power law ``fit`` (exponent, prefactor, stderr, low, high, points) over the rings
    ``fit_from`` .. ``fit_to`` and ``hurst``, or ``None`` with the reason in ``fit_note``;
    ``size`` is the side length L along x and ``ndim`` 2 for a surface, 1 for a line."""

    q: np.ndarray
    psd: np.ndarray
    modes: np.ndarray
    wavenumber: np.ndarray
    fit: Optional[Dict[str, float]] = None
    hurst: Optional[float] = None
    fit_from: Optional[float] = None
    fit_to: Optional[float] = None
    fit_note: Optional[str] = None
    size: float = 1.0
    ndim: int = 2


@dataclass
class Topography:
    """A measured topography read by asperity's own readers (:func:`read_topography`):
    ``heights`` (rows × cols = y × x for a map, or a profile along x; metres where the file
    gives a length unit; NaN where the instrument measured nothing), ``size`` along x,
    ``size_y`` along y (``None`` for a profile; pixels may be rectangular) and the
    ``provenance`` (source, format, channel, channels, units, where the sizes came from).
    A map can go straight to :class:`Solver` (both sizes are used) once it has no NaN.

    Example::

        >>> asperity.surface(64, hurst=0.8, rms_height=1e-6, size=1e-3, seed=1).save(
        ...     "scan.x3p")                      # a stand-in for a measured 1 mm map
        >>> t = asperity.read_topography("scan.x3p", detrend="plane")
        >>> t.heights.shape, t.size, t.size_y, t.provenance["format"]
        ((64, 64), 0.001, 0.001, 'x3p')
    """

    heights: np.ndarray
    size: float
    size_y: Optional[float]
    provenance: Dict[str, Any] = field(default_factory=dict)

    @property
    def physical_sizes(self) -> Tuple[float, ...]:
        return (self.size,) if self.size_y is None else (self.size, self.size_y)

    def save(self, path: Union[str, os.PathLike], *, force: bool = False) -> None:
        """Writes the topography as ``asperity import --out`` does, by the same code:
        ``path`` ``.npy`` (float64, metres) with the sidecar ``path.json`` (source, format,
        channel, units, sizes per axis, every cleaning step, and the provenance), or
        ``.x3p`` (ISO 25178-72; maps only). Both files or neither; an existing one is
        refused unless ``force``, and the file it was read from is never overwritten.
        :func:`load` gives back the same topography (heights bit for bit, sizes,
        provenance); :func:`read_topography` and the CLI read the sizes back.

        Example::

            >>> asperity.surface(64, hurst=0.8, rms_height=1e-6, size=1e-3, seed=1).save(
            ...     "scan.x3p")                              # a stand-in for a measured 1 mm map
            >>> t = asperity.read_topography("scan.x3p", detrend="plane")
            >>> t.save("scan.npy"); t.save("levelled.x3p")
            >>> back = asperity.load("scan.npy")
            >>> bool((back.heights == t.heights).all()), back.physical_sizes
            (True, (0.001, 0.001))
        """
        sizes = list(self.physical_sizes)
        _core.save_topography(os.fspath(path), self.heights, sizes,
                              json.dumps(self.provenance), bool(force))

    def __repr__(self) -> str:
        shape = "x".join(str(n) for n in self.heights.shape)
        sizes = " x ".join(f"{s:g}" for s in self.physical_sizes)
        return (f"Topography({shape}, sizes={sizes} m, "
                f"format={self.provenance.get('format')!r})")


class AsperityWarning(UserWarning):
    """The base of asperity's warnings (``warnings.simplefilter("error", AsperityWarning)``
    turns them all into errors)."""


class UnlevelledWarning(AsperityWarning):
    """A measured surface looks tilted and no levelling was chosen (``detrend=``): its
    heights are used as they are, which makes contact areas, slopes and heights wrong. The
    CLI prints the same words as ``warning:`` lines."""


class UnitWarning(AsperityWarning):
    """A measured file gives no unit: its numbers are used as metres."""


_WARNINGS = {"unlevelled": UnlevelledWarning, "unit": UnitWarning}


def read_topography(path: Union[str, "os.PathLike[str]"], *, channel: Union[None, str, int] = None,
                    size: Union[None, float, Tuple[float, float]] = None,
                    detrend: Optional[str] = None, fill: Optional[str] = None) -> Topography:
    """Reads a measured file with the library's readers and cleans it as asked, by the call
    ``asperity import`` and every command's measured surface use (format by content, then
    extension: X3P, SDF, text and Gwyddion matrices, x y z lists, x z profiles, SUR, PLU,
    OPD, DI, AL3D, MetroPro DAT, FRT, WSxM, TMD, ``.npy``). ``channel``: a name or 0-based
    index (default: the first height channel; a name that several channels share raises
    ``ValueError`` listing their indices: give the index); ``size``: ``x`` or ``(x, y)`` in metres
    where the file carries none, or to override it; ``detrend``: ``none``, ``mean``,
    ``plane``, ``poly2``, ``poly3``, ``lines`` or ``line-means`` (default: none chosen, and
    an :class:`UnlevelledWarning` when the surface looks tilted, as the CLI warns);
    ``fill``: ``harmonic`` (Laplace inpainting) or ``refuse`` undefined points (default:
    they stay NaN). A file with no unit gives a :class:`UnitWarning`. The cleaning is
    recorded in ``provenance["cleaning"]``. Bad files raise ``ValueError`` with the CLI's
    one line.

    Example::

        >>> asperity.surface(64, hurst=0.8, rms_height=1e-6, size=1e-3, seed=1).save(
        ...     "scan.x3p")                      # a stand-in for a measured 1 mm map
        >>> t = asperity.read_topography("scan.x3p", detrend="plane")
        >>> t.provenance["cleaning"]
        ['levelled: least-squares mean plane subtracted']
    """
    size_x, size_y = _sizes(size)
    heights, sizes, provenance, warned = _core.read_topography(
        os.fspath(path), None if channel is None else str(channel), size_x, size_y,
        detrend, fill)
    for category, words in warned:
        warnings.warn(f"{os.fspath(path)}: {words}", _WARNINGS[category], stacklevel=2)
    return Topography(heights=heights, size=float(sizes[0]),
                      size_y=float(sizes[1]) if len(sizes) > 1 else None,
                      provenance=json.loads(provenance))


def import_topography(path: Union[str, "os.PathLike[str]"], out: Union[str, "os.PathLike[str]"],
                      *, channel: Union[None, str, int] = None,
                      size: Union[None, float, Tuple[float, float]] = None,
                      detrend: Optional[str] = None, fill: Optional[str] = None,
                      force: bool = False) -> Topography:
    """``asperity import``: reads and cleans the measured file ``path`` as
    :func:`read_topography` (the same keywords; undefined points are refused unless
    ``fill`` is named, as the CLI refuses them) and writes it to ``out`` by the writer the
    CLI uses: a float64 ``.npy`` with the import sidecar ``out.json`` (source, format,
    channel, units, sizes per axis, every cleaning step; asperity reads the sizes back from
    it), or an ``.x3p`` file (maps only). Both files or neither; an existing output is
    refused unless ``force``. Returns the topography written.

    Example::

        >>> asperity.surface(64, hurst=0.8, rms_height=1e-6, size=1e-3, seed=1).save(
        ...     "scan.x3p")                      # a stand-in for a measured 1 mm map
        >>> t = asperity.import_topography("scan.x3p", "s.npy", detrend="plane")
        >>> bool((asperity.load("s.npy").heights == t.heights).all())
        True
    """
    size_x, size_y = _sizes(size)
    heights, sizes, provenance, warned = _core.import_topography(
        os.fspath(path), os.fspath(out), None if channel is None else str(channel), size_x,
        size_y, detrend, fill, bool(force))
    for category, words in warned:
        warnings.warn(f"{os.fspath(path)}: {words}", _WARNINGS[category], stacklevel=2)
    return Topography(heights=heights, size=float(sizes[0]),
                      size_y=float(sizes[1]) if len(sizes) > 1 else None,
                      provenance=json.loads(provenance))


def psd(
    values: Any,
    *,
    size: Union[None, float, Tuple[float, float]] = None,
    fit_from: Optional[float] = None,
    fit_to: Optional[float] = None,
    window: str = _DEFAULTS["window"],
    convention: str = _DEFAULTS["convention"],
) -> Psd:
    """The PSD of a surface or line, as ``asperity stats --psd``, with the least-squares
    power law ``C ∝ q^p`` over the bins whose rounded q·L/2π lies in ``fit_from`` ..
    ``fit_to`` (the defaults of :func:`stats`: 2, or the spec's roll-off, to Nyquist) and
    the Hurst estimate ``H = -(p + d)/2`` (d = 2 for surfaces, 1 for lines). ``values`` and
    ``size`` as for :func:`stats` (rectangular pixels included).

    Normalisation (``convention``): ``"asperity"`` (the default, the library's and the
    generators'; Persson's) makes ``∫ C2D d²q = rms²`` on a map and ``∫ C1D dq = rms²``
    along a line (``C1D`` counts both signs of q); ``"surface-topography"`` reports
    SurfaceTopography's ``|h̃(q)|²/A`` (``/L``), for which ``∫ C d^dq/(2π)^d = rms²``:
    asperity's times (2π)² on a map and 2π on a line (the exponent and Hurst estimate do
    not change). Bins: rings of width 2π/L centred on whole q·L/2π (a map), or each
    q = 2πk/L (a line). ``window``: ``"none"`` (the scan is one period of a periodic
    surface: right for generated surfaces) or ``"hann"`` (a non-periodic scan: the heights,
    mean removed, times a Hann window -- radial on a map -- scaled to keep the power; the
    window SurfaceTopography uses for non-periodic data), as ``asperity stats --window``.

    Example::

        >>> s = asperity.surface(256, hurst=0.8, seed=2)
        >>> spectrum = asperity.psd(s, fit_from=4, fit_to=64)
        >>> abs(spectrum.hurst - 0.8) < 0.1
        True
    """
    r = _statistics(values, size, fit_from, fit_to, window, convention)
    wavenumber = r["q"] * r["size"] / (2 * np.pi)
    fit = None
    if r["psd_slope"] is not None:
        fit = {"exponent": r["psd_slope"], "prefactor": r["fit_prefactor"],
               "stderr": r["fit_stderr"], "low": r["psd_slope_low"],
               "high": r["psd_slope_high"], "points": r["fit_points"]}
    return Psd(r["q"], r["psd"], r["modes"], wavenumber, fit, r["hurst_estimate"],
               r["fit_from"], r["fit_to"], r["fit_note"], float(r["size"]), int(r["ndim"]))


# --------------------------------------------------------------------------------------
# BEM
# --------------------------------------------------------------------------------------


@dataclass
class ContactResult:
    """A solved contact: scalars and (with ``fields=True``) the fields.

    ``force`` (E*·length²), ``mean_pressure``, ``indentation`` (free boundaries: from the
    highest point; periodic: relative to the mean elastic displacement),
    ``area_fraction``, ``contact_points``, ``iterations``, ``residual``; ``pressure``
    (≥ 0), ``gap`` (≥ 0) and ``displacement`` (u = K p, positive into the half-space),
    rows × cols numpy arrays, or None. Under a hardness H (``Solver(hardness=)``):
    ``plastic_fraction`` and ``plastic_points`` (the points at p = H; zero for the hard
    wall), and with the fields ``plastic_displacement`` (−g ≥ 0 at those points, zero
    elsewhere; in the units of the heights; the gap there is −plastic_displacement).
    """

    force: float
    mean_pressure: float
    indentation: float
    area_fraction: float
    contact_points: int
    iterations: int
    residual: float
    pressure: Optional[np.ndarray] = None
    gap: Optional[np.ndarray] = None
    displacement: Optional[np.ndarray] = None
    plastic_fraction: float = 0.0
    plastic_points: int = 0
    plastic_displacement: Optional[np.ndarray] = None
    #: What produced it: the solver's settings, the surface's identity and the load.
    metadata: Dict[str, Any] = field(default_factory=dict, repr=False)

    def save(self, path: Union[str, os.PathLike], *, force: bool = False) -> None:
        """Writes ``path`` (``.npz``: the fields present, float64) and ``path.json`` (the
        scalars and :attr:`metadata`), both or neither; or, for a name ending in ``.nc``,
        one NetCDF file (the fields on ``y``, ``x`` with CF attributes, the rest in its
        ``asperity_record`` attribute). :func:`load` gives it back."""
        arrays = {name: getattr(self, name) for name in _CONTACT_FIELDS
                  if getattr(self, name) is not None}
        scalars = {name: getattr(self, name) for name in _CONTACT_SCALARS}
        record = {"scalars": scalars, "metadata": self.metadata}
        _result_path(path)
        if _is_netcdf(path):
            _save_netcdf(path, "contact result", {n: ("map", a) for n, a in arrays.items()},
                         record, force)
            return
        _save_bundle(path, "contact result", arrays, record, force)

    def __repr__(self) -> str:
        shape = "" if self.pressure is None else ", fields " + "x".join(map(str, self.pressure.shape))
        return (f"ContactResult(force={self.force:.6g}, area_fraction={self.area_fraction:.6g}, "
                f"contact_points={self.contact_points}, iterations={self.iterations}{shape})")


_CONTACT_FIELDS = ("pressure", "gap", "displacement", "plastic_displacement")
_CONTACT_SCALARS = ("force", "mean_pressure", "indentation", "area_fraction", "contact_points",
                    "iterations", "residual", "plastic_fraction", "plastic_points")


@dataclass
class Sweep:
    """A load sweep: one numpy array per column of ``asperity bem``'s CSV (``force``,
    ``mean_pressure``, ``indentation``, ``area_fraction``, ``stiffness``, ``iterations``,
    ``residual``, ``stiffness_fd``; NaN where not computed), plus ``contact_points`` and,
    with ``fields=True``, lists ``pressure`` and ``gap`` of the fields of every load."""

    columns: Dict[str, Any]
    #: What produced it: the solver's (or contact request's) settings and the surface's
    #: identity (a generated surface's sidecar, a measured one's provenance, and the
    #: SHA-256 of the heights).
    metadata: Dict[str, Any] = field(default_factory=dict)

    def __getattr__(self, name: str) -> Any:
        try:
            return self.__dict__["columns"][name]
        except KeyError:
            raise AttributeError(name) from None

    def __getitem__(self, name: str) -> Any:
        return self.columns[name]

    def __len__(self) -> int:
        return len(next(iter(self.columns.values())))

    def save(self, path: Union[str, os.PathLike], *, force: bool = False) -> None:
        """Writes ``path`` (``.npz``: one array per column; the fields of a sweep with
        ``fields=True`` as ``pressure``/``gap`` stacks of loads × rows × cols) and
        ``path.json`` (column names, :attr:`metadata`), both or neither (an existing file
        is refused unless ``force``); or, for a name ending in ``.nc``, one NetCDF file:
        the columns along ``load``, the fields on (``load``,) ``y``, ``x``, CF attributes,
        the rest in its ``asperity_record`` attribute (``asperity bem --fields FILE.nc``
        writes the same variables). :func:`load` gives back the same sweep."""
        arrays, stacked, scalars = {}, [], {}
        for name, value in self.columns.items():
            if isinstance(value, list):
                arrays[name] = np.stack(value) if value else np.zeros((0, 0, 0))
                stacked.append(name)
            elif isinstance(value, np.ndarray):
                arrays[name] = value
            elif isinstance(value, (int, float)) and not isinstance(value, bool):
                scalars[name] = value
            else:
                raise ValueError(f"column {name}: cannot save a {type(value).__name__}")
        record = {"columns": list(self.columns), "stacked": stacked, "scalars": scalars,
                  "metadata": self.metadata}
        _result_path(path)
        if _is_netcdf(path):
            placed = {name: (_placement(name, a, name in stacked), a)
                      for name, a in arrays.items()}
            _save_netcdf(path, "sweep", placed, record, force)
            return
        _save_bundle(path, "sweep", arrays, record, force)

    def __repr__(self) -> str:
        names = ", ".join(self.columns)
        return f"Sweep({len(self)} loads: {names})"


_BOUNDARIES = ("free", "periodic")


def _one_load(pressure, force, indentation, what: str) -> Tuple[str, float]:
    """The load of one solve, by the front-end layer's rule (``bem::one_load``)."""
    return _core.one_load(what, _opt(pressure), _opt(force), _opt(indentation))


class Solver:
    """A reusable BEM contact solver for one surface (``asperity bem``).

    ``surface``: a 2D array of heights (rows × cols = y × x, positive up; any real dtype
    that converts to float64 without loss, any memory order), an :class:`asperity.Surface`,
    or any object with SurfaceTopography's ``heights()`` and ``physical_sizes`` (its
    ``heights()[x, y]`` is transposed to asperity's ``(y, x)``; pixels may be rectangular).
    ``size``: side L along x (default: the object's, else 1). ``modulus`` E* (default 1),
    or ``young`` E with ``poisson`` ν for E* = E/(1 − ν²) (:func:`effective_modulus`, the
    rule of ``asperity contact``);
    ``boundary`` ``"free"`` (zero-padded, the paper's) or ``"periodic"``; ``tolerance``
    (rms gap violation on the contact set over the rms height) and ``max_iterations``;
    ``solver``: ``"bccg"`` (the default: Fourier-preconditioned bound-constrained conjugate
    gradients, tens of iterations) or ``"pk"`` (Polonsky & Keer 1999, the reference), as
    ``asperity bem --solver``; ``"default"`` is an alias of ``"bccg"``. Both converge to
    the same contact to ``tolerance``.

    ``hardness`` H (``asperity bem --hardness``; in the units of the modulus and the
    pressures: E* units by default, Pa with a modulus in Pa): the contact pressure is
    capped at H, elastic–perfectly-plastic contact (docs/hardness.md), with either solver.
    Results then carry ``plastic_fraction`` (the points at H), solves the
    ``plastic_displacement`` field, sweeps a ``plastic_fraction`` column, and the
    stiffness is that of the elastic set 0 < p < H (the loading tangent dF/dd).
    :meth:`load_path` keeps the plastic displacement between loads (loading, unloading,
    reloading: hysteresis). A hardness that is not positive and finite raises
    ``ValueError``; so does a mean pressure (or force over the nominal area) at or above
    it, before any solve: more than a fully plastic contact can carry.

    The solver plans its FFTs once and keeps its buffers: each solve starts from the last
    pressure (warm start), so a rising load sweep is cheap.

    Example::

        >>> s = asperity.surface(128, hurst=0.8, rolloff=4, rms_slope=1.0, seed=1)
        >>> solver = asperity.Solver(s, boundary="periodic")
        >>> r = solver.solve(pressure=0.02)
        >>> k = solver.stiffness()               # frozen contact set, k = ΔF/Δd
        >>> sweep = solver.sweep(nloads=5, pmin=1e-3, pmax=1e-1)
        >>> sweep.area_fraction.shape
        (5,)
        >>> capped = asperity.Solver(s, boundary="periodic", hardness=0.3)
        >>> bool((capped.sweep(pressures=[0.01, 0.03]).plastic_fraction > 0).all())
        True
    """

    def __init__(
        self,
        surface: Any,
        size: Optional[float] = None,
        *,
        modulus: Optional[float] = None,
        young: Optional[float] = None,
        poisson: Optional[float] = None,
        boundary: str = _DEFAULTS["boundary"],
        tolerance: float = _DEFAULTS["tolerance"],
        max_iterations: int = _DEFAULTS["max_iterations"],
        solver: str = _DEFAULTS["solver"],
        hardness: Optional[float] = None,
    ):
        heights, size_x, size_y = _surface_input(surface, size)
        if modulus is None and young is None and poisson is None:
            modulus = _DEFAULTS["modulus"]
        modulus = effective_modulus(modulus=modulus, young=young, poisson=poisson)
        if isinstance(max_iterations, bool) or int(max_iterations) != max_iterations:
            raise ValueError(f"max_iterations must be an integer, got {max_iterations!r}")
        self._core = _core.Solver(
            heights, size_x, size_y, float(modulus), str(boundary), float(tolerance),
            int(max_iterations), str(solver), _opt(hardness),
        )
        self._surface = _surface_identity(surface, heights)
        self._size_y = size_y

    def _metadata(self, **load: Any) -> Dict[str, Any]:
        """The identity of a result of this solver: its settings, the surface, the load."""
        settings = {"shape": list(self.shape), "size": self.size, "modulus": self.modulus,
                    "boundary": self.boundary, "tolerance": self.tolerance,
                    "max_iterations": self.max_iterations, "solver": self.solver}
        if self._size_y is not None:
            settings["size_y"] = self._size_y
        if self.hardness is not None:
            settings["hardness"] = self.hardness
        return {"generator": f"asperity {__version__}", "solver": settings,
                "surface": self._surface, **load}

    shape = property(lambda self: self._core.shape, doc="(rows, cols)")
    size = property(lambda self: self._core.size, doc="side L along x")
    modulus = property(lambda self: self._core.modulus, doc="E*")
    boundary = property(lambda self: self._core.boundary, doc="'free' or 'periodic'")
    tolerance = property(lambda self: self._core.tolerance)
    max_iterations = property(lambda self: self._core.max_iterations)
    solver = property(lambda self: self._core.solver, doc="'bccg' or 'pk'")
    hardness = property(lambda self: self._core.hardness,
                        doc="the hardness H capping the pressure (units of E*), or None")
    nominal_area = property(lambda self: self._core.nominal_area, doc="rows·cols·Δ²")

    def solve(
        self,
        *,
        pressure: Optional[float] = None,
        force: Optional[float] = None,
        indentation: Optional[float] = None,
        fields: bool = True,
    ) -> ContactResult:
        """Solves the contact under one load: a mean ``pressure`` or total ``force`` (load
        control, > 0) or an ``indentation`` (displacement control, ≥ 0), warm-started from
        the last solve. A load beyond full contact raises :class:`BeyondFullContactError`
        (periodic boundaries: before solving; free: once the solve finds every point in
        contact). The solve is exactly the library's ``ContactSolver::solve``.
        ``fields=False`` skips the copies of the fields (and the displacement's one
        operator application).

        Example::

            >>> solver = asperity.Solver(asperity.surface(64, hurst=0.8, seed=1))
            >>> r = solver.solve(force=0.01)
            >>> f = r.pressure.sum() * (solver.size / solver.shape[1]) ** 2   # ≈ r.force
            >>> bool(abs(f - r.force) < 1e-12)
            True
        """
        quantity, value = _one_load(pressure, force, indentation, "solve")
        result = ContactResult(**self._core.solve(quantity, value, bool(fields)))
        result.metadata = self._metadata(load={"quantity": quantity, "value": value})
        return result

    def stiffness(self) -> float:
        """Contact stiffness of the last solve by the frozen contact set (the paper's
        method): the contact set is pushed down uniformly, ``k = ΔF/Δd`` (E*·length)."""
        k, _, _ = self._core.stiffness()
        return k

    def fd_stiffness(
        self,
        *,
        pressure: Optional[float] = None,
        force: Optional[float] = None,
        indentation: Optional[float] = None,
        step: float = _DEFAULTS["fd_step"],
    ) -> float:
        """``dF/dd`` by central differences: two solves at the load × (1 ± step). Leaves
        the solver in the upper state."""
        quantity, value = _one_load(pressure, force, indentation, "fd_stiffness")
        return self._core.fd_stiffness(quantity, value, float(step))

    def sweep(
        self,
        *,
        pressures: Optional[Sequence[float]] = None,
        forces: Optional[Sequence[float]] = None,
        indentations: Optional[Sequence[float]] = None,
        nloads: Optional[int] = None,
        pmin: Optional[float] = None,
        pmax: Optional[float] = None,
        stiffness: bool = True,
        fd_stiffness: bool = False,
        fd_step: float = _DEFAULTS["fd_step"],
        fields: bool = False,
        progress: ProgressArg = None,
        poisson: Optional[float] = None,
        resistivity: Optional[Sequence[float]] = None,
        thermal_conductivity: Optional[Sequence[float]] = None,
        persson: bool = False,
        gamma: Optional[float] = None,
        kappa: Optional[float] = None,
        tangential: Optional[str] = None,
        timing: bool = False,
    ) -> Sweep:
        """A load sweep exactly as ``asperity bem`` runs it (same numbers bit for bit):
        ``pressures``, ``forces`` or ``indentations`` in the given order, or ``nloads``
        mean pressures log-spaced from ``pmin`` to ``pmax``. Every load is checked against
        full contact before the first solve; each solve warm-starts from the previous one.
        ``stiffness``: frozen-set stiffness per load; ``fd_stiffness``: also ``dF/dd``
        from two more solves at the load × (1 ± fd_step); ``fields``: keep pressure and
        gap of every load. ``progress``: a callable ``progress(done, total)``, or True for
        a tqdm bar. Ctrl-C stops the sweep within a second, inside a load's solve too
        (``KeyboardInterrupt``).

        ``poisson`` (ν in [0, 0.5], ``asperity bem --poisson``): also the tangential
        (no-slip) stiffnesses ``stiffness_x``, ``stiffness_y`` of the frozen contact set
        (Cerruti's kernel; E* stays the solver's modulus) and ``tangential_ratio`` =
        (k_x + k_y)/(2k), Mindlin's 2(1−ν)/(2−ν) for one circular contact.
        ``tangential`` (``"x"``, ``"y"`` or ``"both"``, the default; ``asperity bem
        --tangential``): one direction alone, at about half the cost: only its column,
        and ``tangential_ratio`` = k_x/k (or k_y/k); ``"x"`` gives the ``"both"`` run's
        ``stiffness_x`` bit for bit.
        ``resistivity`` (ρ₁, ρ₂) and ``thermal_conductivity`` (κ₁, κ₂), one value per
        body: also ``electrical_conductance`` = 2k/(E*(ρ₁+ρ₂)) and ``thermal_conductance``
        = (2k/E*)·κ₁κ₂/(κ₁+κ₂) (Barber's analogy). docs/tangential.md.

        ``timing`` (``asperity bem --timing``): also each load's ``solve_seconds`` and
        ``stiffness_seconds`` (wall time), the process's ``peak_rss_mib`` after it, and
        ``tangential_seconds`` with ``poisson``.

        ``persson`` (``asperity bem --persson``): also the BEM's ``mean_gap`` (with
        periodic boundaries Persson's mean separation) and Persson's theory from the
        surface's own PSD at each load's mean pressure: ``area_fraction_persson``,
        ``mean_gap_persson``, ``stiffness_persson`` (interfacial K·A₀), with ``gamma``
        (default 0.45) and ``kappa`` (default √(8/π)). docs/persson.md.

        Example::

            >>> solver = asperity.Solver(asperity.surface(64, hurst=0.8, seed=1))
            >>> sweep = solver.sweep(nloads=20, pmin=1e-4, pmax=1e-1)
            >>> sweep.force.shape, sweep.stiffness.shape, sweep.area_fraction.shape
            ((20,), (20,), (20,))
            >>> t = solver.sweep(pressures=[0.01], poisson=0.3, resistivity=[1, 1])
            >>> t.tangential_ratio.shape, t.electrical_conductance.shape
            ((1,), (1,))
            >>> u = solver.sweep(pressures=[1e-3, 1e-2], persson=True, gamma=0.4)
            >>> bool((u.mean_gap > 0).all() and (u.mean_gap_persson > 0).all())
            True

        With the solver's ``hardness``: also ``plastic_fraction`` (the CLI's column);
        each load on the surface as given (:meth:`load_path` keeps the plastic
        displacement); a mean pressure or force at or above H times the nominal area is
        refused before the first solve.
        """
        # The theory's rule and defaults: the front-end layer's (SweepPersson::from_options).
        theory = _core.sweep_persson(bool(persson), _opt(gamma), _opt(kappa))
        quantity, values = _sweep_loads(pressures, forces, indentations, nloads, pmin, pmax, fields)
        fd = float(fd_step) if fd_stiffness else None
        bar = _Progress(progress, "bem")
        try:
            columns = self._core.sweep(quantity, values, bool(stiffness), fd, bool(fields),
                                       bar.callback, _opt(poisson), _floats(resistivity),
                                       _floats(thermal_conductivity), theory,
                                       _text(tangential), bool(timing))
        finally:
            bar.close()
        derived = {"poisson": _opt(poisson), "tangential": _text(tangential),
                   "resistivity": _floats(resistivity),
                   "thermal_conductivity": _floats(thermal_conductivity)}
        if theory is not None:
            derived["persson"] = {"gamma": theory[0], "kappa": theory[1]}
        derived = {k: v for k, v in derived.items() if v is not None}
        return Sweep(columns, self._metadata(loads={"quantity": quantity, "values": values},
                                             stiffness=bool(stiffness), fd_step=fd, **derived))

    def load_path(
        self,
        *,
        pressures: Optional[Sequence[float]] = None,
        forces: Optional[Sequence[float]] = None,
        indentations: Optional[Sequence[float]] = None,
    ) -> Sweep:
        """A load path (the library's ``load_path``): the loads in the given order --
        loading, then unloading, then reloading -- each solve warm from the last, and the
        plastic displacement of each step kept (the surface flattened where it yielded).
        Unloading is then elastic on the flattened surface, reloading is elastic up to the
        largest load reached before: force, area and stiffness show the hysteresis. With a
        ``hardness``; without one the path is elastic and reversible.

        Returns a :class:`Sweep` with one value per step (the columns of ``asperity bem
        --load-path``, bit for bit): ``branch`` (``"loading"`` beyond every earlier load,
        ``"unloading"``, ``"reloading"``), ``force``, ``mean_pressure``,
        ``indentation``, ``area_fraction``, ``plastic_fraction``, ``stiffness`` (frozen
        elastic set), ``iterations``, ``permanent_max`` (the largest permanent
        displacement so far), ``contact_points``, ``plastic_points``; and
        ``permanent_displacement``, the rows × cols permanent displacement after the last
        step (units of the heights). Each load is checked against the hardness before the
        first solve, as in :meth:`sweep`.

        The solver keeps the permanent displacement: later solves, sweeps and paths are on
        the deformed surface (:meth:`permanent_displacement`); a new ``Solver`` starts
        from the surface as given.

        Example::

            >>> s = asperity.surface(64, hurst=0.8, rolloff=4, rms_slope=1.0, seed=1)
            >>> solver = asperity.Solver(s, boundary="periodic", hardness=0.3)
            >>> path = solver.load_path(pressures=[0.01, 0.03, 0.01, 0.03])
            >>> bool(path.indentation[2] > path.indentation[0])   # deeper after yielding
            True
        """
        quantity, values = _sweep_loads(pressures, forces, indentations, None, None, None, False)
        columns = self._core.load_path(quantity, values)
        columns["branch"] = np.array(columns["branch"])
        return Sweep(columns, self._metadata(loads={"quantity": quantity, "values": values},
                                             load_path=True))

    def permanent_displacement(self) -> np.ndarray:
        """The permanent (plastic) displacement kept by :meth:`load_path` so far, rows ×
        cols (units of the heights; zeros before any)."""
        return self._core.permanent_displacement()

    def full_contact_threshold(self) -> Dict[str, Optional[float]]:
        """Mean pressure and indentation from which the gap is closed everywhere. On free
        boundaries the first call costs about one solve and forgets the warm start."""
        p, d = self._core.full_contact_threshold()
        return {"mean_pressure": p, "force": p * self.nominal_area, "indentation": d}

    def reset(self) -> None:
        """Forgets the last solution: the next solve starts cold."""
        self._core.reset()

    def __repr__(self) -> str:
        rows, cols = self.shape
        return (
            f"Solver({rows}x{cols}, size={self.size}, modulus={self.modulus}, "
            f"boundary={self.boundary!r}, solver={self.solver!r}"
            + ("" if self.hardness is None else f", hardness={self.hardness}") + ")"
        )


def _surface_input(surface: Any, size: Optional[float]) -> Tuple[np.ndarray, float, Optional[float]]:
    """Heights (rows × cols), size along x and (for SurfaceTopography objects) along y."""
    size_x, size_y = _sizes(size)
    if isinstance(surface, Surface):
        if size_y is not None:
            raise ValueError("size: a generated surface has square pixels; give one size")
        return surface.heights, surface.size if size_x is None else size_x, None
    if isinstance(surface, Topography):
        if surface.heights.ndim != 2:
            raise ValueError("surface: a measured profile is no surface (use mdr for lines)")
        if size is not None:
            raise ValueError("size: the topography has its own sizes")
        return surface.heights, surface.size, surface.size_y
    heights_of = getattr(surface, "heights", None)
    if callable(heights_of) and hasattr(surface, "physical_sizes"):
        # SurfaceTopography: heights()[x, y] with physical_sizes (sx, sy).
        sizes = surface.physical_sizes
        if sizes is None or len(sizes) != 2:
            raise ValueError(f"surface: expected two physical sizes (sx, sy), got {sizes!r}")
        heights = _float64(heights_of(), "surface").T
        if heights.ndim != 2:
            raise ValueError(f"surface: expected 2D heights, got shape {heights.shape}")
        if size is not None:
            raise ValueError("size: the topography has its own physical_sizes")
        return heights, float(sizes[0]), float(sizes[1])
    heights = _float64(surface, "surface")
    if heights.ndim != 2:
        raise ValueError(f"surface: expected a 2D array of heights (rows, cols), got shape {heights.shape}")
    return heights, _DEFAULTS["size"] if size_x is None else size_x, size_y


def _sweep_loads(pressures, forces, indentations, nloads, pmin, pmax, fields) -> Tuple[str, List[float]]:
    def values(v):
        return None if v is None else [float(x) for x in np.atleast_1d(np.asarray(v, dtype=np.float64))]
    if nloads is not None and (isinstance(nloads, bool) or int(nloads) != nloads):
        raise ValueError(f"nloads must be an integer, got {nloads!r}")
    return _core.sweep_loads(
        values(forces), values(pressures), values(indentations),
        None if nloads is None else int(nloads), _opt(pmin), _opt(pmax), bool(fields),
    )


def effective_modulus(*, modulus: Optional[float] = None,
                      young: Union[None, float, Sequence[float]] = None,
                      poisson: Union[None, float, Sequence[float]] = None) -> float:
    """E* by the one rule both front ends use (``asperity contact --modulus``, or
    ``--young`` with ``--poisson``): ``modulus`` itself; or ``young`` E and ``poisson`` ν
    (in [0, 0.5]) as E/(1 − ν²) -- a rigid counter-body; or two elastic bodies, ``young``
    (E₁, E₂) and ``poisson`` (ν₁, ν₂), as ``1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂``
    (``--young E1,E2 --poisson NU1,NU2``). Refusals (a ν of 0.6, a negative E, both or
    neither given, one ν for two bodies) raise ``ValueError`` in the CLI's words.

    Examples
    --------
    >>> round(asperity.effective_modulus(young=210e9, poisson=0.3) / 1e9, 3)
    230.769
    >>> round(asperity.effective_modulus(young=(210e9, 210e9), poisson=(0.3, 0.3)) / 1e9, 3)
    115.385
    """
    return _core.effective_modulus(_opt(modulus), _floats(young), _floats(poisson))


def contact(
    surface: Any,
    size: Optional[float] = None,
    *,
    pressures: Optional[Sequence[float]] = None,
    modulus: Optional[float] = None,
    young: Union[None, float, Sequence[float]] = None,
    poisson: Union[None, float, Sequence[float]] = None,
    boundary: str = _DEFAULTS["boundary"],
    tolerance: float = _DEFAULTS["tolerance"],
    map: bool = False,
    resistivity: Optional[Sequence[float]] = None,
    thermal_conductivity: Optional[Sequence[float]] = None,
    hardness: Optional[float] = None,
    tangential: Union[bool, str] = False,
    load_path: bool = False,
    progress: ProgressArg = None,
    work_of_adhesion: Optional[float] = None,
    adhesion_range: Optional[float] = None,
    adhesion_model: Optional[str] = None,
    indentations: Optional[Sequence[float]] = None,
    retract_step: Optional[float] = None,
) -> Sweep:
    """``asperity contact``: the surface (rigid; SI units, heights and sizes in metres)
    pressed into an elastic half-space at each mean ``pressure`` (Pa), with E* =
    ``modulus`` or from ``young`` E and ``poisson`` ν as E/(1 − ν²), or of two elastic
    bodies from ``young=(E₁, E₂)`` and ``poisson=(ν₁, ν₂)`` as 1/E* = (1 − ν₁²)/E₁ +
    (1 − ν₂²)/E₂ (:func:`effective_modulus`). The same request,
    rules and load sweep as the CLI (warm starts, full contact checked before any solve,
    frozen-set stiffness), so the same numbers bit for bit.

    Returns the CLI's columns as numpy arrays: ``mean_pressure_pa``, ``force_n``,
    ``contact_area_m2``, ``area_fraction``, ``mean_gap_m``, ``stiffness_n_per_m``,
    ``patches``, ``indentation_m``, ``iterations``, ``residual``; ``effective_modulus``;
    with ``map=True`` also ``map``, the contact set (True in contact) of the last load,
    ``patch_labels`` (its 4-connected patches numbered from 1, 0 outside contact: the rule
    of the ``patches`` column) and ``patch_areas_m2`` (each patch's area, by label).
    With ``resistivity`` (ρ₁, ρ₂ of the two bodies, Ω·m) also ``electrical_conductance_s``
    = 2k/(E*(ρ₁+ρ₂)); with ``thermal_conductivity`` (κ₁, κ₂, W/(m·K)) also
    ``thermal_conductance_w_per_k`` = (2k/E*)·κ₁κ₂/(κ₁+κ₂) (Barber's analogy).
    With ``hardness`` (Pa) the contact pressure is capped there (elastic–perfectly-plastic
    contact, docs/hardness.md; each load on the surface as given), adding
    ``plastic_area_m2`` and ``plastic_fraction`` (the points at the hardness); the
    stiffness is then that of the elastic set. A hardness that is not positive and finite,
    or a pressure at or above it, raises ValueError. With ``tangential=True`` (needs
    ``poisson``: with ``young``, or beside ``modulus`` for Cerruti's kernel alone) also
    ``stiffness_x_n_per_m``, ``stiffness_y_n_per_m`` (the no-slip tangential stiffness of
    the frozen contact set) and ``tangential_ratio`` = (k_x + k_y)/(2k);
    ``tangential="x"`` (or ``"y"``; ``asperity contact --tangential=x``) one direction
    alone, at about half the cost: its column, and ``tangential_ratio`` = k_x/k (k_y/k).
    ``progress``: as for :meth:`Solver.sweep` (``asperity contact --progress``; none by
    default, as ``--quiet``), counted in loads.

    With ``load_path=True`` (``asperity contact --load-path``) the pressures are walked in
    the given order as one load path -- loading, unloading, reloading -- each step warm
    from the last and its plastic displacement kept (:meth:`Solver.load_path`, the
    library's load path, in SI units); the columns are the CLI's: ``branch``, ``force_n``,
    ``mean_pressure_pa``, ``indentation_m``, ``area_fraction``, ``plastic_fraction``,
    ``stiffness_n_per_m`` (the frozen elastic set), ``iterations``, ``permanent_max_m``,
    and ``permanent_displacement_m`` (rows × cols, after the last step). It does not go
    with ``map``, ``tangential``, ``resistivity`` or ``thermal_conductivity``.

    Example::

        >>> s = asperity.surface(64, hurst=0.8, rms_height=1e-6, size=1e-3, seed=1)
        >>> s.save("scan.x3p")                          # a 1 mm map, 1 µm rms, as X3P
        >>> t = asperity.read_topography("scan.x3p", detrend="plane")
        >>> c = asperity.contact(t, young=210e9, poisson=0.3, pressures=[1e5, 1e6])
        >>> bool(0 < c.contact_area_m2[0] < c.contact_area_m2[1])
        True
        >>> bool(c.stiffness_n_per_m[1] > c.stiffness_n_per_m[0] > 0)
        True
        >>> capped = asperity.contact(t, young=210e9, poisson=0.3, pressures=[1e7],
        ...                           hardness=2e9)
        >>> bool(capped.plastic_fraction[0] > 0)
        True

    With ``work_of_adhesion`` (Δγ, J/m²) the run is adhesive instead of a load sweep, as
    ``asperity contact --work-of-adhesion`` (the solver and rules of :func:`bem_adhesion`,
    in SI units): the path of ``indentations`` (m), then the retraction to pull-off in
    steps of ``retract_step`` (m); ``adhesion_range`` (m) and ``adhesion_model``
    (``"maugis-dugdale"`` or ``"exponential"``) choose a cohesive law, none the pixel
    criterion. Columns ``indentation_m``, ``force_n``, ``mean_pressure_pa``,
    ``contact_area_m2``, ``area_fraction``, ``tensile_fraction``, ``rounds``,
    ``cg_iterations``, ``branch``; ``critical_stress`` (Pa) and ``effective_modulus``;
    ``metadata["pull_off"]`` (both controls, force in N, indentation in m) and
    ``metadata["warning"]``. It goes with neither ``load_path`` nor ``map`` (nor the load
    sweep's options), and reports no ``progress``. See docs/adhesion.md.
    """
    heights, size_x, size_y = _surface_input(surface, size)
    loads = [] if pressures is None else [
        float(p) for p in np.atleast_1d(np.asarray(pressures, dtype=np.float64))]
    path = [] if indentations is None else [
        float(d) for d in np.atleast_1d(np.asarray(indentations, dtype=np.float64))]
    adhesion = (_opt(work_of_adhesion), _opt(adhesion_range),
                None if adhesion_model is None else str(adhesion_model), path,
                _opt(retract_step))
    bar = _Progress(progress, "contact")
    try:
        columns = _core.contact(
            heights, size_x, size_y, loads, _opt(modulus), _floats(young), _floats(poisson),
            str(boundary), float(tolerance), bool(map),
            None if resistivity is None else [float(v) for v in np.atleast_1d(resistivity)],
            None if thermal_conductivity is None
            else [float(v) for v in np.atleast_1d(thermal_conductivity)],
            _opt(hardness), *_tangential(tangential), bar.callback, adhesion,
            bool(load_path),
        )
    finally:
        bar.close()
    if columns is None:  # load_path: the request's rules passed, the path on Solver
        return _contact_path(surface, size, loads, modulus, young, poisson, boundary,
                             tolerance, hardness)
    if work_of_adhesion is not None:
        extra = {k: columns.pop(k) for k in ("pull_off", "warning")}
        request = {"work_of_adhesion": adhesion[0], "adhesion_range": adhesion[1],
                   "adhesion_model": adhesion[2], "indentations": path,
                   "retract_step": adhesion[4], "modulus": _opt(modulus),
                   "young": _one_or_both(young), "poisson": _one_or_both(poisson),
                   "boundary": str(boundary)}
        return Sweep(columns, {"generator": f"asperity {__version__}", "contact": request,
                               **extra, "shape": list(heights.shape),
                               "sizes": [size_x, size_y],
                               "surface": _surface_identity(surface, heights)})
    if "map" in columns:
        dx = size_x / heights.shape[1]
        dy = dx if size_y is None else size_y / heights.shape[0]
        found = patches(columns["map"], pixel_area=dx * dy)
        columns["patch_labels"], columns["patch_areas_m2"] = found.labels, found.areas
    request = {"pressures": loads, "modulus": _opt(modulus), "young": _one_or_both(young),
               "poisson": _one_or_both(poisson), "boundary": str(boundary),
               "tolerance": float(tolerance), "resistivity": _floats(resistivity),
               "thermal_conductivity": _floats(thermal_conductivity),
               "hardness": _opt(hardness), "tangential": _tangential(tangential)[0]}
    if isinstance(tangential, str):
        request["directions"] = tangential
    return Sweep(columns, {"generator": f"asperity {__version__}", "contact": request,
                           "shape": list(heights.shape), "sizes": [size_x, size_y],
                           "surface": _surface_identity(surface, heights)})


#: ``Solver.load_path``'s columns under ``asperity contact --load-path``'s SI names.
_PATH_SI = {"branch": "branch", "force": "force_n", "mean_pressure": "mean_pressure_pa",
            "indentation": "indentation_m", "area_fraction": "area_fraction",
            "plastic_fraction": "plastic_fraction", "stiffness": "stiffness_n_per_m",
            "iterations": "iterations", "permanent_max": "permanent_max_m",
            "permanent_displacement": "permanent_displacement_m"}


def _contact_path(surface, size, pressures, modulus, young, poisson, boundary, tolerance,
                  hardness) -> Sweep:
    """``contact(load_path=True)``, its request checked by the front-end layer (what a
    path cannot carry refused as the CLI does): the solver of ``asperity contact`` (E* from
    the same rule, its boundary, tolerance and hardness) walked along the pressures."""
    e_star = effective_modulus(modulus=modulus, young=young, poisson=poisson)
    solver = Solver(surface, size, modulus=e_star, boundary=boundary, tolerance=tolerance,
                    hardness=hardness)
    loads = [float(p) for p in np.atleast_1d(np.asarray(pressures, dtype=np.float64))]
    path = solver.load_path(pressures=loads)
    columns = {si: path.columns[name] for name, si in _PATH_SI.items()}
    request = {"pressures": loads, "modulus": _opt(modulus), "young": _one_or_both(young),
               "poisson": _one_or_both(poisson), "boundary": str(boundary),
               "tolerance": float(tolerance), "hardness": _opt(hardness), "load_path": True}
    return Sweep(columns, {"generator": f"asperity {__version__}", "contact": request,
                           "shape": list(solver.shape), "sizes": [solver.size, solver._size_y],
                           "surface": solver._surface})


@dataclass
class Patches(_Saved):
    """The contact patches of a contact set: ``labels`` (rows × cols, uint32: 0 outside
    contact, patches numbered 1, 2, ... in the order of their first point, row by row),
    ``points`` (each patch's number of points, index k for label k + 1) and ``areas``
    (``points`` times the pixel area)."""

    labels: np.ndarray
    points: np.ndarray
    areas: np.ndarray

    def __len__(self) -> int:
        return len(self.points)

    def __repr__(self) -> str:
        rows, cols = self.labels.shape
        return f"Patches({len(self)} patches on {rows}x{cols})"


def patches(contact_set: Any, *, pixel_area: float = 1.0) -> Patches:
    """The 4-connected patches of a contact set (points sharing an edge; no wrap-around),
    by the library's rule, the one of ``asperity contact``'s ``patches`` column:
    ``len(patches(c.map))`` is its value at the last load. ``contact_set``: a 2D boolean
    array (e.g. ``result.pressure > 0`` or the ``map`` of :func:`contact`);
    ``pixel_area``: the area of one point (Δx·Δy), for ``areas``.

    Example::

        >>> p = asperity.patches(np.array([[1, 1, 0], [0, 0, 1]], dtype=bool))
        >>> len(p), p.points.tolist()
        (2, [2, 1])
    """
    array = np.asarray(contact_set)
    if array.dtype != np.bool_ or array.ndim != 2:
        raise ValueError(f"contact_set: expected a 2D boolean array, got {array.dtype} "
                         f"of shape {array.shape}")
    labels, points, areas = _core.label_patches(np.ascontiguousarray(array), float(pixel_area))
    return Patches(labels, points, areas)


def _floats(values: Any) -> Optional[List[float]]:
    return None if values is None else [float(v) for v in np.atleast_1d(values)]


def _one_or_both(values: Any) -> Union[None, float, List[float]]:
    """A value given once as a float, per body (two) as a list, as the CLI's record."""
    given = _floats(values)
    return given[0] if given is not None and len(given) == 1 else given


def _surface_identity(surface: Any, heights: np.ndarray) -> Dict[str, Any]:
    """What a result records of the surface it was computed on: a generated surface's
    sidecar, a measured one's provenance, and always the SHA-256 of the heights (float64,
    row-major)."""
    import hashlib

    digest = hashlib.sha256(np.ascontiguousarray(heights, dtype=np.float64).tobytes())
    identity: Dict[str, Any] = {"heights_sha256": digest.hexdigest()}
    if isinstance(surface, Surface):
        identity["sidecar"] = surface.metadata
    elif isinstance(surface, Topography):
        identity["provenance"] = surface.provenance
    return identity


# --------------------------------------------------------------------------------------
# MDR
# --------------------------------------------------------------------------------------


@dataclass
class MdrCurve(_Saved):
    """An MDR curve (``asperity mdr``): ``indentation`` (from first contact), ``force``,
    ``stiffness`` (dF/dd), ``contacts`` (springs compressed), with a ``description`` of the
    indenter, the ``spring`` law and its ``critical_depth`` u0, and E* (``modulus``; None in
    a curve saved before it was kept). With a work of adhesion,
    also ``branch`` (``"approach"`` or ``"retract"`` per row) and ``pull_off``
    (``{"force_controlled": {...}, "displacement_controlled": {...}}``, each with
    ``force``, ``indentation`` and ``contacts``; None if nothing was in contact)."""

    indentation: np.ndarray
    force: np.ndarray
    stiffness: np.ndarray
    contacts: np.ndarray
    description: str
    spring: str
    critical_depth: float
    branch: Optional[List[str]] = None
    pull_off: Optional[Dict[str, Dict[str, float]]] = None
    modulus: Optional[float] = None


#: The keywords of the front-end layer's ``MdrRequest`` that :func:`mdr` and
#: :func:`mdr_slip` share (the indenter, the springs, the loads), besides ``line``,
#: ``radial``, ``size`` and ``indentations``.
_MDR_KEYWORDS = ("profile", "radial_step", "radius", "slope", "coefficient", "exponent", "n",
                 "dx", "modulus", "spring", "hurst", "rms_height", "asperity_radius", "nloads",
                 "dmin", "dmax", "breakpoints", "work_of_adhesion")


def _mdr_request(keywords: Dict[str, Any]
                 ) -> Tuple[Dict[str, Any], Optional[np.ndarray], Optional[np.ndarray]]:
    """The one request builder of :func:`mdr` and :func:`mdr_slip`: from their keywords
    (``locals()``), the request (the keywords of ``MdrRequest`` in :data:`_MDR_KEYWORDS`)
    with the line's heights and the radial samples. Keywords left ``None`` are left out
    and take the request's defaults (the CLI's)."""
    line, radial, size = keywords["line"], keywords["radial"], keywords["size"]
    indentations = keywords["indentations"]
    options = {name: keywords[name] for name in _MDR_KEYWORDS if name in keywords}
    line_heights = None
    if line is not None:
        if isinstance(line, Line):
            size = line.size if size is None else size
            line_heights = line.heights
        else:
            line_heights = _float64(line, "line")
        if line_heights.ndim != 1:
            raise ValueError(f"line: expected a 1D array, got shape {line_heights.shape}")
    radial_values = None
    if radial is not None:
        radial_values = _float64(radial, "radial")
        if radial_values.ndim != 1:
            raise ValueError(f"radial: expected a 1D array, got shape {radial_values.shape}")
    request = {name: value for name, value in options.items() if value is not None}
    request["size"] = _opt(size)
    if indentations is not None:
        request["indentations"] = [
            float(d) for d in np.atleast_1d(np.asarray(indentations, dtype=np.float64))]
    return request, line_heights, radial_values


def mdr(
    *,
    line: Any = None,
    profile: Optional[str] = None,
    radial: Any = None,
    radial_step: Optional[float] = None,
    radius: Optional[float] = None,
    slope: Optional[float] = None,
    coefficient: Optional[float] = None,
    exponent: Optional[float] = None,
    n: Optional[int] = None,
    dx: Optional[float] = None,
    size: Optional[float] = None,
    modulus: Optional[float] = None,
    spring: Optional[str] = None,
    hurst: Optional[float] = None,
    rms_height: Optional[float] = None,
    asperity_radius: Optional[float] = None,
    indentations: Optional[Sequence[float]] = None,
    nloads: Optional[int] = None,
    dmin: Optional[float] = None,
    dmax: Optional[float] = None,
    breakpoints: bool = False,
    work_of_adhesion: Optional[float] = None,
) -> MdrCurve:
    """Force, stiffness and contacts of an indenter on the MDR spring foundation, with
    every option of ``asperity mdr``.

    Indenter (one of): ``line`` (1D heights or :class:`Line`; spacing = size / n, size
    default the Line's, else 1); ``profile`` ``"hertz"`` (``radius``), ``"cone"``
    (``slope`` tan θ), ``"punch"`` (``radius``) or ``"power"`` (``coefficient``,
    ``exponent``: f = c rⁿ), on ``n`` springs at spacing ``dx``; ``radial`` samples of
    f(r) at steps ``radial_step``, mapped by the MDR transform.
    Springs: ``"linear"`` (E*·Δx, the default), ``"hertz"`` (15.2, ``asperity_radius``;
    default ``radius`` for a Hertz profile) or ``"fractal"`` (15.7, ``hurst`` 0 < H < 2,
    ``rms_height`` default the line's own); ``modulus`` E* (default 1). A keyword left
    ``None`` takes the CLI's default (the front-end layer's ``MdrRequest``).
    Indentations: a list, or ``nloads`` (default 50) log-spaced from ``dmin`` (default
    dmax·1e-6) to ``dmax`` (default: full contact); or ``breakpoints=True``: the exact
    piecewise-linear curve of linear springs on a line, one row per contact count.
    Adhesion: ``work_of_adhesion`` Δγ (linear springs) makes the springs stick by Heß's
    rule (let go at √(2πaΔγ/E*)): the indentations become a load path (negative allowed),
    then the indenter retracts to pull-off, the exact curve returned with ``branch`` and
    ``pull_off`` (as ``asperity mdr --work-of-adhesion``).

    Example::

        >>> c = asperity.mdr(profile="hertz", radius=1.0, n=2001, dx=0.01, spring="hertz",
        ...                  indentations=[1e-6, 1e-4])
        >>> l = asperity.line(32768, hurst=0.5, seed=1)
        >>> curve = asperity.mdr(line=l, nloads=40)
        >>> jkr = asperity.mdr(profile="hertz", radius=1.0, n=1001, dx=1e-3,
        ...                    work_of_adhesion=1e-3, indentations=[0.09])
        >>> round(jkr.pull_off["force_controlled"]["force"] / (-1.5 * np.pi * 1e-3), 3)
        1.0
    """
    breakpoints = bool(breakpoints)
    request, line_heights, radial_values = _mdr_request(locals())
    out = _core.mdr_curve(request, line_heights, radial_values)
    return MdrCurve(**out)


@dataclass
class SlipCycle(_Saved):
    """A tangential cycle (``asperity mdr --tangential-force``): ``branch`` (``loading``,
    ``unloading``, ``reloading``), ``tangential_displacement``, ``tangential_force``,
    ``stick_springs`` and, for axisymmetric indenters, ``stick_radius`` (else None); the
    ``summary`` (indentation, normal_force, friction_limit μF, no_slip_stiffness,
    stiffness_ratio G*/E*, dissipation_per_cycle, contacts) and a ``description``."""

    branch: List[str]
    tangential_displacement: np.ndarray
    tangential_force: np.ndarray
    stick_springs: np.ndarray
    stick_radius: Optional[np.ndarray]
    summary: Dict[str, Any]
    description: str


def mdr_slip(
    *,
    tangential_force: float,
    friction: Optional[float] = None,
    poisson: Optional[float] = None,
    cycle_points: Optional[int] = None,
    indentations: Optional[Sequence[float]] = None,
    line: Any = None,
    profile: Optional[str] = None,
    radial: Any = None,
    radial_step: Optional[float] = None,
    radius: Optional[float] = None,
    slope: Optional[float] = None,
    coefficient: Optional[float] = None,
    exponent: Optional[float] = None,
    n: Optional[int] = None,
    dx: Optional[float] = None,
    size: Optional[float] = None,
    modulus: Optional[float] = None,
    spring: Optional[str] = None,
    hurst: Optional[float] = None,
    rms_height: Optional[float] = None,
    asperity_radius: Optional[float] = None,
    work_of_adhesion: Optional[float] = None,
) -> SlipCycle:
    """Partial slip under a tangential force amplitude ``tangential_force`` Q* ≤ μF at the one
    indentation of ``indentations``: loading from rest to Q*, unloading to −Q*, reloading to
    Q* (``asperity mdr --tangential-force``). ``friction`` μ > 0; ``poisson`` ν in [0, 0.5]
    (default 0.3, the CLI's) gives tangential springs G*/E* = 2(1−ν)/(2−ν) times the
    normal ones. The indenter and
    springs take the keywords of :func:`mdr` (``profile``, ``radius``, ``n``, ``dx``,
    ``spring``, ``modulus``, ...).

    Example (Cattaneo–Mindlin: c/a = (1 − Q/μF)^{1/3})::

        >>> c = asperity.mdr_slip(profile="hertz", radius=1.0, n=4001, dx=1e-3,
        ...                       indentations=[1.0], tangential_force=1/3, friction=0.5)
        >>> round(float(c.stick_radius[49]), 3)  # top of the loading branch: 0.5^(1/3)
        0.794
    """
    request, line_heights, radial_values = _mdr_request(locals())
    out = _core.mdr_slip(
        request, line_heights, radial_values, float(tangential_force), _opt(friction),
        _opt(poisson), cycle_points,
    )
    out["summary"] = json.loads(out["summary"])
    out.setdefault("stick_radius", None)
    return SlipCycle(**out)


# --------------------------------------------------------------------------------------
# Studies
# --------------------------------------------------------------------------------------


@dataclass
class BemAdhesion(_Saved):
    """An adhesive BEM run (:func:`bem_adhesion`; the columns of ``asperity bem
    --work-of-adhesion``): per settled state ``indentation``, ``force``, ``mean_pressure``,
    ``area_fraction`` (attached pixels), ``tensile_fraction``, ``rounds``,
    ``cg_iterations`` and ``branch`` (``"path"`` or ``"retract"``); ``pull_off`` (both
    controls: force, indentation, attached_points; ``None`` if nothing stayed attached),
    the pixel's ``critical_stress`` and a resolution ``warning`` (or ``None``)."""

    indentation: np.ndarray
    force: np.ndarray
    mean_pressure: np.ndarray
    area_fraction: np.ndarray
    tensile_fraction: np.ndarray
    rounds: np.ndarray
    cg_iterations: np.ndarray
    branch: List[str]
    pull_off: Optional[Dict[str, Any]]
    critical_stress: float
    warning: Optional[str]

    def __repr__(self) -> str:
        return f"BemAdhesion({len(self.force)} states, critical_stress={self.critical_stress:.4e})"


def bem_adhesion(
    surface: Any,
    *,
    work_of_adhesion: float,
    indentations: Sequence[float],
    size: Optional[float] = None,
    modulus: float = _DEFAULTS["modulus"],
    boundary: str = _DEFAULTS["boundary"],
    retract_step: Optional[float] = None,
    adhesion_range: Optional[float] = None,
    adhesion_model: Optional[str] = None,
) -> BemAdhesion:
    """Adhesive contact on the BEM by Pohrt & Popov's pixel criterion, or a cohesive law of
    range ``adhesion_range``: a Maugis–Dugdale zone (``adhesion_model="maugis-dugdale"``, the
    default; stress ``work_of_adhesion / adhesion_range``) or the exponential potential
    (``adhesion_model="exponential"``; tension ``(w/ρ)·exp(−g/ρ)``), as ``asperity bem
    --work-of-adhesion [--adhesion-range] [--adhesion-model]`` (the same code and numbers):
    the ``indentations`` are a path (negative allowed), then the indenter is retracted in
    steps of ``retract_step`` (default: the deepest indentation, plus any range, / 200)
    until nothing is attached. Square pixels. See docs/adhesion.md.

    Example::

        >>> x = (np.arange(40) - 20) * 5e-3
        >>> h = -(x[:, None]**2 + x[None, :]**2) / 2
        >>> run = asperity.bem_adhesion(h, size=0.2, work_of_adhesion=2e-4,
        ...                             indentations=[0.002, 0.004, 0.006, 0.008])
        >>> bool(run.pull_off["force_controlled"]["force"] < 0)
        True
    """
    heights, size_x, size_y = _surface_input(surface, size)
    path = [float(d) for d in np.atleast_1d(np.asarray(indentations, dtype=np.float64))]
    out = _core.bem_adhesion(heights, size_x, size_y, float(modulus), str(boundary),
                             float(work_of_adhesion), path, _opt(retract_step),
                             _opt(adhesion_range),
                             None if adhesion_model is None else str(adhesion_model))
    return BemAdhesion(**out)


PERSSON_KAPPA: float = _DEFAULTS["kappa"]
"""Persson's own small-load area coefficient √(8/π) in A/A₀ = κ p/(E* ḡ) (Persson 2001);
simulations find about 2."""


@dataclass
class PerssonTable(_Saved):
    """Persson's theory for one surface (:func:`persson`; the columns of ``asperity
    persson``): ``pressure`` (mean pressure, in the unit of ``modulus``), ``area_fraction``
    (A/A₀), ``mean_gap`` (ū, in the surface's length unit), ``stiffness_per_area``
    (K = −dp/dū) and ``contact_stiffness`` (K·A₀, comparable with the BEM's stiffness);
    the surface's ``rms_height``, spectral ``rms_gradient`` and the separation scale
    ``u0``, and the parameters used."""

    pressure: np.ndarray
    area_fraction: np.ndarray
    mean_gap: np.ndarray
    stiffness_per_area: np.ndarray
    contact_stiffness: np.ndarray
    rms_height: float
    rms_gradient: float
    u0: float
    modulus: float
    gamma: float
    kappa: float

    def __repr__(self) -> str:
        return (f"PerssonTable({len(self.pressure)} pressures, modulus={self.modulus}, "
                f"gamma={self.gamma}, kappa={self.kappa:.4g}, u0={self.u0:.4e})")


def persson(
    surface: Any,
    pressures: Optional[Sequence[float]] = None,
    *,
    size: Optional[float] = None,
    modulus: float = _DEFAULTS["modulus"],
    gamma: float = _DEFAULTS["gamma"],
    kappa: float = PERSSON_KAPPA,
    nloads: Optional[int] = None,
    pmin: Optional[float] = None,
    pmax: Optional[float] = None,
) -> PerssonTable:
    """Persson's theory from the surface's own radially averaged PSD, as ``asperity
    persson`` (the same code and numbers): relative contact area (Persson 2001, with the
    small-load coefficient ``kappa``), mean interfacial separation (Persson 2007 with Yang
    & Persson 2008's ``S = γ + (1−γ)P²``, ``gamma`` in (0, 1]) and the contact stiffness
    that follows, at the mean ``pressures`` or ``nloads`` log-spaced from ``pmin`` to
    ``pmax``. ``surface``: a :class:`Surface`, a :class:`Topography` (levelled, without
    undefined points), a SurfaceTopography topography, or heights with ``size`` = L along x.
    See docs/persson.md.

    Example::

        >>> s = asperity.surface(128, hurst=0.8, rolloff=4, rms_slope=1.0, seed=1)
        >>> t = asperity.persson(s, [1e-3, 1e-2])
        >>> bool(t.area_fraction[1] > t.area_fraction[0])
        True
    """
    heights, size_x, size_y = _surface_input(surface, size)
    values = None if pressures is None else [
        float(p) for p in np.atleast_1d(np.asarray(pressures, dtype=np.float64))]
    if nloads is not None and (isinstance(nloads, bool) or int(nloads) != nloads):
        raise ValueError(f"nloads must be an integer, got {nloads!r}")
    table = _core.persson_table(
        heights, size_x, size_y, float(modulus), float(gamma), float(kappa), values,
        None if nloads is None else int(nloads), _opt(pmin), _opt(pmax),
    )
    return PerssonTable(modulus=float(modulus), gamma=float(gamma), kappa=float(kappa), **table)


@dataclass
class StudyResult:
    """A finished study: ``columns`` (numpy arrays named as the CLI's ``alpha.csv`` or
    ``curve.csv``), ``rows`` (the same as a list of dicts) and ``tasks`` (every task's
    result as the checkpoint stores it: mean curve, α fit, per-sample α)."""

    columns: Dict[str, np.ndarray]
    rows: List[Dict[str, Any]]
    tasks: List[Dict[str, Any]]
    #: Each task's row of the comparison with the paper (see :meth:`comparison`).
    comparisons: List[Optional[Dict[str, Any]]] = field(default_factory=list, repr=False)
    #: Why the study cannot be compared (a roll-off study whose sweeps ended), or None.
    comparison_error: Optional[str] = field(default=None, repr=False)
    #: What produced it: ``study`` (``alpha`` or ``curve``), the ``folder`` and its
    #: ``spec`` (the folder's ``study.json``).
    metadata: Dict[str, Any] = field(default_factory=dict, repr=False)
    #: The study's figures as the CLI draws them (``alpha``: α(H) with the theory curves,
    #: or α(N) for one H; ``curve``: the ensemble k(F)), drawn by :mod:`asperity.plot`.
    figures: Dict[str, Any] = field(default_factory=dict, repr=False)

    def save(self, path: Union[str, os.PathLike], *, force: bool = False) -> None:
        """Writes ``path`` (``.npz``: the columns) and ``path.json`` (rows, tasks,
        comparisons, figures, :attr:`metadata`), both or neither; :func:`load` gives it
        back."""
        arrays = {name: (v.astype(str) if v.dtype == object else v)
                  for name, v in self.columns.items()}
        record = {"columns": list(self.columns), "rows": self.rows, "tasks": self.tasks,
                  "comparisons": self.comparisons,
                  "comparison_error": self.comparison_error,
                  "metadata": self.metadata, "figures": self.figures}
        _save_bundle(path, "study result", arrays, record, force)

    def __repr__(self) -> str:
        kind = self.metadata.get("study", "study")
        tasks = len(self.tasks)
        hursts = sorted({t["task"]["hurst"] for t in self.tasks if "task" in t})
        span = f", hurst {hursts[0]:g}..{hursts[-1]:g}" if hursts else ""
        return (f"StudyResult({kind}: {tasks} tasks{span}, {len(self.rows)} rows; "
                f"columns {', '.join(self.columns)})")

    def __getattr__(self, name: str) -> Any:
        try:
            return self.__dict__["columns"][name]
        except KeyError:
            raise AttributeError(name) from None

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def comparison(self) -> Dict[str, np.ndarray]:
        """The comparison with the paper, as ``asperity study compare`` writes it to
        ``comparison.csv`` (one definition, the library's ``study::compare``): per task
        with a fit, ``method``, ``n``, ``hurst``, ``quantity``, ``ours``, ``low``/``high``
        (its 95 % interval), ``reference``, ``source``, ``tolerance`` and the ``verdict``:
        ``agrees`` (the reference inside the interval widened by the tolerance), ``close``
        (within 0.02) or ``differs``. A study without roll-off compares its ensemble α
        (``quantity`` ``alpha``, interval ± t·s/√m over the m per-sample α) with eq. (6),
        eq. (24) or Hertz 1/3; one with a roll-off the steepest log–log slope of its mean
        curve over a decade (``steepest_slope``; interval: 400 bootstrap resamples of the
        sample curves its folder keeps) with the paper's "≈ 1" (tolerance 0.1). A roll-off
        study whose samples ended their sweeps (an α study without ``full_sweep``) cannot
        be compared: ``ValueError``."""
        if self.comparison_error is not None:
            raise ValueError(self.comparison_error)
        found = [c for c in self.comparisons if c is not None]
        columns = {}
        for name, kind in _core.comparison_columns():
            values = [c["row"][name] for c in found]
            columns[name] = np.array(values, dtype=object if kind == "text" else np.float64)
        columns["verdict"] = np.array([c["verdict"] for c in found], dtype=object)
        return columns


def _hursts(hurst: Union[str, float, Sequence[float]]) -> List[float]:
    if isinstance(hurst, str):
        return _core.hurst_range(hurst)
    return [float(h) for h in np.atleast_1d(np.asarray(hurst, dtype=np.float64))]


def _run_study(kind, method, sizes, hurst, samples, out, rolloff, seed, min_contacts,
               max_fraction, levels, full_sweep, force, checkpoint_every, progress,
               description, derived=(None, None, None, None)):
    # The study's keywords, read by the front-end layer (asperity_app::study::request):
    # integers as given (a negative count is refused there, in the CLI's words).
    count = lambda v: None if v is None else int(v)
    request = dict(
        kind=kind, method=str(method), sizes=[int(n) for n in sizes], hursts=_hursts(hurst),
        samples=int(samples), rolloff=_opt(rolloff),
        seed=None if seed is None else _seed(seed), min_contacts=count(min_contacts),
        max_fraction=_opt(max_fraction), levels=count(levels), full_sweep=bool(full_sweep),
        poisson=_opt(derived[0]), tangential=_text(derived[3]),
    )
    args = (request, os.fspath(out), bool(force), _opt(checkpoint_every))
    _, resistivity, thermal, _ = derived
    pair = lambda v: None if v is None else [float(x) for x in np.atleast_1d(v)]
    derived = dict(resistivity=pair(resistivity), thermal_conductivity=pair(thermal))
    # Under `mpirun -n K python ...` with mpi4py: one study over the K ranks (docs/mpi.md).
    comm = _mpi.world()
    if comm is not None and comm.Get_rank() != 0:
        progress = None  # one progress bar, rank 0's
    bar = _Progress(progress, description)
    try:
        if comm is None:
            text = _core.run_study(*args, bar.callback, eta=bar.weigh, **derived)
        else:
            text = _mpi.run_study(comm, lambda job: job.begin(*args, **derived), bar.callback)
    finally:
        bar.close()
    return json.loads(text)


def _table(table: Dict[str, Any]) -> Tuple[Dict[str, np.ndarray], List[Dict[str, Any]]]:
    """A result table of the front-end layer (``asperity_app::study::rows``: the columns
    of ``alpha.csv`` or ``curve.csv``, named and typed once) as numpy columns and as rows
    of dicts; a missing number (an empty CSV cell) is NaN in the columns, None in the
    rows."""
    names = [name for name, _ in table["columns"]]
    rows = [dict(zip(names, row)) for row in table["rows"]]
    columns = {}
    for i, (name, kind) in enumerate(table["columns"]):
        values = [row[i] for row in table["rows"]]
        if kind == "text":
            columns[name] = np.array(values, dtype=object)
        elif kind == "count":
            columns[name] = np.array(values, dtype=np.int64)
        else:
            columns[name] = np.array([np.nan if v is None else v for v in values],
                                     dtype=np.float64)
    return columns, rows


def study_alpha(
    *,
    method: str,
    n: Union[int, Sequence[int]],
    hurst: Union[str, float, Sequence[float]],
    samples: int,
    out: Union[str, os.PathLike],
    rolloff: Optional[float] = None,
    seed: Optional[int] = None,
    min_contacts: Optional[int] = None,
    max_fraction: Optional[float] = None,
    levels: Optional[int] = None,
    full_sweep: bool = False,
    force: bool = False,
    checkpoint_every: Optional[float] = None,
    progress: ProgressArg = None,
) -> StudyResult:
    """The exponent α of ``k ∝ F^α`` over grid sizes ``n`` and Hurst exponents ``hurst``
    (a list, or the CLI's text ``"-1:3:0.25"``), ``samples`` realisations each, as
    ``asperity study alpha`` -- in the same checkpoint folder ``out`` (``study.json``,
    ``checkpoint/``): a study started here resumes from the CLI and the other way round,
    with bit-identical results. Nothing else is written (no CSV, no plots).

    ``method``: ``"mdr"`` (rough lines, unit rms height) or ``"bem"`` (surfaces, unit rms
    slope, free boundaries); ``rolloff`` q0·L/2π; ``seed`` (study seed); the α window
    ``min_contacts``, ``max_fraction``; ``levels`` force levels of the mean curves;
    ``full_sweep`` solves every BEM load up to p̄ = 0.2 E* (by default a sample stops
    loading past 4 times the largest contact fraction an α window ends at, as the CLI's;
    the fits are the same); ``force`` discards another study's checkpoints in ``out``;
    ``checkpoint_every`` seconds between checkpoints of a task in progress (0: every
    batch). Each keyword left ``None`` takes the CLI's default (the library's
    ``StudySpec::default``: seed 1, 48 levels, the default α window; checkpoints every
    10 s). Ctrl-C stops after the samples in flight (``KeyboardInterrupt``); run again
    to resume.

    Returns the rows of ``alpha.csv`` (``alpha`` fitted on the ensemble-mean curve,
    ``alpha_low``/``alpha_high`` the 2.5 %/97.5 % quantiles of the per-sample α, ...).

    Example::

        >>> r = asperity.study_alpha(method="mdr", n=[512], hurst="0:1:0.5", samples=50,
        ...                          out="alpha-study")
        >>> r.hurst
        array([0. , 0.5, 1. ])
        >>> bool(r.alpha[0] > r.alpha[1] > r.alpha[2])   # α falls as H rises
        True
    """
    sizes = [n] if np.ndim(n) == 0 else list(n)
    records = _run_study("alpha", method, sizes, hurst, samples, out, rolloff, seed,
                         min_contacts, max_fraction, levels, full_sweep, force,
                         checkpoint_every, progress, f"{method} study")
    columns, rows = _table(records["alpha"])
    return StudyResult(columns, rows, records["tasks"], records["comparisons"],
                       records["comparison_error"], _study_metadata("alpha", out),
                       records["figures"])


def study_curve(
    *,
    method: str,
    n: int,
    hurst: Union[str, float, Sequence[float]],
    samples: int,
    out: Union[str, os.PathLike],
    rolloff: Optional[float] = None,
    seed: Optional[int] = None,
    min_contacts: Optional[int] = None,
    max_fraction: Optional[float] = None,
    levels: Optional[int] = None,
    force: bool = False,
    checkpoint_every: Optional[float] = None,
    progress: ProgressArg = None,
    poisson: Optional[float] = None,
    resistivity: Optional[Sequence[float]] = None,
    thermal_conductivity: Optional[Sequence[float]] = None,
    tangential: Optional[str] = None,
) -> StudyResult:
    """Ensemble-mean ``k(F)`` curves at one grid size ``n`` over ``hurst``, as
    ``asperity study curve`` (same folder, checkpoints and numbers; see
    :func:`study_alpha`). Returns the rows of ``curve.csv``: ``force``, ``stiffness``
    (mean), ``stiffness_low``/``stiffness_high`` (95 % interval of the mean),
    ``samples``, ``area_fraction`` (mean) with ``area_fraction_low``/``area_fraction_high``
    (95 % interval of the mean), per (method, n, hurst).

    BEM only: ``poisson`` (ν) adds the tangential (no-slip) stiffness at every load,
    ``tangential_ratio`` = (k_x + k_y)/(2k) with ``tangential_ratio_low``/``_high``
    (``tangential="x"`` or ``"y"``, the CLI's ``--tangential``: k_x/k or k_y/k alone, at
    about half the cost);
    ``resistivity=[ρ₁, ρ₂]`` adds ``electrical_conductance`` = 2k/(E*(ρ₁+ρ₂)) and
    ``thermal_conductivity=[κ₁, κ₂]`` ``thermal_conductance``, each with its interval
    (Barber's analogy, E* = 1), as the CLI's ``--poisson``, ``--resistivity`` and
    ``--thermal-conductivity``; ``figures["tangential"]`` then holds their plots
    (docs/tangential.md).

    Example::

        >>> c = asperity.study_curve(method="bem", n=32, hurst=[0.5], samples=4, out="curves")
        >>> c.force.shape == c.stiffness.shape
        True
        >>> bool((np.diff(c.stiffness) >= 0).all())     # k rises with F
        True
    """
    records = _run_study("curve", method, [n], hurst, samples, out, rolloff, seed,
                         min_contacts, max_fraction, levels, False, force, checkpoint_every,
                         progress, f"{method} study", (poisson, resistivity,
                                                       thermal_conductivity, tangential))
    columns, rows = _table(records["curve"])
    return StudyResult(columns, rows, records["tasks"], records["comparisons"],
                       records["comparison_error"], _study_metadata("curve", out),
                       records["figures"])


def _study_metadata(kind: str, out: Union[str, os.PathLike]) -> Dict[str, Any]:
    """A study result's identity: which study, its folder and the folder's spec."""
    folder = os.fspath(out)
    try:
        with open(os.path.join(folder, "study.json"), encoding="utf-8") as f:
            spec = json.load(f)
    except (OSError, ValueError):
        spec = None
    return {"generator": f"asperity {__version__}", "study": kind, "folder": folder,
            "spec": spec}


def study_compare(folder: Union[str, "os.PathLike[str]"], *, force: bool = False
                  ) -> Dict[str, np.ndarray]:
    """``asperity study compare FOLDER``: the finished study in ``folder`` (of
    :func:`study_alpha`, :func:`study_curve`, :func:`study_file` or the CLI) beside the
    paper, by the command's own code: writes ``comparison.csv`` and ``report.md`` (the
    verdicts, the trend with N, the window sensitivity of a BEM study) into the folder
    (an existing one is refused unless ``force``) and returns the comparison as
    :meth:`StudyResult.comparison` does: the columns of ``comparison.csv`` (``method``,
    ``n``, ``hurst``, ``quantity``, ``ours``, ``low``, ``high``, ``reference``, ``source``,
    ``tolerance``) and each row's ``verdict`` (``agrees``, ``close`` or ``differs``, as
    ``report.md`` prints it).

    A missing folder, or one without ``study.json``: ``FileNotFoundError``; an unfinished
    study, a roll-off study whose sweeps ended, an existing output without ``force``:
    ``ValueError``.

    Example::

        >>> _ = asperity.study_alpha(method="mdr", n=256, hurst=[0.5], samples=8, out="s")
        >>> c = asperity.study_compare("s")                   # writes s/comparison.csv, s/report.md
        >>> c["quantity"][0], c["verdict"][0] in ("agrees", "close", "differs")
        ('alpha', True)
    """
    import csv
    import errno

    folder = os.fspath(folder)
    for path, what in ((folder, "no such study folder"),
                       (os.path.join(folder, "study.json"), "not a study folder (no study.json)")):
        if not os.path.exists(path):
            raise FileNotFoundError(errno.ENOENT, f"{folder}: {what}", path)
    verdicts = _core.compare_study(folder, bool(force))
    with open(os.path.join(folder, "comparison.csv"), newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    columns = {}
    for name, kind in _core.comparison_columns():
        values = [r[name] if kind == "text" else float(r[name]) for r in rows]
        columns[name] = np.array(values, dtype=object if kind == "text" else np.float64)
    columns["verdict"] = np.array(verdicts, dtype=object)
    return columns


# --------------------------------------------------------------------------------------
# The paper's figures
# --------------------------------------------------------------------------------------


def study_file(path: Union[str, "os.PathLike[str]"], out: Union[str, "os.PathLike[str]"], *,
               force: bool = False, checkpoint_every: Optional[float] = None,
               progress: ProgressArg = None) -> StudyResult:
    """Runs (or resumes) the study a TOML study file describes, as ``asperity study file
    PATH --out OUT``: the file is read by the CLI's reader (the same keys, defaults and
    refusals, in the same words; see ``asperity study file --help`` and docs/sweep.toml),
    then the study runs as :func:`study_alpha` or :func:`study_curve` (its ``kind``) would
    run it, in the same folder with the same checkpoints and numbers."""
    k = _core.read_study_file(os.fspath(path))
    kind = k["kind"]
    records = _run_study(kind, k["method"], k["sizes"], k["hursts"], k["samples"], out,
                         k["rolloff"], k["seed"], k["min_contacts"], k["max_fraction"],
                         k["levels"], k["full_sweep"], force, checkpoint_every, progress,
                         f"{k['method']} study", (k["poisson"], k["resistivity"],
                                                  k["thermal_conductivity"], k["tangential"]))
    columns, rows = _table(records[kind])
    return StudyResult(columns, rows, records["tasks"], records["comparisons"],
                       records["comparison_error"], _study_metadata(kind, out),
                       records["figures"])


def study_windows(out: Union[str, "os.PathLike[str]"]) -> Dict[str, np.ndarray]:
    """α of the BEM study in the folder ``out`` (finished or running) refitted with other
    windows, as ``asperity study windows`` (the same rows, bit for bit): every start of 4,
    8 and 16 points in contact with every end of 0.5, 1 and 2 % contact, from the sample
    curves its checkpoints keep; reads only. Returns the CSV's columns by name: ``n``,
    ``hurst``, ``min_contacts``, ``max_fraction``, ``alpha`` (the ensemble-mean fit),
    ``low``, ``high`` (2.5 and 97.5 % of 400 bootstrap resamples of the samples) and
    ``samples``; counts as int64, the rest float64 (``pandas.DataFrame`` takes the dict).
    A study whose tasks keep no sample curves (MDR) is refused: ``ValueError``.

    Example::

        >>> _ = asperity.study_curve(method="bem", n=64, hurst=0.5, samples=3, seed=5,
        ...                          out="bem_study", progress=None)
        >>> w = asperity.study_windows("bem_study")
        >>> list(w), int(w["samples"][0])
        (['n', 'hurst', 'min_contacts', 'max_fraction', 'alpha', 'low', 'high', 'samples'], 3)
    """
    return dict(_core.study_windows(os.fspath(out)))


def reproduce(figure: str, out: Union[str, "os.PathLike[str]"], *, setting: str = "paper",
              force: bool = False) -> str:
    """Regenerates a figure of the paper, ``asperity reproduce FIGURE --setting SETTING
    --out OUT``: ``figure`` ``"fig1"``, ``"fig2"``, ``"fig5"``, ``"fig6"``,
    ``"fig15.1"``, ``"fig15.2"`` or ``"all"``; ``setting`` ``"quick"`` (minutes),
    ``"medium"`` (hours) or ``"paper"`` (about 10 hours for all). Writes one sub-folder
    per figure (its CSV, PNG, SVG and ``report.md`` with the paper's value beside ours;
    resumable, never overwritten without ``force``) and returns ``out``.

    It runs the command line compiled into this package (the installed ``asperity``
    command) in a child process of its own, so a long run keeps the command's own
    checkpoints, progress lines and Ctrl-C handling (an interrupted figure resumes when
    called again), and the files are the CLI's byte for byte. Its studies are also
    Python calls (:func:`study_alpha`, :func:`study_curve`, :meth:`StudyResult.comparison`).
    A bad request raises ``ValueError`` with the CLI's one line; a failed run
    ``RuntimeError`` with its last line.

    Example::

        >>> import os
        >>> folder = asperity.reproduce("fig15.1", "paper-figures")
        >>> os.path.exists(os.path.join(folder, "fig15.1", "fig15_1.csv"))
        True
    """
    import subprocess

    out = os.fspath(out)
    args = [sys.executable, "-m", "asperity._cli", "reproduce", str(figure), "--setting",
            str(setting), "--out", out, *(["--force"] if force else [])]
    result = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        lines = [l for l in result.stderr.splitlines() if l.strip()]
        errors = [l[len("error: "):] for l in lines if l.startswith("error: ")]
        message = (errors or lines or [f"exit status {result.returncode}"])[-1]
        raise (ValueError if result.returncode == 2 else RuntimeError)(message)
    return out


# --------------------------------------------------------------------------------------
# Saving and loading
# --------------------------------------------------------------------------------------


def _save_bundle(path: Union[str, os.PathLike], kind: str, arrays: Dict[str, np.ndarray],
                 record: Dict[str, Any], force: bool) -> None:
    """Writes a result as ``path`` (``.npz``, numpy's archive of ``.npy`` arrays, no
    pickles) and its JSON sidecar ``path.json`` (``kind``, generator, ``record``), both or
    neither, by the library's all-or-nothing writer (the CLI's)."""
    import io

    path = os.fspath(path)
    if not path.lower().endswith(".npz"):
        raise ValueError(f"path {path}: the file name must end in .npz")
    for name, value in arrays.items():
        if value.dtype == object:
            raise ValueError(f"{name}: an array of Python objects cannot be saved")
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    sidecar = {"kind": kind, "generator": f"asperity {__version__}", **record}
    try:
        text = json.dumps(sidecar, indent=2, allow_nan=False, default=_json_scalar)
    except ValueError as e:
        raise ValueError(f"{path}: the record holds a non-finite number ({e})") from None
    _core.save_files([(path, buffer.getvalue()), (path + ".json", (text + "\n").encode())],
                     bool(force))


def _is_netcdf(path: Union[str, os.PathLike]) -> bool:
    return os.fspath(path).lower().endswith(".nc")


def _result_path(path: Union[str, os.PathLike]) -> None:
    """Refuses a result's file name that names neither format it can be saved in."""
    name = os.fspath(path)
    if not (_is_netcdf(name) or name.lower().endswith(".npz")):
        raise ValueError(f"path {name}: the file name must end in .npz (numpy archive and "
                         "JSON sidecar) or .nc (NetCDF)")


#: 1-D columns that lie along a dimension of their own, not along the loads.
_NC_ALONG = {"patch_areas_m2": "patch"}


def _placement(name: str, array: np.ndarray, stacked: bool) -> str:
    """Where a sweep's array lies in a NetCDF file (see ``asperity_app::fields``)."""
    if stacked:
        return "load_map"
    if array.ndim == 2:
        return "map"
    if array.ndim == 1:
        return f"along:{_NC_ALONG[name]}" if name in _NC_ALONG else "load"
    raise ValueError(f"column {name}: a {array.ndim}-D array cannot be saved as NetCDF")


def _nc_sides(metadata: Dict[str, Any], shape: Tuple[int, int]) -> Tuple[float, float]:
    """The sides (x, y) of the surface a result lies on, from its metadata: a solver's
    settings, a contact request's sizes, or the record of ``asperity bem``."""
    settings = metadata.get("solver") if isinstance(metadata.get("solver"), dict) else metadata
    size = settings.get("size")
    size_y = settings.get("size_y")
    if "sizes" in metadata:
        size, size_y = metadata["sizes"]
    if size is None:
        raise ValueError("the metadata give no side length: cannot write the map's "
                         "coordinates (save as .npz instead)")
    rows, cols = shape
    return float(size), float(size_y) if size_y is not None else float(size) * rows / cols


def _nc_units(metadata: Dict[str, Any]) -> Tuple[bool, bool]:
    """Which units are known (metres, pascals): SI for ``contact``; metres for a
    measured surface (read in metres; the modulus's unit is the user's), as the CLI."""
    if "contact" in metadata:
        return True, True
    surface = metadata.get("surface")
    measured = isinstance(surface, dict) and "provenance" in surface
    return measured or metadata.get("size_source") == "file", False


def _save_netcdf(path: Union[str, os.PathLike], kind: str,
                 arrays: Dict[str, Tuple[str, np.ndarray]], record: Dict[str, Any],
                 force: bool) -> None:
    """Writes a result as one NetCDF file (the library's ``asperity::fields``, as
    ``asperity bem --fields FILE.nc``): each array where ``arrays`` places it, float64,
    int32 or bool, its dtype kept in the record so that :func:`load` restores it."""
    path = os.fspath(path)
    variables, dtypes, texts, shape = [], {}, {}, None
    for name, (place, value) in arrays.items():
        a = np.asarray(value)
        dtypes[name] = a.dtype.str
        if a.dtype.kind == "U":  # names (a load path's branches): in the record
            texts[name] = a.tolist()
            continue
        if a.dtype.kind in "iu":
            fits = a.size == 0 or (a.min() >= -2**31 and a.max() < 2**31)
            a = a.astype(np.int32 if fits else np.float64)
            if not fits and np.abs(a).max() > 2**53:
                raise ValueError(f"{name}: integers beyond 2**53 cannot be saved as NetCDF")
        elif a.dtype.kind == "f":
            a = a.astype(np.float64)
        elif a.dtype.kind != "b":
            raise ValueError(f"{name}: a {a.dtype} array cannot be saved as NetCDF")
        if place in ("map", "load_map"):
            shape = a.shape[-2:]
        variables.append((name, place, np.ascontiguousarray(a)))
    metadata = record.get("metadata", {})
    grid = None if shape is None else (tuple(shape), _nc_sides(metadata, tuple(shape)))
    sidecar = {"kind": kind, "generator": f"asperity {__version__}", **record,
               "dtypes": dtypes, "texts": texts}
    try:
        text = json.dumps(sidecar, allow_nan=False, default=_json_scalar)
    except ValueError as e:
        raise ValueError(f"{path}: the record holds a non-finite number ({e})") from None
    _core.write_fields(path, grid, _nc_units(metadata), f"asperity {kind}", text, variables,
                       bool(force))


def _load_netcdf(path: str) -> Any:
    """A result saved as NetCDF (by :meth:`Sweep.save`, :meth:`ContactResult.save` or
    ``asperity bem --fields FILE.nc``), or None for another NetCDF file (a topography)."""
    try:
        attributes, _, variables = _core.read_fields(path)
    except ValueError:
        return None  # not laid out as a field file: read_topography's to read or refuse
    text = dict(attributes).get("asperity_record")
    if text is None:
        return None
    record = json.loads(text)
    dtypes = record.get("dtypes", {})
    arrays = {name: (a.astype(np.dtype(dtypes[name])) if name in dtypes else a)
              for name, _, _, _, _, a in variables}
    for name, values in record.get("texts", {}).items():
        arrays[name] = np.array(values, dtype=np.dtype(dtypes[name]))
    kind = record.get("kind")
    if kind == "contact result":
        return ContactResult(**record["scalars"], **arrays, metadata=record["metadata"])
    if kind == "sweep":
        scalars = record.get("scalars", {})
        columns = {name: (scalars[name] if name in scalars else
                          list(arrays[name]) if name in record["stacked"] else arrays[name])
                   for name in record["columns"]}
        return Sweep(columns, record["metadata"])
    # `asperity bem --fields FILE.nc`: the record is OUT.csv.json's.
    columns = {name: (list(a) if a.ndim == 3 else a) for name, a in arrays.items()}
    return Sweep(columns, record)


def _json_scalar(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON")


def _read_sidecar(path: str) -> Optional[Dict[str, Any]]:
    """The sidecar of `path` (None: it has none), read by the rules of every input
    (``asperity_app::argument::saved_sidecar``): `path` and its sidecar regular files (a
    FIFO is refused, not waited on), the sidecar bounded and a JSON object, else
    ``ValueError``."""
    text = _core.saved_sidecar(path)
    return None if text is None else json.loads(text)


def _npz(path: str) -> Dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as archive:
        return {name: archive[name] for name in archive.files}


Psd._kind = "psd"
Analysis._kind = "analysis"
Patches._kind = "patches"
MdrCurve._kind = "mdr curve"
SlipCycle._kind = "slip cycle"
BemAdhesion._kind = "bem adhesion"
PerssonTable._kind = "persson table"
_SAVED = {cls._kind: cls for cls in (Psd, Analysis, Patches, MdrCurve, SlipCycle, BemAdhesion,
                                      PerssonTable)}


def load(path: Union[str, "os.PathLike[str]"]) -> Any:
    """Loads what asperity saved, as the object that was saved: a :class:`Surface` or
    :class:`Line` (``.npy`` with the sidecar of ``asperity surface``/``line`` or
    :meth:`Surface.save`), a :class:`Topography` (``.npy`` with the sidecar of ``asperity
    import`` or :meth:`Topography.save`, heights bit for bit with their sizes and
    provenance; any other file, X3P included, through :func:`read_topography`), a
    :class:`Sweep`, :class:`ContactResult`, :class:`StudyResult`, :class:`Psd`,
    :class:`Patches`, :class:`MdrCurve`, :class:`SlipCycle`, :class:`BemAdhesion` or
    :class:`PerssonTable` (``.npz`` + sidecar of their ``save``). Arrays are read without
    pickles.

    Example::

        >>> sweep = asperity.Solver(asperity.surface(32, hurst=0.8, seed=1)).sweep(
        ...     nloads=3, pmin=1e-3, pmax=1e-2)
        >>> sweep.save("sweep.npz")
        >>> back = asperity.load("sweep.npz")
        >>> bool((back.force == sweep.force).all()), back.metadata == sweep.metadata
        (True, True)
    """
    path = os.fspath(path)
    if _is_netcdf(path):
        loaded = _load_netcdf(path)
        if loaded is not None:
            return loaded
    record = _read_sidecar(path)
    kind = None if record is None else record.get("kind")
    if kind in ("surface", "line"):
        heights = np.load(path, allow_pickle=False)
        size = float(record["spec"]["size"])
        return (Surface if kind == "surface" else Line)(heights, size, record)
    if kind in ("measured surface", "measured line") and "provenance" in record:
        heights = np.load(path, allow_pickle=False)
        sizes = [float(v) for v in record["sizes"]]
        return Topography(heights, sizes[0], sizes[1] if len(sizes) > 1 else None,
                          record["provenance"])
    if kind == "sweep":
        arrays = _npz(path)
        scalars = record.get("scalars", {})
        columns = {name: (scalars[name] if name in scalars else
                          list(arrays[name]) if name in record["stacked"] else arrays[name])
                   for name in record["columns"]}
        return Sweep(columns, record["metadata"])
    if kind == "contact result":
        arrays = _npz(path)
        return ContactResult(**record["scalars"], **arrays, metadata=record["metadata"])
    if kind == "study result":
        arrays = _npz(path)
        columns = {name: (arrays[name].astype(object) if arrays[name].dtype.kind == "U"
                          else arrays[name]) for name in record["columns"]}
        return StudyResult(columns, record["rows"], record["tasks"], record["comparisons"],
                           record.get("comparison_error"), record["metadata"],
                           record.get("figures", {}))
    if kind in _SAVED:
        return _SAVED[kind](**_npz(path), **record["values"])
    return read_topography(path)
