"""Python gives the CLI's numbers bit for bit: same seed → the same .npy heights and
sidecar, same surface → the same solve, sweep, fields, stats, PSD and MDR curves.

Both call the same library functions in the same order; these tests compare every value
exactly (`==` on floats, `array_equal` on arrays). The CLI writes floats with Rust's
shortest round-trip formatting, which Python's float() reads back exactly."""

import csv
import json

import numpy as np
import pytest

import asperity


def read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    columns = {}
    for name in rows[0]:
        columns[name] = [float(r[name]) if r[name] != "" else None for r in rows]
    return columns


SURFACES = [
    # CLI options, Python keywords
    (["--n", 64, "--m", 32, "--hurst", 0.7, "--rolloff", 3, "--short-cutoff", 20,
      "--rms-slope", 0.5, "--size", 2, "--seed", 5],
     dict(n=64, m=32, hurst=0.7, rolloff=3, short_cutoff=20, rms_slope=0.5, size=2, seed=5)),
    (["--n", 48, "--hurst", -0.5, "--cutoff", 2, "--rms-height", 1e-3, "--seed", 11],
     dict(n=48, hurst=-0.5, cutoff=2, rms_height=1e-3, seed=11)),
    (["--n", 32, "--hurst", 2.5, "--seed", 0], dict(n=32, hurst=2.5)),
]


@pytest.mark.parametrize("flags,kwargs", SURFACES)
def test_surface_heights_and_sidecar_equal_the_cli(cli, tmp_path, flags, kwargs):
    cli("surface", *flags, "--out", tmp_path / "s.npy")
    ours = asperity.surface(**kwargs)
    theirs = np.load(tmp_path / "s.npy")
    assert ours.heights.dtype == np.float64 and ours.heights.shape == theirs.shape
    assert ours.heights.tobytes() == theirs.tobytes()
    assert ours.metadata == json.loads((tmp_path / "s.npy.json").read_text())
    # And what Python saves is what the CLI wrote, byte for byte.
    ours.save(tmp_path / "p.npy")
    assert (tmp_path / "p.npy").read_bytes() == (tmp_path / "s.npy").read_bytes()
    assert json.loads((tmp_path / "p.npy.json").read_text()) == ours.metadata


def test_line_equals_the_cli(cli, tmp_path):
    cli("line", "--n", 4096, "--hurst", 0.5, "--rolloff", 4, "--rms-slope", 3, "--size", 5,
        "--seed", 3, "--out", tmp_path / "l.npy")
    ours = asperity.line(4096, hurst=0.5, rolloff=4, rms_slope=3, size=5, seed=3)
    assert ours.heights.tobytes() == np.load(tmp_path / "l.npy").tobytes()
    assert ours.metadata == json.loads((tmp_path / "l.npy.json").read_text())


def test_stats_and_psd_equal_the_cli(cli, tmp_path):
    s = asperity.surface(64, hurst=0.8, rolloff=2, seed=4, size=3)
    s.save(tmp_path / "s.npy")
    report = json.loads(cli("stats", tmp_path / "s.npy", "--json", "--psd", tmp_path / "psd.csv").stdout)
    ours = asperity.stats(s)
    assert {k: ours[k] for k in report["stats"]} == report["stats"]
    # The default fit range is one rule (it was 1 in Python, 2 in the CLI).
    for key in ("psd_slope", "psd_slope_low", "psd_slope_high", "fit_from", "fit_to",
                "fit_note", "hurst_estimate", "iso"):
        assert ours[key] == report[key], key
    table = read_csv(tmp_path / "psd.csv")
    assert asperity.psd(s).fit["exponent"] == report["psd_slope"]
    spectrum = asperity.psd(s, fit_from=report["fit_from"], fit_to=report["fit_to"])
    assert spectrum.q.tolist() == table["q"]
    assert spectrum.psd.tolist() == table["psd"]
    assert spectrum.wavenumber.tolist() == table["q_l_2pi"]
    assert spectrum.fit["exponent"] == report["psd_slope"]
    assert spectrum.hurst == report["hurst_estimate"]
    line = asperity.line(1024, hurst=0.3, seed=2)
    line.save(tmp_path / "l.npy")
    report = json.loads(cli("stats", tmp_path / "l.npy", "--json").stdout)
    ours = asperity.stats(line)
    assert {k: ours[k] for k in report["stats"]} == report["stats"]
    assert (ours["psd_slope"], ours["fit_from"]) == (report["psd_slope"], report["fit_from"])
    # A spec's roll-off above 2 sets the lower end, in both front ends.
    knee = asperity.surface(64, hurst=0.8, rolloff=6, seed=4)
    knee.save(tmp_path / "k.npy")
    report = json.loads(cli("stats", tmp_path / "k.npy", "--json").stdout)
    assert asperity.stats(knee)["fit_from"] == report["fit_from"] == 6
    assert asperity.psd(knee).fit["exponent"] == report["psd_slope"]


BEM_CASES = [
    ("free", ["--pressures", "0.003,0.01,0.03"], dict(pressures=[0.003, 0.01, 0.03])),
    ("periodic", ["--forces", "0.02,0.005"], dict(forces=[0.02, 0.005])),
    ("free", ["--indentations", "0,0.01,0.02"], dict(indentations=[0, 0.01, 0.02])),
    ("periodic", ["--indentations", "0.005,0.01"], dict(indentations=[0.005, 0.01])),
    ("free", ["--nloads", 4, "--pmin", 1e-3, "--pmax", 3e-2], dict(nloads=4, pmin=1e-3, pmax=3e-2)),
]


@pytest.mark.parametrize("solver_name", ["bccg", "pk"])
@pytest.mark.parametrize("boundary,flags,kwargs", BEM_CASES)
def test_bem_sweep_and_fields_equal_the_cli(cli, tmp_path, boundary, flags, kwargs, solver_name):
    s = asperity.surface(48, m=40, hurst=0.8, rolloff=3, rms_slope=0.5, seed=7, size=2.0)
    s.save(tmp_path / "s.npy")
    cli("bem", "--surface", tmp_path / "s.npy", "--boundary", boundary, *flags, "--fd-stiffness",
        "--tol", 1e-9, "--solver", solver_name, "--fields", tmp_path / "fields",
        "--out", tmp_path / "out.csv", "--quiet")
    table = read_csv(tmp_path / "out.csv")
    # The surface as a plain array with its size, as a user would load it.
    solver = asperity.Solver(np.load(tmp_path / "s.npy"), 2.0, boundary=boundary, tolerance=1e-9,
                             solver=solver_name)
    assert solver.solver == solver_name
    sweep = solver.sweep(**kwargs, fd_stiffness=True, fields=True)
    for name in ("force", "mean_pressure", "indentation", "area_fraction", "stiffness",
                 "iterations", "residual"):
        assert sweep[name].tolist() == table[name], name
    fd = [None if np.isnan(v) else v for v in sweep.stiffness_fd]
    assert fd == table["stiffness_fd"]
    for k in range(len(sweep)):
        assert np.array_equal(sweep.pressure[k], np.load(tmp_path / "fields" / f"pressure_{k}.npy"))
        assert np.array_equal(sweep.gap[k], np.load(tmp_path / "fields" / f"gap_{k}.npy"))


# The CLI's default solver (no --solver) against Python's default and both explicit names.
@pytest.mark.parametrize("flags,kwargs", [
    ([], {}), (["--solver", "bccg"], dict(solver="default")), (["--solver", "pk"], dict(solver="pk")),
])
@pytest.mark.parametrize("boundary", ["free", "periodic"])
def test_a_single_solve_equals_the_cli(cli, tmp_path, boundary, flags, kwargs):
    s = asperity.surface(64, hurst=0.6, rolloff=4, rms_slope=1.0, seed=2)
    s.save(tmp_path / "s.npy")
    cli("bem", "--surface", tmp_path / "s.npy", "--boundary", boundary, "--forces", 0.02,
        *flags, "--fields", tmp_path / "f", "--out", tmp_path / "out.csv", "--quiet")
    row = read_csv(tmp_path / "out.csv")
    solver = asperity.Solver(s, boundary=boundary, **kwargs)
    r = solver.solve(force=0.02)
    assert [r.force] == row["force"] and [r.indentation] == row["indentation"]
    assert [r.area_fraction] == row["area_fraction"] and [r.iterations] == row["iterations"]
    assert [r.residual] == row["residual"]
    assert [solver.stiffness()] == row["stiffness"]
    assert np.array_equal(r.pressure, np.load(tmp_path / "f" / "pressure_0.npy"))
    assert np.array_equal(r.gap, np.load(tmp_path / "f" / "gap_0.npy"))
    # The displacement is the gap's: g = u + f − d, except that the solver sets g = 0
    # exactly on the contact set, where u + f − d is zero only to the tolerance (rms
    # violation 1e-8 h_rms; pointwise a few times that, hence 100x).
    f = s.heights.max() - s.heights
    if boundary == "free":
        atol = 100 * solver.tolerance * np.std(s.heights)
        assert np.allclose(r.gap, r.displacement + f - r.indentation, rtol=0, atol=atol)


MDR_CASES = [
    (["--nloads", 30], dict(nloads=30)),
    (["--breakpoints"], dict(breakpoints=True)),
    (["--spring", "fractal", "--hurst", 0.5, "--nloads", 20, "--dmin", 1e-6],
     dict(spring="fractal", hurst=0.5, nloads=20, dmin=1e-6)),
    (["--spring", "hertz", "--asperity-radius", 0.01, "--indentations", "0,1e-3,0.5"],
     dict(spring="hertz", asperity_radius=0.01, indentations=[0, 1e-3, 0.5])),
]


@pytest.mark.parametrize("flags,kwargs", MDR_CASES)
def test_mdr_on_a_line_equals_the_cli(cli, tmp_path, flags, kwargs):
    line = asperity.line(2048, hurst=0.5, seed=9, size=3.0)
    line.save(tmp_path / "l.npy")
    cli("mdr", "--line", tmp_path / "l.npy", *flags, "--out", tmp_path / "c.csv")
    table = read_csv(tmp_path / "c.csv")
    curve = asperity.mdr(line=line, **kwargs)
    for name in ("indentation", "force", "stiffness", "contacts"):
        assert getattr(curve, name).tolist() == table[name], name


@pytest.mark.parametrize("flags,kwargs", [
    (["--profile", "hertz", "--radius", 1, "--n", 2001, "--dx", 0.01, "--spring", "hertz",
      "--indentations", "1e-8,1e-6,1e-4"],
     dict(profile="hertz", radius=1, n=2001, dx=0.01, spring="hertz", indentations=[1e-8, 1e-6, 1e-4])),
    (["--profile", "cone", "--slope", 0.2, "--n", 401, "--dx", 1e-3, "--nloads", 20],
     dict(profile="cone", slope=0.2, n=401, dx=1e-3, nloads=20)),
    (["--profile", "power", "--coefficient", 2, "--exponent", 3, "--n", 301, "--dx", 1e-2,
      "--spring", "fractal", "--hurst", 0.8, "--rms-height", 1e-3, "--nloads", 10],
     dict(profile="power", coefficient=2, exponent=3, n=301, dx=1e-2, spring="fractal",
          hurst=0.8, rms_height=1e-3, nloads=10)),
])
def test_mdr_on_profiles_equals_the_cli(cli, tmp_path, flags, kwargs):
    cli("mdr", *flags, "--out", tmp_path / "c.csv")
    table = read_csv(tmp_path / "c.csv")
    curve = asperity.mdr(**kwargs)
    for name in ("indentation", "force", "stiffness", "contacts"):
        assert getattr(curve, name).tolist() == table[name], name


def test_mdr_on_a_radial_profile_equals_the_cli(cli, tmp_path):
    r = np.arange(200) * 1e-2
    np.save(tmp_path / "tip.npy", r**2 / 2)
    cli("mdr", "--radial", tmp_path / "tip.npy", "--radial-step", 1e-2, "--n", 101, "--dx", 1e-2,
        "--nloads", 10, "--out", tmp_path / "c.csv")
    table = read_csv(tmp_path / "c.csv")
    curve = asperity.mdr(radial=r**2 / 2, radial_step=1e-2, n=101, dx=1e-2, nloads=10)
    assert curve.force.tolist() == table["force"]
    assert curve.stiffness.tolist() == table["stiffness"]


@pytest.mark.parametrize("flags,kwargs", [
    (["--pressures", "0.001,0.01,0.05"], dict(pressures=[0.001, 0.01, 0.05])),
    (["--nloads", 5, "--pmin", 1e-4, "--pmax", 0.1, "--gamma", 0.6, "--kappa", 2,
      "--modulus", 3], dict(nloads=5, pmin=1e-4, pmax=0.1, gamma=0.6, kappa=2, modulus=3)),
])
def test_persson_equals_the_cli(cli, tmp_path, flags, kwargs):
    s = asperity.surface(64, hurst=0.8, rolloff=4, rms_slope=1.0, seed=2, size=2)
    s.save(tmp_path / "s.npy")
    cli("persson", tmp_path / "s.npy", *flags, "--out", tmp_path / "p.csv")
    theirs = read_csv(tmp_path / "p.csv")
    ours = asperity.persson(s, **kwargs)
    assert list(theirs) == ["pressure", "area_fraction", "mean_gap", "stiffness_per_area",
                            "contact_stiffness"]
    for name, values in theirs.items():
        assert getattr(ours, name).tolist() == values, name
    # The same table from the heights with their size, and refusals in Python's words.
    again = asperity.persson(s.heights, size=2, **kwargs)
    assert again.mean_gap.tobytes() == ours.mean_gap.tobytes()
    with pytest.raises(ValueError, match=r"pressures: 0 is not allowed \(values must be finite"):
        asperity.persson(s, [0.0])
    with pytest.raises(ValueError, match=r"pmax \(0.1\) must not be smaller than pmin \(1\)"):
        asperity.persson(s, nloads=3, pmin=1.0, pmax=0.1)
    with pytest.raises(ValueError, match="gamma"):
        asperity.persson(s, [0.01], gamma=0.0)


@pytest.mark.parametrize("boundary", ["periodic", "free"])
def test_bem_persson_columns_equal_the_cli(cli, tmp_path, boundary):
    s = asperity.surface(64, hurst=0.8, rolloff=4, rms_slope=0.5, seed=3, size=2)
    s.save(tmp_path / "s.npy")
    cli("bem", "--surface", tmp_path / "s.npy", "--pressures", "0.005,0.02,0.08", "--boundary",
        boundary, "--modulus", 2, "--persson", "--gamma", 0.4, "--kappa", 2, "--quiet",
        "--out", tmp_path / "c.csv")
    theirs = read_csv(tmp_path / "c.csv")
    solver = asperity.Solver(s.heights, size=2, modulus=2, boundary=boundary)
    ours = solver.sweep(pressures=[0.005, 0.02, 0.08], persson=True, gamma=0.4, kappa=2)
    names = ["mean_gap", "area_fraction_persson", "mean_gap_persson", "stiffness_persson"]
    assert list(theirs)[-4:] == names
    for name, values in theirs.items():
        assert ours[name].tolist() == values, name
    assert ours.metadata["persson"] == {"gamma": 0.4, "kappa": 2.0}
    # The theory beside the sweep is asperity.persson's of the same surface (to the rounding
    # of the profile max(h) − h whose PSD the sweep takes).
    theory = asperity.persson(s, [0.005, 0.02, 0.08], modulus=2, gamma=0.4, kappa=2)
    assert np.allclose(ours.mean_gap_persson, theory.mean_gap, rtol=1e-12, atol=0)
    assert np.allclose(ours.stiffness_persson, theory.contact_stiffness, rtol=1e-12, atol=0)
    plain = asperity.Solver(s.heights, size=2, modulus=2, boundary=boundary).sweep(
        pressures=[0.005, 0.02, 0.08])
    assert "mean_gap" not in plain.columns
    with pytest.raises(ValueError, match="gamma goes with persson"):
        solver.sweep(pressures=[0.01], gamma=0.4)
    with pytest.raises(ValueError, match=r"γ must lie in \(0, 1\]"):
        solver.sweep(pressures=[0.01], persson=True, gamma=1.5)


@pytest.mark.parametrize("tangential", [False, True])
def test_bem_timing_columns_are_the_cli_s(cli, tmp_path, tangential):
    # `Solver.sweep(timing=True)` adds `asperity bem --timing`'s columns, in its order; the
    # times and memory are the process's own (so only their names, finiteness and sign are
    # compared), every other column equals the CLI's bit for bit.
    s = asperity.surface(48, hurst=0.8, rolloff=4, rms_slope=0.5, seed=2)
    s.save(tmp_path / "s.npy")
    extra = ["--poisson", 0.3] if tangential else []
    cli("bem", "--surface", tmp_path / "s.npy", "--pressures", "0.005,0.02", "--timing",
        *extra, "--quiet", "--out", tmp_path / "t.csv")
    theirs = read_csv(tmp_path / "t.csv")
    timed = ["solve_seconds", "stiffness_seconds", "peak_rss_mib"]
    timed += ["tangential_seconds"] if tangential else []
    kwargs = dict(poisson=0.3) if tangential else {}
    ours = asperity.Solver(s).sweep(pressures=[0.005, 0.02], timing=True, **kwargs)
    assert [c for c in ours.columns if c in theirs] == list(theirs)
    assert list(theirs)[-len(timed):] == timed
    for name, values in theirs.items():
        if name in timed:
            assert np.isfinite(ours[name]).all() and (ours[name] >= 0).all(), name
            assert (ours[name] > 0).any(), name
        else:
            assert ours[name].tolist() == values, name
    plain = asperity.Solver(s).sweep(pressures=[0.005, 0.02], **kwargs)
    assert not set(timed) & set(plain.columns)


def test_bem_adhesion_equals_the_cli(cli, tmp_path):
    x = (np.arange(40) - 20) * 5e-3
    h = -(x[:, None]**2 + x[None, :]**2) / 2
    np.save(tmp_path / "sphere.npy", h)
    path = [0.002, 0.004, 0.006, 0.008, 0.004]
    cli("bem", "--surface", tmp_path / "sphere.npy", "--size", 0.2, "--work-of-adhesion", 2e-4,
        "--indentations", ",".join(map(str, path)), "--retract-step", 1e-4,
        "--out", tmp_path / "a.csv")
    with open(tmp_path / "a.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    ours = asperity.bem_adhesion(h, size=0.2, work_of_adhesion=2e-4, indentations=path,
                                 retract_step=1e-4)
    assert ours.branch == [r["branch"] for r in rows]
    for name in ["indentation", "force", "mean_pressure", "area_fraction", "tensile_fraction"]:
        assert getattr(ours, name).tolist() == [float(r[name]) for r in rows], name
    for name in ["rounds", "cg_iterations"]:
        assert getattr(ours, name).tolist() == [int(r[name]) for r in rows], name
    record = json.load(open(tmp_path / "a.csv.json"))
    assert record["adhesion"]["pull_off"]["force_controlled"]["force"] == \
        ours.pull_off["force_controlled"]["force"]
    assert ours.pull_off["force_controlled"]["force"] < 0
    # Refusals in Python's words.
    with pytest.raises(ValueError, match="invalid work_of_adhesion"):
        asperity.bem_adhesion(h, size=0.2, work_of_adhesion=-1.0, indentations=path)
    with pytest.raises(ValueError, match="never press the surface"):
        asperity.bem_adhesion(h, size=0.2, work_of_adhesion=1e-3, indentations=[-0.01])


def test_bem_cohesive_zone_equals_the_cli(cli, tmp_path):
    # The Maugis–Dugdale cohesive zone (--adhesion-range / adhesion_range): same numbers.
    x = (np.arange(40) - 20) * 5e-3
    h = -(x[:, None]**2 + x[None, :]**2) / 2
    np.save(tmp_path / "sphere.npy", h)
    path = [-1e-3, 0.002, 0.004, 0.006, 0.008, 0.004]
    cli("bem", "--surface", tmp_path / "sphere.npy", "--size", 0.2, "--work-of-adhesion", 2e-4,
        "--adhesion-range", 2e-3, "--indentations", ",".join(map(str, path)),
        "--retract-step", 1e-4, "--out", tmp_path / "md.csv")
    with open(tmp_path / "md.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    ours = asperity.bem_adhesion(h, size=0.2, work_of_adhesion=2e-4, indentations=path,
                                 retract_step=1e-4, adhesion_range=2e-3)
    assert ours.branch == [r["branch"] for r in rows]
    for name in ["indentation", "force", "tensile_fraction"]:
        assert getattr(ours, name).tolist() == [float(r[name]) for r in rows], name
    # Within the range before touching: attracted.
    assert ours.force[0] < 0
    record = json.load(open(tmp_path / "md.csv.json"))
    assert record["adhesion"]["model"] == "Maugis–Dugdale cohesive zone"
    assert record["adhesion"]["pull_off"]["force_controlled"]["force"] == \
        ours.pull_off["force_controlled"]["force"]
    with pytest.raises(ValueError, match="invalid adhesion_range"):
        asperity.bem_adhesion(h, size=0.2, work_of_adhesion=2e-4, indentations=path,
                              adhesion_range=0.0)
    with pytest.raises(ValueError, match="spans no pixel"):
        asperity.bem_adhesion(h, size=0.2, work_of_adhesion=2e-4, indentations=path,
                              adhesion_range=1e-9)


def test_bem_exponential_potential_equals_the_cli(cli, tmp_path):
    # The exponential potential (--adhesion-model exponential / adhesion_model): same numbers.
    x = (np.arange(40) - 20) * 5e-3
    h = -(x[:, None]**2 + x[None, :]**2) / 2
    np.save(tmp_path / "sphere.npy", h)
    path = [0.002, 0.004, 0.008, 0.004]
    rho = 2e-4 ** (2 / 3)
    cli("bem", "--surface", tmp_path / "sphere.npy", "--size", 0.2, "--work-of-adhesion", 2e-4,
        "--adhesion-range", rho, "--adhesion-model", "exponential",
        "--indentations", ",".join(map(str, path)), "--retract-step", 2e-4,
        "--out", tmp_path / "exp.csv")
    with open(tmp_path / "exp.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    ours = asperity.bem_adhesion(h, size=0.2, work_of_adhesion=2e-4, indentations=path,
                                 retract_step=2e-4, adhesion_range=rho,
                                 adhesion_model="exponential")
    assert ours.branch == [r["branch"] for r in rows]
    for name in ["indentation", "force", "tensile_fraction"]:
        assert getattr(ours, name).tolist() == [float(r[name]) for r in rows], name
    for name in ["rounds", "cg_iterations"]:
        assert getattr(ours, name).tolist() == [int(r[name]) for r in rows], name
    record = json.load(open(tmp_path / "exp.csv.json"))
    assert record["adhesion"]["model"] == "exponential potential"
    assert record["adhesion"]["pull_off"]["force_controlled"]["force"] == \
        ours.pull_off["force_controlled"]["force"]
    assert ours.pull_off["force_controlled"]["force"] < 0
    with pytest.raises(ValueError, match="adhesion_model needs adhesion_range"):
        asperity.bem_adhesion(h, size=0.2, work_of_adhesion=2e-4, indentations=path,
                              adhesion_model="exponential")
    with pytest.raises(ValueError, match="invalid adhesion_model"):
        asperity.bem_adhesion(h, size=0.2, work_of_adhesion=2e-4, indentations=path,
                              adhesion_range=rho, adhesion_model="lennard-jones")


def test_contact_adhesion_equals_the_cli(cli, tmp_path):
    # asperity contact --work-of-adhesion (SI units) and contact(work_of_adhesion=...): the
    # same request, run and numbers, bit for bit; the loop's figure is one definition
    # (the CLI's --plot FILE.json series are Python's adhesion_loop's).
    from asperity import _asperity

    x = (np.arange(40) - 20) * 5e-7                      # 0.5 µm pixels
    h = -(x[:, None]**2 + x[None, :]**2) / (2 * 1e-4)   # a sphere R = 0.1 mm, in m
    np.save(tmp_path / "sphere.npy", h)
    path = [2e-8, 4e-8, 8e-8, 4e-8]
    w, rho, e_star = 0.05, 1e-8, 1e9                     # zone resolution 4.2
    cli("contact", tmp_path / "sphere.npy", "--size", 2e-5, "--detrend", "none",
        "--modulus", e_star, "--work-of-adhesion", w, "--adhesion-range", rho,
        "--adhesion-model", "exponential", "--indentations", ",".join(map(str, path)),
        "--retract-step", 2e-9, "--out", tmp_path / "c.csv", "--plot", tmp_path / "c.json")
    with open(tmp_path / "c.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    ours = asperity.contact(h, size=2e-5, modulus=e_star, work_of_adhesion=w,
                            adhesion_range=rho, adhesion_model="exponential",
                            indentations=path, retract_step=2e-9)
    assert ours.branch == [r["branch"] for r in rows]
    for name in ["indentation_m", "force_n", "mean_pressure_pa", "contact_area_m2",
                 "area_fraction", "tensile_fraction"]:
        assert ours[name].tolist() == [float(r[name]) for r in rows], name
    for name in ["rounds", "cg_iterations"]:
        assert ours[name].tolist() == [int(r[name]) for r in rows], name
    assert min(ours["rounds"]) >= 1  # the retraction's rows count their solves too
    record = json.load(open(tmp_path / "c.csv.json"))
    pull = record["adhesion"]["pull_off"]["force_controlled"]
    assert pull["force_n"] == ours.metadata["pull_off"]["force_controlled"]["force"] < 0
    assert record["adhesion"]["work_of_adhesion_j_per_m2"] == w
    drawn = json.load(open(tmp_path / "c.json"))["charts"][0]
    pulls = ours.metadata["pull_off"]
    mark = tuple((p["indentation"], p["force"]) for p in
                 (pulls["force_controlled"], pulls["displacement_controlled"]))
    python = json.loads(_asperity.adhesion_loop_figure(
        ours["indentation_m"].tolist(), ours["force_n"].tolist(),
        [b == "retract" for b in ours.branch], mark, "t", "x", "y", " N"))["charts"][0]
    assert python["series"] == drawn["series"]
    assert [s["style"] for s in drawn["series"]].count("arrows") == 2
    # asperity.plot.adhesion_loop draws that chart: its labels, and each line series' points.
    pytest.importorskip("matplotlib").use("Agg")
    from asperity import plot

    ax = plot.adhesion_loop(ours)
    assert (ax.get_xlabel(), ax.get_ylabel()) == (drawn["x_label"], drawn["y_label"])
    lines = [np.asarray(line.get_xydata()) for line in ax.lines]
    for series in drawn["series"]:
        if series["style"] == "line" and len(series["points"]) > 1:
            assert any(np.array_equal(xy, np.array(series["points"])) for xy in lines)
    # Refusals in Python's words, the CLI's rules.
    with pytest.raises(ValueError, match="does not go with pressures"):
        asperity.contact(h, size=2e-5, modulus=e_star, work_of_adhesion=w,
                         indentations=path, pressures=[1e6])
    with pytest.raises(ValueError, match="adhesion_range needs work_of_adhesion"):
        asperity.contact(h, size=2e-5, modulus=e_star, pressures=[1e6], adhesion_range=rho)
    # What an adhesive run cannot carry, in the front-end layer's words for both.
    refused = cli("contact", tmp_path / "sphere.npy", "--size", 2e-5, "--detrend", "none",
                  "--modulus", e_star, "--work-of-adhesion", w, "--indentations", "2e-8",
                  "--load-path", ok=False).stderr
    assert "--work-of-adhesion takes a path of --indentations (m) and does not go with " \
           "--load-path" in refused
    for extra, name in [({"load_path": True}, "load_path"), ({"map": True}, "map")]:
        with pytest.raises(ValueError, match=f"work_of_adhesion takes a path of indentations "
                                             rf"\(m\) and does not go with {name}$"):
            asperity.contact(h, size=2e-5, modulus=e_star, work_of_adhesion=w,
                             indentations=path, **extra)
