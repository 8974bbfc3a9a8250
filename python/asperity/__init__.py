"""asperity: contact mechanics of randomly rough surfaces, from Python.

The Python face of the ``asperity`` Rust library (the same code as the ``asperity``
command line, so the same seed gives the same numbers bit for bit):

* :func:`surface`, :func:`line` -- self-affine rough surfaces and lines (Fourier
  synthesis, ``C2D(q) ∝ q^(-2H-2)``, roll-off / cut-off / short cut-off, rms height or
  slope), returned as numpy arrays with their metadata;
* :func:`stats`, :func:`psd`, :func:`analysis` -- rms height, slope, curvature and the
  (radially averaged) power spectrum with an optional power-law fit; the bearing-area
  curve, the ACF (1D and 2D), scale-dependent slope and curvature, variable-bandwidth rms
  height and the height, slope and curvature distributions;
* :class:`Solver` -- the boundary-element contact solver (bound-constrained conjugate
  gradients or Polonsky & Keer, on FFTs; free or periodic boundaries), reusable across
  loads, with frozen-set and finite-difference stiffness and load sweeps;
* :func:`mdr` -- the method of dimensionality reduction: rough lines and axisymmetric
  indenters on linear, Hertz (15.2) or fractal (15.7) spring foundations;
* :func:`study_alpha`, :func:`study_curve` -- checkpointed ensemble studies of the exponent
  α of ``k ∝ F^α`` and of mean ``k(F)`` curves, in the CLI's folders (a study started here
  resumes from ``asperity study`` and the other way round); :func:`study_windows` refits a
  BEM study's α with other windows; :func:`study_compare` writes ``asperity study
  compare``'s comparison with the paper (``comparison.csv``, ``report.md``).

Conventions (as the library's): lengths in the unit of the heights, E* = 1 by default,
side L = 1 by default; arrays row-major ``(row, col) = (y, x)`` with square pixels
``L / cols``; wavenumbers as wavelengths per side ``q L / 2π``; heights positive up,
pressure ≥ 0, gap ≥ 0; forces in ``E* · length²``.

Long computations release the GIL (other Python threads run meanwhile) and stop on Ctrl-C:
a solve, stiffness or sweep within a second (the solver checks every iteration), a study
after the samples in flight.
Errors: ``ValueError`` for bad input (the CLI's one-line message), ``MemoryError`` when a
grid would not fit in memory, :class:`ConvergenceError` and
:class:`BeyondFullContactError` from the solver.

Example::

    >>> import asperity
    >>> s = asperity.surface(128, hurst=0.8, rolloff=4, rms_slope=1.0, seed=1)
    >>> solver = asperity.Solver(s)
    >>> result = solver.solve(pressure=0.01)
    >>> 0 < result.area_fraction < 0.2
    True
"""

from . import reference
from ._api import (  # noqa: F401 (re-exported)
    ANALYSES,
    analysis,
    Analysis,
    AsperityWarning,
    bem_adhesion,
    BemAdhesion,
    contact,
    ContactResult,
    effective_modulus,
    import_topography,
    Line,
    line,
    load,
    mdr,
    mdr_slip,
    MdrCurve,
    patches,
    Patches,
    persson,
    PERSSON_KAPPA,
    PerssonTable,
    Psd,
    psd,
    read_topography,
    reproduce,
    SlipCycle,
    Solver,
    stats,
    study_alpha,
    study_compare,
    study_curve,
    study_file,
    study_windows,
    StudyResult,
    Surface,
    surface,
    Sweep,
    Topography,
    UnitWarning,
    UnlevelledWarning,
)
from ._asperity import BeyondFullContactError, ConvergenceError, __version__

# The public names, and only these: the implementation and its helpers (numpy as ``np``,
# ``os``, ``json``, ...) live in the private module ``asperity._api``.
__all__ = [
    "ANALYSES",
    "Analysis",
    "AsperityWarning",
    "BeyondFullContactError",
    "ContactResult",
    "BemAdhesion",
    "ConvergenceError",
    "Line",
    "MdrCurve",
    "PERSSON_KAPPA",
    "PerssonTable",
    "Psd",
    "Solver",
    "StudyResult",
    "Surface",
    "Sweep",
    "Topography",
    "UnitWarning",
    "UnlevelledWarning",
    "analysis",
    "contact",
    "bem_adhesion",
    "effective_modulus",
    "patches",
    "Patches",
    "SlipCycle",
    "line",
    "load",
    "mdr",
    "mdr_slip",
    "persson",
    "psd",
    "import_topography",
    "read_topography",
    "reference",
    "reproduce",
    "stats",
    "study_alpha",
    "study_compare",
    "study_curve",
    "study_file",
    "study_windows",
    "surface",
    "__version__",
]


def __dir__() -> list[str]:
    """The public names only (``dir(asperity)``, tab completion)."""
    return sorted(__all__)
