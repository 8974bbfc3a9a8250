"""The plotting helpers draw what their figure shows: the fit line is the fit, the scale
bar names its length, each patch has its colour, intervals are drawn as bands and bars."""

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import asperity  # noqa: E402
import asperity.plot  # noqa: E402


def test_surface_image_with_scale_bar(tmp_path):
    s = asperity.surface(64, m=32, hurst=0.8, size=2.0, seed=1)
    ax = asperity.plot.surface(s)
    image = ax.get_images()[0]
    assert image.get_extent() == [0, 2.0, 0, 1.0]
    np.testing.assert_array_equal(image.get_array(), s.heights)
    texts = [t.get_text() for a in ax.artists for t in a.findobj(matplotlib.text.Text)]
    assert "0.2" in texts  # a round length near a fifth of the width
    ax.figure.savefig(tmp_path / "s.png")


def test_psd_with_its_fit():
    s = asperity.surface(128, hurst=0.8, rolloff=4, seed=2)
    p = asperity.psd(s)
    ax = asperity.plot.psd(p)
    data, fit = ax.get_lines()
    np.testing.assert_array_equal(data.get_ydata(), p.psd[p.psd > 0])
    k = fit.get_xdata()
    assert np.rint(k).min() == p.fit_from and np.rint(k).max() == p.fit_to
    q = k * 2 * np.pi / s.size
    np.testing.assert_allclose(fit.get_ydata(), p.fit["prefactor"] * q ** p.fit["exponent"])
    assert "slope" in ax.get_legend().get_texts()[1].get_text()


def test_contact_map_colours_each_patch():
    contact = np.array([[1, 1, 0, 0, 1], [0, 0, 0, 0, 1], [1, 0, 1, 1, 0]], dtype=bool)
    ax = asperity.plot.contact_map(contact)
    rgb = ax.get_images()[0].get_array()
    labels = asperity.patches(contact).labels
    for label in range(1, labels.max() + 1):
        colours = {tuple(c) for c in rgb[labels == label]}
        assert len(colours) == 1  # one colour per patch
    assert (rgb[labels == 0] == 1.0).all()  # free surface white
    assert ax.get_title().startswith("contact set: 4 contact patches")


def test_curves_and_alpha_with_intervals(tmp_path):
    curve = asperity.study_curve(method="mdr", n=256, hurst=[0.5], samples=4,
                                 out=tmp_path / "curve")
    ax = asperity.plot.stiffness(curve)
    assert len(ax.collections) == 1  # the band of the 95 % interval
    # The ensemble curve and the k ∝ F reference, as `asperity study curve` draws them.
    assert [l.get_label() for l in ax.get_lines()] == ["mdr N = 256 H = 0.5", "slope 1 (k ∝ F)"]
    asperity.plot.area(curve)
    study = asperity.study_alpha(method="mdr", n=[256], hurst=[0.25, 0.75], samples=4,
                                 out=tmp_path / "alpha")
    ax = asperity.plot.alpha(study)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["mdr N = 256", "1/(1+H) (6)", "1/3 (Hertz)", "(24), N = 256"]
    # The points are the ensemble α of alpha.csv's rows, shifted by nothing (one N).
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), study.alpha)
    sweep = asperity.Solver(asperity.surface(32, hurst=0.8, seed=1)).sweep(
        nloads=3, pmin=1e-3, pmax=1e-2)
    ax = asperity.plot.stiffness(sweep)
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), sweep.stiffness)
    with pytest.raises(ValueError, match="study_alpha"):
        asperity.plot.alpha(curve)
