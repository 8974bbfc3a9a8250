"""The docstrings' examples run as tests: every ``>>>`` example (numpy-style ``Examples``
sections and ``Example::`` blocks) of every public object of ``asperity``,
``asperity.reference`` and ``asperity.plot``, in a fresh folder, with ``asperity`` and
``np`` in scope. Every example runs and must print what it shows: one that needs a measured
scan writes a stand-in first (a synthetic map saved as ``scan.x3p``); none is skipped."""

import doctest

import numpy as np
import pytest

import asperity
import asperity.reference

try:
    import matplotlib

    matplotlib.use("Agg")
    import asperity.plot

    MODULES = (asperity, asperity.reference, asperity.plot)
except ImportError:  # pragma: no cover - matplotlib is optional
    MODULES = (asperity, asperity.reference)


def _examples():
    finder = doctest.DocTestFinder(exclude_empty=True)
    seen = set()
    for module in MODULES:
        objects = [(module.__name__, module)]
        objects += [(f"{module.__name__}.{n}", getattr(module, n)) for n in module.__all__]
        for name, obj in objects:
            # module=False: no filtering by defining module (the API lives in asperity._api).
            for test in finder.find(obj, name, module=False, globs={}):
                if test.examples and test.name not in seen:
                    seen.add(test.name)
                    yield test


EXAMPLES = sorted(_examples(), key=lambda t: t.name)


def test_there_are_examples_to_run_and_none_is_skipped():
    # A guard: the collection itself must find the package's examples, and an example
    # that does not run is not an example.
    assert len(EXAMPLES) >= 20
    skipped = [t.name for t in EXAMPLES for e in t.examples
               if e.options.get(doctest.SKIP)]
    assert not skipped, skipped


@pytest.mark.parametrize("test", EXAMPLES, ids=[t.name for t in EXAMPLES])
def test_docstring_example_runs(test, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    test.globs = {"asperity": asperity, "np": np, "reference": asperity.reference}
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    runner = doctest.DocTestRunner(optionflags=flags)
    report = []
    runner.run(test, out=report.append)
    assert runner.failures == 0, "".join(report)
