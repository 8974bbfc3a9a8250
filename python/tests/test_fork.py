"""Issue 33, item 9: a child of a default (fork) ``multiprocessing.Pool`` works after its parent
has used asperity. A forked child inherits rayon's global pool without its threads, so any
parallel work the bindings start outside their own per-thread pool waits forever there; each
call below runs first in the parent (which starts every pool), then in forked children, with a
deadline so that a regression fails instead of hanging the suite."""
import multiprocessing as mp
import sys

import numpy as np
import pytest

import asperity

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="fork is Linux's default start method")


def _rough():
    return asperity.surface(48, hurst=0.8, rolloff=4, rms_slope=1.0, seed=3)


CALLS = {
    "surface": lambda: float(np.asarray(_rough().heights).std()),
    "line": lambda: float(np.asarray(asperity.line(256, hurst=0.7, seed=2).heights).std()),
    "stats": lambda: asperity.stats(np.asarray(_rough().heights), size=1.0)["rms_slope"],
    "psd": lambda: float(asperity.psd(np.asarray(_rough().heights), size=1.0).q[-1]),
    "solve": lambda: asperity.Solver(np.asarray(_rough().heights)).solve(pressure=0.05).area_fraction,
    "contact": lambda: asperity.contact(np.asarray(_rough().heights) * 1e-6, 1e-4, pressures=[1e7],
                                        modulus=1e11).area_fraction[0],
    "mdr": lambda: float(asperity.mdr(radial=np.linspace(0, 1, 101) ** 2 / 2, radial_step=1e-2,
                                      n=101, dx=1e-2, nloads=5).force[-1]),
}


def _call(name):
    return CALLS[name]()


@pytest.mark.parametrize("name", sorted(CALLS))
def test_a_forked_child_gives_the_parents_result(name):
    expected = _call(name)  # the parent starts its pools first
    context = mp.get_context("fork")
    with context.Pool(2) as pool:
        results = pool.map_async(_call, [name] * 4).get(timeout=120)
    assert results == [expected] * 4
