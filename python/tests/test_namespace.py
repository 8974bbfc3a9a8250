"""The package's face: only public names in `dir(asperity)`, every `__all__` name real,
short reprs (a study shows its shape, not its rows), and `stats` naming what it takes."""

import importlib
import inspect

import numpy as np
import pytest

import asperity

from test_topography import shared


def test_only_public_names_are_listed():
    names = dir(asperity)
    for helper in ("np", "os", "json", "sys", "warnings", "dataclass", "field", "Any",
                   "annotations", "List"):
        assert helper not in names, helper
        assert not hasattr(asperity, helper), helper
    for name in asperity.__all__:
        assert hasattr(asperity, name), name
    assert names == sorted(asperity.__all__)
    # Not only hidden from dir(): the package's namespace holds nothing public but
    # __all__ (the implementation and its imports live in the private asperity._api),
    # and the plot submodule once imported.
    importlib.import_module("asperity.plot")
    public = {n for n in vars(asperity) if not n.startswith("_")}
    assert public - set(asperity.__all__) == {"plot"}


@pytest.mark.parametrize("module", ["reference", "plot"])
def test_submodules_list_every_public_object_and_nothing_else(module):
    if module == "plot":
        pytest.importorskip("matplotlib")
    mod = importlib.import_module(f"asperity.{module}")
    assert dir(mod) == sorted(mod.__all__)
    assert all(hasattr(mod, n) for n in mod.__all__)
    # Every function and class the module defines without a leading underscore is public.
    defined = {n for n, v in vars(mod).items()
               if not n.startswith("_") and getattr(v, "__module__", None) == mod.__name__
               and (inspect.isfunction(v) or inspect.isclass(v))}
    assert defined == set(mod.__all__)


def test_reprs_show_shapes_not_contents(tmp_path):
    s = asperity.surface(256, hurst=0.8, seed=1)
    assert repr(s) == "Surface(256x256, size=1.0, seed=1)"
    sweep = asperity.Solver(s).sweep(nloads=40, pmin=1e-3, pmax=1e-2, fields=True)
    assert len(repr(sweep)) < 200 and repr(sweep).startswith("Sweep(40 loads:")
    r = asperity.Solver(s).solve(pressure=1e-2)
    assert "fields 256x256" in repr(r) and len(repr(r)) < 200
    t = asperity.read_topography(shared("x3p-2.x3p"), detrend="plane")
    assert repr(t).startswith("Topography(650x650, sizes=")
    study = asperity.study_curve(method="mdr", n=256, hurst=[0.25, 0.5, 0.75], samples=3,
                                 out=tmp_path / "study")
    text = repr(study)
    assert text.startswith("StudyResult(curve: 3 tasks, hurst 0.25..0.75") and len(text) < 300


def test_stats_takes_a_topography_and_names_what_it_takes():
    t = asperity.read_topography(shared("x3p-2.x3p"), detrend="plane")
    assert asperity.stats(t)["rms_slope"] == asperity.stats(t.heights, size=t.physical_sizes)["rms_slope"]
    with pytest.raises(ValueError, match="expected an asperity Surface, Line or Topography"):
        asperity.stats({"heights": t.heights})
