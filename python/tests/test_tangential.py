"""The tangential (no-slip) stiffness and the contact conductances as columns: Python's
``Solver.sweep`` and ``contact`` give the CLI's numbers bit for bit (one definition in the
front-end layer, crates/asperity-app/src/derived.rs), with Mindlin's ratio and Barber's
analogy as oracles (docs/tangential.md)."""

import os

import numpy as np

import asperity

MINDLIN = 2 * (1 - 0.3) / (2 - 0.3)


def test_bem_sweep_columns_are_the_clis(cli, tmp_path):
    s = asperity.surface(64, hurst=0.8, rolloff=4, rms_slope=0.5, seed=3)
    np.save(tmp_path / "s.npy", s.heights)
    cli("bem", "--surface", tmp_path / "s.npy", "--pressures", "0.005,0.02,0.08", "--poisson", 0.3,
        "--resistivity", "2,3", "--thermal-conductivity", "4,12", "--modulus", 2,
        "--out", tmp_path / "c.csv", "--quiet")
    theirs = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True)
    solver = asperity.Solver(s.heights, size=1.0, modulus=2)
    ours = solver.sweep(pressures=[0.005, 0.02, 0.08], poisson=0.3, resistivity=[2, 3],
                        thermal_conductivity=[4, 12])
    names = ["stiffness", "stiffness_x", "stiffness_y", "tangential_ratio",
             "electrical_conductance", "thermal_conductance"]
    for name in names:
        assert np.array_equal(ours[name], theirs[name]), name
    k = ours.stiffness
    assert np.array_equal(ours.tangential_ratio, (ours.stiffness_x + ours.stiffness_y) / (2 * k))
    assert np.allclose(ours.tangential_ratio, MINDLIN, rtol=1e-2)
    # Barber: 2k/(E*(ρ₁+ρ₂)) and (2k/E*)·κ₁κ₂/(κ₁+κ₂), E* = 2.
    assert np.allclose(ours.electrical_conductance, 2 * k / (2 * 5), rtol=1e-15, atol=0)
    assert np.allclose(ours.thermal_conductance, 2 * k / 2 * 3, rtol=1e-15, atol=0)
    assert ours.metadata["poisson"] == 0.3
    # Without them: no such columns, the others unchanged bit for bit.
    plain = asperity.Solver(s.heights, size=1.0, modulus=2).sweep(pressures=[0.005, 0.02, 0.08])
    assert "stiffness_x" not in plain.columns
    for name in ["force", "indentation", "area_fraction", "stiffness"]:
        assert np.array_equal(plain[name], ours[name]), name


def test_one_direction_is_the_clis_and_the_both_runs(cli, tmp_path):
    # tangential="x": only stiffness_x, the ratio k_x/k; the CLI's numbers bit for bit, and
    # the both run's k_x bit for bit (the same start and CG). "y" starts elsewhere (Mindlin
    # times the normal solution, not 2w - k_x's): the both run's k_y to the CG's stopping
    # energy error (1e-12 relative).
    s = asperity.surface(64, hurst=0.8, rolloff=4, rms_slope=0.5, seed=3)
    np.save(tmp_path / "s.npy", s.heights)
    loads = [0.005, 0.02, 0.08]
    cli("bem", "--surface", tmp_path / "s.npy", "--pressures", "0.005,0.02,0.08", "--poisson", 0.3,
        "--tangential", "x", "--out", tmp_path / "x.csv", "--quiet")
    theirs = np.genfromtxt(tmp_path / "x.csv", delimiter=",", names=True)
    sweep = lambda **kw: asperity.Solver(s.heights, size=1.0).sweep(pressures=loads, poisson=0.3,
                                                                    **kw)
    ours, both, y = sweep(tangential="x"), sweep(), sweep(tangential="y")
    assert "stiffness_y" not in ours.columns and "stiffness_y" not in theirs.dtype.names
    for name in ["stiffness", "stiffness_x", "tangential_ratio"]:
        assert np.array_equal(ours[name], theirs[name]), name
    assert np.array_equal(ours.stiffness_x, both.stiffness_x)
    assert np.array_equal(ours.tangential_ratio, ours.stiffness_x / ours.stiffness)
    assert "stiffness_x" not in y.columns
    np.testing.assert_allclose(y.stiffness_y, both.stiffness_y, rtol=1e-11, atol=0)
    assert ours.metadata["tangential"] == "x"
    # contact: tangential="x" is --tangential=x, cell for cell.
    t = asperity.surface(48, hurst=0.8, rolloff=2, rms_slope=1, seed=3, size=1e-4)
    np.save(tmp_path / "h.npy", t.heights * 1e-6)
    cli("import", tmp_path / "h.npy", "--size", "1e-4", "--detrend", "none",
        "--out", tmp_path / "t.npy")
    cli("contact", tmp_path / "t.npy", "--young", 2e11, "--poisson", 0.3, "--tangential=x",
        "--pressures", "1e4,1e5", "--detrend", "none", "--out", tmp_path / "c.csv")
    theirs = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True)
    t = asperity.read_topography(tmp_path / "t.npy")
    ours = asperity.contact(t, young=2e11, poisson=0.3, tangential="x", pressures=[1e4, 1e5])
    assert "stiffness_y_n_per_m" not in ours.columns
    for name in ["stiffness_n_per_m", "stiffness_x_n_per_m", "tangential_ratio"]:
        assert np.array_equal(ours[name], theirs[name]), name


def test_contact_tangential_is_the_clis(cli, tmp_path):
    s = asperity.surface(48, hurst=0.8, rolloff=2, rms_slope=1, seed=3, size=1e-4)
    np.save(tmp_path / "h.npy", s.heights * 1e-6)
    cli("import", tmp_path / "h.npy", "--size", "1e-4", "--detrend", "none",
        "--out", tmp_path / "t.npy")
    cli("contact", tmp_path / "t.npy", "--young", 2e11 * 0.91, "--poisson", 0.3, "--tangential",
        "--pressures", "1e4,1e5", "--resistivity", "1.7e-8,1.7e-8", "--detrend", "none",
        "--out", tmp_path / "c.csv")
    theirs = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True)
    t = asperity.read_topography(tmp_path / "t.npy")
    ours = asperity.contact(t, young=2e11 * 0.91, poisson=0.3, tangential=True,
                            pressures=[1e4, 1e5], resistivity=[1.7e-8, 1.7e-8])
    for name in ["stiffness_n_per_m", "stiffness_x_n_per_m", "stiffness_y_n_per_m",
                 "tangential_ratio", "electrical_conductance_s"]:
        assert np.array_equal(ours[name], theirs[name]), name
    assert np.allclose(ours["tangential_ratio"], MINDLIN, rtol=1e-2)
    assert ours.metadata["contact"]["tangential"] is True


def test_study_curve_tangential_and_conductance_are_the_clis(cli, tmp_path):
    # The same study from both front ends: the same curve.csv columns, cell for cell
    # (one definition: asperity_app::study::rows), the ratio at least Mindlin's (an exact
    # bound, docs/tangential.md) and the conductance the stiffness times 2/(E*(ρ₁+ρ₂)).
    args = dict(method="bem", n=32, hurst=[0.5], samples=2, rolloff=4, levels=4)
    cli("study", "curve", "--method", "bem", "--n", 32, "--hurst", 0.5, "--samples", 2,
        "--rolloff", 4, "--levels", 4, "--poisson", 0.3, "--resistivity", "1,3", "--quiet",
        "--out", tmp_path / "cli")
    theirs = np.genfromtxt(tmp_path / "cli" / "curve.csv", delimiter=",", names=True)
    ours = asperity.study_curve(out=tmp_path / "py", poisson=0.3, resistivity=[1, 3], **args)
    for name in ["stiffness", "tangential_ratio", "tangential_ratio_low",
                 "tangential_ratio_high", "electrical_conductance",
                 "electrical_conductance_high"]:
        assert np.array_equal(ours[name], theirs[name]), name
    assert np.all(ours.tangential_ratio >= MINDLIN * (1 - 1e-9))
    assert np.allclose(ours.tangential_ratio, MINDLIN, rtol=1e-2)
    assert np.array_equal(ours.electrical_conductance, ours.stiffness * 2 / 4)
    charts = ours.figures["tangential"]["charts"]
    assert len(charts) == 2 and "Mindlin" in charts[0]["series"][-1]["label"]
    # Bad values are refused in the keywords' words, creating nothing.
    mdr = "poisson applies to BEM studies only (method=\"bem\"): an MDR line has no tangential"
    for bad, words in [(dict(poisson=0.7), "poisson must be in [0, 0.5]"),
                       (dict(resistivity=[1]), "give two values"),
                       (dict(method="mdr", poisson=0.3), mdr)]:
        try:
            asperity.study_curve(out=tmp_path / "bad", **{**args, **bad})
        except ValueError as e:
            assert words in str(e), str(e)
        else:
            raise AssertionError(f"{bad} accepted")
        assert not (tmp_path / "bad").exists()


def test_the_distributed_coordinator_carries_poisson_and_the_resistivities(tmp_path):
    # The coordinator and sample computer that a study under mpirun drives (_mpi.py),
    # driven here by hand on one rank: Poisson's ratio reaches the ranks in the spec they
    # are sent, and the records are the serial run's, tangential and conductance columns
    # included, with the same checkpoints byte for byte (tests/mpi/run.sh runs the same
    # under mpirun).
    import filecmp
    import json

    from asperity import _asperity as core

    def args(out):
        request = dict(kind="curve", method="bem", sizes=[32], hursts=[0.5], samples=2,
                       rolloff=4.0, seed=None, min_contacts=None, max_fraction=None, levels=4,
                       full_sweep=False, poisson=0.3, tangential=None)
        return (request, str(tmp_path / out), False, None)

    derived = dict(resistivity=[1.0, 3.0])
    coordinator = core.StudyCoordinator(1, 1)
    actions, computer, sent = coordinator.begin(*args("mpi"), **derived), None, []
    while not any(action[0] == "end" for action in actions):
        (kind, rank, t, indices, spec), = actions
        assert (kind, rank) == ("assign", 0)
        if spec is not None:
            sent.append(json.loads(spec))
            computer = core.SampleComputer(spec)
        actions = coordinator.on_done(0, computer.compute(t, indices)) + coordinator.save_due()
    distributed = json.loads(coordinator.finish())
    coordinator.close()
    assert sent and all(spec["poisson"] == 0.3 for spec in sent)
    serial = json.loads(core.run_study(*args("serial"), None, **derived))
    assert distributed["curve"] == serial["curve"]
    assert distributed["figures"] == serial["figures"]
    names = [name for name, _ in distributed["curve"]["columns"]]
    assert "tangential_ratio" in names and "electrical_conductance" in names
    for name in ["study.json"] + [f"checkpoint/{f}" for f in
                                  sorted(os.listdir(tmp_path / "serial" / "checkpoint"))]:
        assert filecmp.cmp(tmp_path / "mpi" / name, tmp_path / "serial" / name, shallow=False)
