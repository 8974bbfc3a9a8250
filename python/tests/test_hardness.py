"""The hardness cap from Python (`Solver(hardness=)`): the CLI's numbers bit for bit
(`asperity bem --hardness`, `asperity contact --hardness`), and the oracles of
elastic–perfectly-plastic contact (docs/hardness.md): a cap above the elastic peak pressure
gives the elastic result exactly; every point satisfies the capped contact conditions; a
load path keeps the plastic displacement (hysteresis). The refusals are rows of
test_rules.py's BEM table."""

import json

import numpy as np
import pytest

import asperity

from test_cli_identity import read_csv


@pytest.fixture(scope="module")
def rough(tmp_path_factory):
    """A 48×40 surface (L = 2) saved for the CLI, and a hardness that caps part of the
    contact at every load below: half the elastic peak pressure at p̄ = 0.01."""
    s = asperity.surface(48, m=40, hurst=0.8, rolloff=3, rms_slope=0.5, seed=7, size=2.0)
    path = tmp_path_factory.mktemp("hardness") / "s.npy"
    s.save(path)
    peak = asperity.Solver(s).solve(pressure=0.01).pressure.max()
    return s, path, float(f"{0.5 * peak:.6g}")


CASES = [
    ("free", ["--pressures", "0.003,0.01,0.03"], dict(pressures=[0.003, 0.01, 0.03])),
    ("periodic", ["--forces", "0.05,0.02"], dict(forces=[0.05, 0.02])),
    ("free", ["--indentations", "0,0.01,0.02"], dict(indentations=[0, 0.01, 0.02])),
    ("periodic", ["--indentations", "0.05,0.07"], dict(indentations=[0.05, 0.07])),
]


@pytest.mark.parametrize("solver_name", ["bccg", "pk"])
@pytest.mark.parametrize("boundary,flags,kwargs", CASES)
def test_a_capped_sweep_equals_bem_hardness(cli, tmp_path, rough, boundary, flags, kwargs,
                                            solver_name):
    """Every column of `asperity bem --hardness H` (plastic_fraction and the
    finite-difference stiffness included) and every field, bit for bit, and the record
    states the hardness."""
    s, path, h = rough
    cli("bem", "--surface", path, "--boundary", boundary, *flags, "--hardness", h,
        "--fd-stiffness", "--tol", 1e-9, "--solver", solver_name, "--fields", tmp_path / "f",
        "--out", tmp_path / "out.csv", "--quiet")
    table = read_csv(tmp_path / "out.csv")
    record = json.loads((tmp_path / "out.csv.json").read_text())
    assert record["hardness"] == h and "plastic_fraction" in record["columns"]
    solver = asperity.Solver(np.load(path), 2.0, boundary=boundary, tolerance=1e-9,
                             solver=solver_name, hardness=h)
    assert solver.hardness == h
    sweep = solver.sweep(**kwargs, fd_stiffness=True, fields=True)
    assert sweep.metadata["solver"]["hardness"] == h
    for name, column in table.items():
        ours = [None if np.isnan(v) else v for v in sweep[name].tolist()]
        assert ours == column, name
    assert max(table["plastic_fraction"]) > 0, "the cap is reached"
    for k in range(len(sweep)):
        p = np.load(tmp_path / "f" / f"pressure_{k}.npy")
        assert np.array_equal(sweep.pressure[k], p)
        assert np.array_equal(sweep.gap[k], np.load(tmp_path / "f" / f"gap_{k}.npy"))
        assert p.max() <= h


def test_a_capped_solver_in_pa_equals_contact_hardness(cli, tmp_path):
    """`Solver(young=, poisson=, hardness=Pa)` on a measured surface gives the numbers of
    `asperity contact --hardness` (the same library sweep, the same SI units): force,
    indentation, area and plastic fractions, stiffness, iterations, residual."""
    s = asperity.surface(64, hurst=0.8, rolloff=2, rms_slope=1, seed=2, size=1e-4)
    np.save(tmp_path / "h.npy", s.heights * 1e-6)
    cli("import", tmp_path / "h.npy", "--size", "1e-4", "--detrend", "none", "--out",
        tmp_path / "t.npy")
    t = asperity.read_topography(tmp_path / "t.npy", detrend="none")
    hardness, loads = 4e5, [1e4, 1e5]
    cli("contact", tmp_path / "t.npy", "--young", 210e9, "--poisson", 0.3, "--pressures",
        "1e4,1e5", "--hardness", hardness, "--detrend", "none", "--out", tmp_path / "c.csv")
    theirs = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True)
    solver = asperity.Solver(t, young=210e9, poisson=0.3, hardness=hardness)
    ours = solver.sweep(pressures=loads)
    pairs = {"mean_pressure": "mean_pressure_pa", "force": "force_n",
             "indentation": "indentation_m", "area_fraction": "area_fraction",
             "plastic_fraction": "plastic_fraction", "stiffness": "stiffness_n_per_m",
             "iterations": "iterations", "residual": "residual"}
    for name, theirs_name in pairs.items():
        assert np.array_equal(ours[name], theirs[theirs_name]), name
    assert ours.plastic_fraction[-1] > 0


def test_contact_load_path_equals_the_clis_contact_load_path(cli, tmp_path):
    """`asperity.contact(..., load_path=True)` is `asperity contact --load-path`: every
    column of its table bit for bit (branch names included), SI units; what a path cannot
    carry is refused alike."""
    s = asperity.surface(48, hurst=0.8, rolloff=2, rms_slope=1, seed=4, size=1e-4)
    np.save(tmp_path / "h.npy", s.heights * 1e-6)
    cli("import", tmp_path / "h.npy", "--size", "1e-4", "--detrend", "none", "--out",
        tmp_path / "t.npy")
    t = asperity.read_topography(tmp_path / "t.npy", detrend="none")
    loads = [1e4, 1e5, 3e4, 2e5]
    cli("contact", tmp_path / "t.npy", "--young", 210e9, "--poisson", 0.3, "--pressures",
        ",".join(map(str, loads)), "--hardness", 4e5, "--load-path", "--detrend", "none",
        "--out", tmp_path / "p.csv")
    import csv

    with open(tmp_path / "p.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    ours = asperity.contact(t, young=210e9, poisson=0.3, pressures=loads, hardness=4e5,
                            load_path=True)
    assert list(rows[0]) == [n for n in ours.columns if n != "permanent_displacement_m"]
    assert list(ours.branch) == [r["branch"] for r in rows]
    assert list(ours.branch) == ["loading", "loading", "unloading", "loading"]
    for name in list(rows[0])[1:]:
        assert ours[name].tolist() == [float(r[name]) for r in rows], name
    assert ours.permanent_displacement_m.shape == t.heights.shape
    assert ours.permanent_max_m[-1] > 0
    refused = cli("contact", tmp_path / "t.npy", "--young", 210e9, "--poisson", 0.3,
                  "--pressures", "1e4", "--load-path", "--tangential", "--detrend", "none",
                  ok=False).stderr
    with pytest.raises(ValueError, match="load_path does not go with tangential") as err:
        asperity.contact(t, young=210e9, poisson=0.3, pressures=[1e4], load_path=True,
                         tangential=True)
    assert str(err.value).split(" (")[1] in refused


def test_contact_reports_its_progress_per_load_and_stops_on_an_exception():
    """`contact(progress=)` (`asperity contact --progress`): called before the first load
    and after each, with the same numbers as without it; an exception it raises stops the
    sweep and comes back."""
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_slope=1, seed=4, size=1e-4)
    heights, loads = s.heights * 1e-6, [1e4, 3e4, 1e5]
    calls = []
    ours = asperity.contact(heights, 1e-4, young=210e9, poisson=0.3, pressures=loads,
                            progress=lambda done, total: calls.append((done, total)))
    assert calls == [(0, 3), (1, 3), (2, 3), (3, 3)]
    quiet = asperity.contact(heights, 1e-4, young=210e9, poisson=0.3, pressures=loads)
    assert ours.force_n.tolist() == quiet.force_n.tolist()

    def stop(done, total):
        if done == 1:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        asperity.contact(heights, 1e-4, young=210e9, poisson=0.3, pressures=loads,
                         progress=stop)


@pytest.mark.parametrize("solver_name", ["bccg", "pk"])
@pytest.mark.parametrize("boundary", ["free", "periodic"])
def test_a_cap_above_the_elastic_peak_is_the_elastic_result_bit_for_bit(rough, boundary,
                                                                        solver_name):
    """Each solve from cold (load and displacement control): the hard wall's scalars,
    fields and stiffness to the bit, no plastic point. In a sweep the first load is too;
    the later, warm-started loads agree to the tolerance only: under a cap the library
    starts them from the previous pressure, not from the hard wall's tangent predictor
    (`predict_from_tangent`), so they take other (converged) iterates."""
    s, _, _ = rough
    elastic = asperity.Solver(s, boundary=boundary, solver=solver_name)
    loads = [0.003, 0.01, 0.03]
    want = elastic.sweep(pressures=loads, fields=True)
    peak = max(p.max() for p in want.pressure)
    capped = asperity.Solver(s, boundary=boundary, solver=solver_name, hardness=1.5 * peak)
    # Displacement control starts cold from local springs (d − f)/K₀₀, above the peak:
    # a cap no iterate reaches is then higher.
    high = asperity.Solver(s, boundary=boundary, solver=solver_name, hardness=1e3 * peak)
    controls = [(dict(pressure=p), capped) for p in loads]
    controls += [(dict(indentation=d), high) for d in want.indentation]
    for control, solver in controls:
        elastic.reset()
        solver.reset()
        a, b = elastic.solve(**control), solver.solve(**control)
        for name in ("force", "mean_pressure", "indentation", "area_fraction", "contact_points",
                     "iterations", "residual"):
            assert getattr(a, name) == getattr(b, name), (control, name)
        for name in ("pressure", "gap", "displacement"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), (control, name)
        assert elastic.stiffness() == solver.stiffness()
        assert b.plastic_points == 0 and not b.plastic_displacement.any()
    capped.reset()
    got = capped.sweep(pressures=loads, fields=True)
    for name in ("force", "indentation", "area_fraction", "stiffness", "iterations", "residual"):
        assert got[name][0] == want[name][0], name
    assert np.array_equal(got.pressure[0], want.pressure[0])
    assert np.all(got.plastic_fraction == 0)
    for k in (1, 2):
        # Two solutions each within the tolerance (1e-8): measured ≤ 2.1e-8 of the peak.
        assert np.abs(got.pressure[k] - want.pressure[k]).max() < 1e-6 * peak
        assert abs(got.force[k] / want.force[k] - 1) < 1e-12


@pytest.mark.parametrize("solver_name", ["bccg", "pk"])
@pytest.mark.parametrize("boundary", ["free", "periodic"])
@pytest.mark.parametrize("load", [dict(pressure=0.02), dict(indentation=0.03)])
def test_capped_solves_satisfy_the_conditions_at_every_point(rough, boundary, solver_name,
                                                             load):
    """p ∈ [0, H]; g = 0 where 0 < p < H, g ≥ 0 out of contact, g ≤ 0 at the cap; the
    plastic displacement is −g at the cap and zero elsewhere; the counts agree."""
    s, _, h = rough
    solver = asperity.Solver(s, boundary=boundary, solver=solver_name, hardness=h)
    r = solver.solve(**load)
    p, g, w = r.pressure, r.gap, r.plastic_displacement
    assert p.min() >= 0 and p.max() <= h
    cap, elastic, free = p == h, (p > 0) & (p < h), p == 0
    assert cap.any() and elastic.any()
    assert np.all(g[elastic] == 0) and np.all(g[free] >= 0) and np.all(g[cap] <= 0)
    assert np.array_equal(w, np.where(cap, -g, 0.0))
    assert r.plastic_points == cap.sum() and r.contact_points == (p > 0).sum()
    assert r.plastic_fraction == cap.sum() / p.size
    # F ≤ H·A: no point carries more than the hardness.
    dx = s.size / p.shape[1]
    assert r.force <= h * r.contact_points * dx * dx * (1 + 1e-12)


@pytest.mark.parametrize("boundary", ["free", "periodic"])
def test_a_load_path_keeps_the_plastic_displacement(rough, boundary):
    """Loading, unloading, reloading: unloading is elastic on the flattened surface (deeper
    at the same load, nothing yields, at least as much area), reloading to the largest
    load comes back to it; the permanent displacement is the solver's afterwards. The
    path's first step is a cold solve and its stiffness, bit for bit."""
    s, _, h = rough
    solver = asperity.Solver(s, boundary=boundary, hardness=h)
    path = solver.load_path(pressures=[0.01, 0.03, 0.01, 0.03])
    first, top, down, again = range(4)
    assert path.plastic_fraction[top] > 0 and path.permanent_max[top] > 0
    assert path.indentation[down] > path.indentation[first]
    assert path.plastic_fraction[down] == 0 and path.plastic_points[down] == 0
    assert path.area_fraction[down] >= path.area_fraction[first]
    assert path.permanent_max[down] == path.permanent_max[top]
    assert abs(path.indentation[again] / path.indentation[top] - 1) < 1e-6
    w = solver.permanent_displacement()
    assert np.array_equal(w, path.permanent_displacement)
    assert w.max() == path.permanent_max[-1] and w.min() >= 0
    assert path.metadata["load_path"] is True
    fresh = asperity.Solver(s, boundary=boundary, hardness=h)
    r = fresh.solve(pressure=0.01, fields=False)
    assert (r.force, r.indentation, r.area_fraction, r.iterations) == (
        path.force[0], path.indentation[0], path.area_fraction[0], path.iterations[0])
    assert fresh.stiffness() == path.stiffness[0]


def test_an_elastic_load_path_is_reversible(rough):
    """Without yielding (the hard wall, or a cap above every pressure) a path leaves no
    permanent displacement and unloading retraces loading."""
    s, _, _ = rough
    for hardness in [None, 10.0]:
        solver = asperity.Solver(s, boundary="periodic", hardness=hardness)
        path = solver.load_path(pressures=[0.01, 0.03, 0.01])
        assert np.all(path.permanent_max == 0) and not solver.permanent_displacement().any()
        assert abs(path.indentation[2] / path.indentation[0] - 1) < 1e-6


@pytest.mark.parametrize("solver_name", ["bccg", "pk"])
@pytest.mark.parametrize("boundary,flags,kwargs", [
    ("periodic", ["--pressures", "0.01,0.03,0.01,0.02,0.03"],
     dict(pressures=[0.01, 0.03, 0.01, 0.02, 0.03])),
    ("free", ["--indentations", "0.01,0.03,0.015,0.03"], dict(indentations=[0.01, 0.03, 0.015, 0.03])),
])
def test_a_load_path_equals_bem_load_path(cli, tmp_path, rough, boundary, flags, kwargs,
                                          solver_name):
    """`asperity bem --load-path` and `Solver.load_path`: every column bit for bit, the
    branches named alike, and `--fields DIR/permanent.npy` the permanent displacement."""
    s, path, h = rough
    cli("bem", "--surface", path, "--boundary", boundary, *flags, "--hardness", h,
        "--load-path", "--solver", solver_name, "--fields", tmp_path / "f",
        "--out", tmp_path / "path.csv", "--quiet")
    with open(tmp_path / "path.csv", newline="") as fh:
        import csv
        rows = list(csv.DictReader(fh))
    record = json.loads((tmp_path / "path.csv.json").read_text())
    assert record["hardness"] == h and record["command"] == "asperity bem --load-path"
    solver = asperity.Solver(np.load(path), 2.0, boundary=boundary, solver=solver_name,
                             hardness=h)
    ours = solver.load_path(**kwargs)
    assert list(ours.branch) == [r["branch"] for r in rows]
    for name in record["columns"][1:]:
        assert ours[name].tolist() == [float(r[name]) for r in rows], name
    assert "unloading" in list(ours.branch) and max(ours.plastic_fraction) > 0
    assert np.array_equal(ours.permanent_displacement, np.load(tmp_path / "f" / "permanent.npy"))


def test_a_load_path_refuses_what_it_cannot_carry_alike(cli, rough):
    s, path, h = rough
    theirs = cli("bem", "--surface", path, "--size", 2, "--pressures", f"0.01,{h}",
                 "--hardness", h, "--load-path", ok=False)
    from conftest import cli_error
    from test_rules import in_keywords
    with pytest.raises(ValueError) as refused:
        asperity.Solver(s, hardness=h).load_path(pressures=[0.01, h])
    assert str(refused.value) == in_keywords(cli_error(theirs))
    assert "is at or above the hardness" in str(refused.value)
    theirs = cli("bem", "--surface", path, "--pressures", "0.01", "--load-path",
                 "--fd-stiffness", ok=False)
    assert cli_error(theirs).startswith("--load-path does not go with --fd-stiffness")
