"""Reference solutions and E* from Young's modulus and Poisson's ratio: the library's
closed forms, checked against ContactMechanics' own reference solutions (the peer) and
against the BEM; E* by the CLI's one rule."""

import json
import math

import numpy as np
import pytest

import asperity
from asperity import reference

from conftest import cli_error


def test_hertz_equals_contact_mechanics():
    Hertz = pytest.importorskip("ContactMechanics.ReferenceSolutions.Hertz")
    h = reference.Hertz(radius=2.5, modulus=3.0)
    d = np.logspace(-4, -1, 7)
    np.testing.assert_allclose(h.force(d), Hertz.normal_load(d, 2.5, 3.0), rtol=1e-13)
    forces = h.force(d)
    np.testing.assert_allclose(h.indentation(forces), Hertz.penetration(forces, 2.5, 3.0),
                               rtol=1e-12)
    a, p0 = Hertz.radius_and_pressure(forces[3], 2.5, 3.0)
    assert h.contact_radius(d[3]) == pytest.approx(a, rel=1e-12)
    assert h.pressure(d[3], 0.0) == pytest.approx(p0, rel=1e-12)
    # Arrays keep their shape; a number gives a float.
    assert h.force(np.ones((2, 3))).shape == (2, 3) and isinstance(h.force(0.1), float)


def test_westergaard_equals_contact_mechanics():
    W = pytest.importorskip("ContactMechanics.ReferenceSolutions.Westergaard")
    w = reference.Westergaard(wavelength=2.0, amplitude=0.1, modulus=4.0)
    pstar = math.pi * 4.0 * 0.1 / 2.0
    assert w.full_contact_pressure() == pytest.approx(pstar, rel=1e-15)
    p = np.array([0.01, 0.3, 0.9]) * pstar
    # ContactMechanics: half-width in units of λ at p̄ in units of p*.
    np.testing.assert_allclose(w.contact_half_width(p) / 2.0, W.contact_radius(p / pstar),
                               rtol=1e-13)


def test_the_flat_punch_and_hertz_agree_with_the_bem():
    # The BEM's frozen-set stiffness of a Hertz contact is 2E*a (independent oracle: the
    # solver), within the discretisation error of a 128² grid (a ≈ 16 pixels: 3 %).
    n, size, radius = 128, 1.0, 1.0
    x = (np.arange(n) - n / 2 + 0.5) * size / n
    heights = -(x[None, :] ** 2 + x[:, None] ** 2) / (2 * radius)
    solver = asperity.Solver(heights, size, boundary="free")
    r = solver.solve(indentation=0.015)
    h = reference.Hertz(radius=radius, modulus=1.0)
    assert r.force == pytest.approx(h.force(0.015), rel=0.03)
    assert solver.stiffness() == pytest.approx(h.stiffness(0.015), rel=0.03)
    punch = reference.FlatPunch(radius=0.2, modulus=2.0)
    assert punch.stiffness() == pytest.approx(0.8) and punch.force(0.5) == pytest.approx(0.4)


def test_adhesive_and_tangential_closed_forms():
    jkr = reference.Jkr(radius=1.0, modulus=1.0, work_of_adhesion=1e-3)
    assert jkr.pull_off_force() == pytest.approx(-1.5 * math.pi * 1e-3, rel=1e-15)
    assert jkr.pull_off_force("displacement") == pytest.approx(-5 / 6 * math.pi * 1e-3)
    a = jkr.contact_radius_at_force(0.01)
    assert jkr.force(a) == pytest.approx(0.01, rel=1e-10)
    assert reference.Dmt(1.0, 1.0, 1e-3).pull_off_force() == pytest.approx(-2 * math.pi * 1e-3)
    cm = reference.CattaneoMindlin(radius=1.0, modulus=1.0, ratio=0.8, friction=0.5)
    top = 0.5 * reference.Hertz(1.0, 1.0).force(0.01)  # μF
    a = reference.Hertz(1.0, 1.0).contact_radius(0.01)
    assert cm.stick_radius(0.01, top / 2) == pytest.approx(a * 0.5 ** (1 / 3), rel=1e-13)
    assert cm.no_slip_stiffness(0.01) == pytest.approx(2 * 0.8 * a)
    # The library refuses meaningless parameters.
    with pytest.raises(ValueError, match="radius must be positive"):
        reference.Hertz(radius=-1.0, modulus=1.0)
    with pytest.raises(ValueError, match="work_of_adhesion"):
        reference.Jkr(1.0, 1.0, 0.0)
    with pytest.raises(ValueError, match="control"):
        jkr.pull_off_force("both")


def test_effective_modulus_is_the_cli_rule(cli, tmp_path):
    e_star = asperity.effective_modulus(young=210e9, poisson=0.3)
    assert e_star == 210e9 / (1 - 0.3 ** 2)
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_height=1e-6, size=1e-4, seed=1)
    a = asperity.Solver(s, young=210e9, poisson=0.3, boundary="periodic")
    b = asperity.Solver(s, modulus=e_star, boundary="periodic")
    assert a.modulus == b.modulus == e_star
    assert a.solve(pressure=1e6).force == b.solve(pressure=1e6).force
    c = asperity.contact(s, young=210e9, poisson=0.3, pressures=[1e6])
    assert c.effective_modulus == e_star
    # The same refusal in the same words (flags there, keywords here).
    s.save(tmp_path / "s.npy")
    with pytest.raises(ValueError) as error:
        asperity.Solver(s, young=210e9, poisson=0.6)
    words = cli_error(cli("contact", tmp_path / "s.npy", "--young", "210e9", "--poisson", "0.6",
                          "--pressures", "1e6", "--detrend", "none", ok=False))
    assert str(error.value) == words.replace("--", "")
    with pytest.raises(ValueError, match="give either modulus"):
        asperity.Solver(s, modulus=1.0, young=2.0, poisson=0.3)


def test_two_bodies_give_the_closed_form_e_star_in_both_front_ends(cli, tmp_path):
    # Steel on aluminium: 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂, the CLI's record and
    # Python's E* the same double; the contact itself then bit for bit the same.
    closed = 1 / ((1 - 0.3 ** 2) / 210e9 + (1 - 0.33 ** 2) / 70e9)
    e_star = asperity.effective_modulus(young=(210e9, 70e9), poisson=(0.3, 0.33))
    assert e_star == pytest.approx(closed, rel=1e-15)
    # Two equal bodies: half of one body's E/(1 − ν²).
    one = asperity.effective_modulus(young=210e9, poisson=0.3)
    both = asperity.effective_modulus(young=[210e9, 210e9], poisson=[0.3, 0.3])
    assert both == pytest.approx(one / 2, rel=1e-15)
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_height=1e-6, size=1e-4, seed=1)
    s.save(tmp_path / "s.npy")
    c = asperity.contact(s, young=(210e9, 70e9), poisson=(0.3, 0.33), pressures=[1e6, 1e7])
    assert c.effective_modulus == e_star
    assert c.metadata["contact"]["young"] == [210e9, 70e9]
    cli("contact", tmp_path / "s.npy", "--young", "210e9,70e9", "--poisson", "0.3,0.33",
        "--pressures", "1e6,1e7", "--detrend", "none", "--quiet", "--out", tmp_path / "c.csv")
    record = json.loads((tmp_path / "c.csv.json").read_text())
    assert record["effective_modulus_pa"] == e_star
    assert record["young_pa"] == [210e9, 70e9] and record["poisson"] == [0.3, 0.33]
    rows = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True)
    np.testing.assert_array_equal(rows["stiffness_n_per_m"], c.stiffness_n_per_m)
    # The Solver takes the same keywords.
    solver = asperity.Solver(s, young=(210e9, 70e9), poisson=(0.3, 0.33))
    assert solver.modulus == e_star


def test_patches_are_the_cli_count_with_their_areas(cli, tmp_path):
    s = asperity.surface(64, hurst=0.8, rolloff=4, rms_height=1e-6, size=1e-4, seed=3)
    t_path = tmp_path / "s.npy"
    s.save(t_path)
    c = asperity.contact(s, modulus=1e9, pressures=[1e6, 5e6], map=True)
    p = asperity.patches(c.map, pixel_area=(1e-4 / 64) ** 2)
    assert len(p) == c.patches[-1] > 1
    np.testing.assert_array_equal(c.patch_areas_m2, p.areas)
    assert p.areas.sum() == pytest.approx(c.contact_area_m2[-1], rel=1e-12)
    assert ((p.labels > 0) == c.map).all() and p.labels.max() == len(p)
    # The CLI's patches column at the same loads (its surface read from the saved file).
    out = tmp_path / "c.csv"
    cli("contact", t_path, "--modulus", "1e9", "--pressures", "1e6,5e6", "--detrend", "none",
        "--out", out, "--quiet")
    table = np.genfromtxt(out, delimiter=",", names=True)
    np.testing.assert_array_equal(table["patches"], c.patches)


def test_maugis_dugdale_is_the_librarys_curve_between_dmt_and_jkr():
    md = reference.MaugisDugdale(1.0)
    a = np.array([0.2, 0.5, 1.0, 2.0])
    m = md.zone_ratio(a)
    s = np.sqrt(m ** 2 - 1)
    lam = 1.0
    # Oracle: Maugis' energy balance holds at the m returned (bisected to rounding), and the
    # force and approach are its closed forms at that m (Johnson & Greenwood 1997).
    balance = (lam * a ** 2 / 2 * (s + (m ** 2 - 2) * np.arctan(s))
               + 4 * lam ** 2 * a / 3 * (s * np.arctan(s) - m + 1))
    np.testing.assert_allclose(balance, 1.0, rtol=1e-12)
    np.testing.assert_allclose(md.force(a), a ** 3 - lam * a ** 2 * (s + m ** 2 * np.arctan(s)),
                               rtol=1e-12)
    np.testing.assert_allclose(md.approach(a), a ** 2 - 4 / 3 * lam * a * s, rtol=1e-12)
    # The limits (the library's own test bounds): JKR -3/2 and -5/6, DMT -2.
    assert reference.MaugisDugdale(1e4).pull_off_force() == pytest.approx(-1.5, abs=2e-3)
    assert (reference.MaugisDugdale(1e4).pull_off_force("displacement")
            == pytest.approx(-5 / 6, abs=2e-3))
    assert reference.MaugisDugdale(1e-8).pull_off_force() == pytest.approx(-2.0, abs=1e-3)
    forces = [reference.MaugisDugdale(lam).pull_off_force() for lam in (0.1, 1.0, 10.0)]
    assert forces == sorted(forces) and -2 < forces[0] and forces[-1] < -1.5
    # The pull-off point lies on the curve.
    point = md.pull_off_radius()
    assert md.force(point) == pytest.approx(md.pull_off_force(), rel=1e-14)
    assert md.approach(point) == pytest.approx(md.pull_off_approach(), rel=1e-14)
    # Units of a sphere, closed form; its λ.
    r, e, w, sigma = 1e-3, 1e9, 0.05, 1e7
    k = 4 * e / 3
    units = reference.MaugisDugdale.scales(r, e, w, sigma)
    assert units["force"] == pytest.approx(math.pi * w * r, rel=1e-15)
    assert units["radius"] == pytest.approx((math.pi * w * r * r / k) ** (1 / 3), rel=1e-15)
    assert units["approach"] == pytest.approx((math.pi ** 2 * w * w * r / k ** 2) ** (1 / 3),
                                              rel=1e-15)
    assert units["maugis_parameter"] == pytest.approx(
        2 * sigma * (r / (math.pi * w * k * k)) ** (1 / 3), rel=1e-15)
    with pytest.raises(ValueError, match="maugis_parameter must be positive"):
        reference.MaugisDugdale(0.0)
    with pytest.raises(ValueError, match="contact_radius must be positive"):
        md.force(0.0)


def test_the_jkr_curve_the_cli_draws_is_asperity_reference_jkr(cli, tmp_path):
    """Issue 36 item 1, reference solutions: `asperity mdr --profile hertz
    --work-of-adhesion` draws JKR's equilibrium curve beside its loop (--plot FILE.json);
    its points are asperity.reference.Jkr's approach and force at the same contact radii
    (800 up to 2√(R d_max), cut at the deepest approach), bit for bit; and the pull-off
    the CLI records is within 1e-4 of Jkr's."""
    radius, w = 1.0, 1e-3
    cli("mdr", "--profile", "hertz", "--radius", radius, "--n", 1001, "--dx", 1e-3,
        "--work-of-adhesion", w, "--indentations", "0.02,0.09,0.05",
        "--out", tmp_path / "c.csv", "--plot", tmp_path / "c.json")
    charts = json.loads((tmp_path / "c.json").read_text())["charts"]
    theirs = next(s for c in charts for s in c["series"] if s["label"].startswith("JKR"))
    ours = asperity.mdr(profile="hertz", radius=radius, n=1001, dx=1e-3,
                        work_of_adhesion=w, indentations=[0.02, 0.09, 0.05])
    deepest = float(ours.indentation.max())
    a_top = 2.0 * math.sqrt(radius * deepest)
    a = np.array([a_top * i / 800.0 for i in range(1, 801)])
    jkr = reference.Jkr(radius=radius, modulus=1.0, work_of_adhesion=w)
    d, f = jkr.approach(a), jkr.force(a)
    keep = d <= deepest
    assert 100 < keep.sum() < 800
    assert theirs["points"] == [[x, y] for x, y in zip(d[keep], f[keep])]
    record = json.loads((tmp_path / "c.csv.json").read_text())
    pull = record["adhesion"]["pull_off"]["force_controlled"]["force"]
    assert abs(pull / jkr.pull_off_force("force") - 1) < 1e-4


def test_johnson_sinusoid_is_the_closed_form_with_its_pull_offs_and_thresholds():
    # The library's JohnsonSinusoid through Python against the closed form written here in
    # numpy: p̄ = p*[sin²ψ − α√tan ψ] and the approach Δr(1 − ln r) + (2λp̄ₚ/πE*) ln(1/sin ψ),
    # p̄ₚ = −√(2E*w tan ψ/λ); the pull-offs against a fine numpy scan of the same curve
    # (force control: the least p̄ on the stable branch; displacement control: p̄ at the
    # least approach); the thresholds against Johnson's closed forms of α.
    from asperity.reference import JohnsonSinusoid

    lam, amp, e, w = 1.0, 0.01, 1.0, 1.2337e-4
    j = JohnsonSinusoid(wavelength=lam, amplitude=amp, modulus=e, work_of_adhesion=w)
    alpha = np.sqrt(2 * w * lam / (np.pi**2 * e * amp**2))
    p_star = np.pi * e * amp / lam
    assert j.alpha() == pytest.approx(alpha, rel=1e-14)
    assert j.full_contact_pressure() == pytest.approx(p_star, rel=1e-14)
    a = np.linspace(1e-4, 0.4, 4000) * lam
    psi = np.pi * a / lam
    punch = -np.sqrt(2 * e * w * np.tan(psi) / lam)
    p = p_star * np.sin(psi)**2 + punch
    r = np.sin(psi)**2
    d = amp * r * (1 - np.log(r)) - 2 * lam * punch / (np.pi * e) * np.log(np.sin(psi))
    np.testing.assert_allclose(j.mean_pressure(a), p, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(j.approach(a), d, rtol=1e-12, atol=1e-15)
    least, greatest = j.stable_branch()
    stable = (a >= least) & (a <= greatest)
    assert j.pull_off_pressure("force") == pytest.approx(p[stable].min(), rel=1e-6)
    assert j.pull_off_half_width("force") == pytest.approx(a[np.argmin(p)], abs=2e-4)
    upto = a <= greatest
    k = np.argmin(d[upto])
    assert j.pull_off_half_width("displacement") == pytest.approx(a[upto][k], abs=2e-4)
    assert j.pull_off_pressure("displacement") == pytest.approx(p[upto][k], rel=1e-3)
    # Johnson's α thresholds, and beyond the first no partial contact is stable.
    assert JohnsonSinusoid.alpha_stable() == pytest.approx(
        4 * (3 / 8)**0.75 * (5 / 8)**1.25, rel=1e-14)
    assert JohnsonSinusoid.alpha_snap() == pytest.approx(0.75**0.75 / np.sqrt(2), rel=1e-14)
    sticky = JohnsonSinusoid(lam, amp, e, w * (1.1 / alpha)**2)
    assert sticky.stable_branch() is None and np.isnan(sticky.pull_off_pressure())
    with pytest.raises(ValueError, match="work_of_adhesion"):
        JohnsonSinusoid(lam, amp, e, -1.0)
