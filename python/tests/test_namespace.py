"""The package's face: only public names in `dir(asperity)`, every `__all__` name real,
short reprs (a study shows its shape, not its rows), and `stats` naming what it takes."""

import numpy as np
import pytest

import asperity

from test_topography import shared


def test_only_public_names_are_listed():
    names = dir(asperity)
    for helper in ("np", "os", "json", "sys", "warnings", "dataclass", "field", "Any"):
        assert helper not in names, helper
    for name in asperity.__all__:
        assert hasattr(asperity, name), name
    assert set(names) == set(asperity.__all__)


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
