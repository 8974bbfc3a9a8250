"""`asperity.study_windows` is `asperity study windows` (the same rows by the front-end
layer's one call, `asperity_app::study::windows`): the arrays equal the CSV the CLI prints,
bit for bit, on a finished BEM study; an MDR study is refused in the CLI's
words."""

import csv
import io

import numpy as np
import pytest

import asperity

from conftest import cli_error


def cli_columns(text):
    rows = list(csv.reader(io.StringIO(text)))
    header, body = rows[0], rows[1:]
    return header, [[row[i] for row in body] for i in range(len(header))]


def assert_the_cli_s(cli, out):
    header, columns = cli_columns(cli("study", "windows", out).stdout)
    ours = asperity.study_windows(out)
    assert list(ours) == header
    for name, texts in zip(header, columns):
        if name in ("n", "min_contacts", "samples"):
            assert ours[name].dtype == np.int64
            assert ours[name].tolist() == [int(t) for t in texts], name
        else:
            assert ours[name].dtype == np.float64
            assert ours[name].tolist() == [float(t) for t in texts], name
    return ours


def test_the_windows_of_a_bem_study_are_the_cli_s(cli, tmp_path):
    out = tmp_path / "bem"
    asperity.study_curve(method="bem", n=64, hurst=[0.3, 0.8], samples=4, seed=5, out=out,
                         progress=None)
    ours = assert_the_cli_s(cli, out)
    # Both tasks, several windows each, every sample in each; α inside its interval.
    assert sorted(set(ours["hurst"].tolist())) == [0.3, 0.8]
    assert len(ours["alpha"]) > 2 and (ours["samples"] == 4).all()
    assert ((ours["low"] <= ours["alpha"]) & (ours["alpha"] <= ours["high"])).all()


def test_an_mdr_study_is_refused_in_the_cli_s_words(cli, tmp_path):
    out = tmp_path / "mdr"
    asperity.study_alpha(method="mdr", n=256, hurst=0.5, samples=4, out=out, progress=None)
    theirs = cli_error(cli("study", "windows", out, ok=False))
    with pytest.raises(ValueError) as ours:
        asperity.study_windows(out)
    assert str(ours.value) == theirs
    assert "no task of this study has stored sample curves" in theirs
    # A folder that holds no study: OSError (as for every file Python cannot read), in the
    # CLI's words.
    with pytest.raises(OSError) as missing:
        asperity.study_windows(tmp_path / "none")
    assert str(missing.value) == cli_error(cli("study", "windows", tmp_path / "none",
                                               ok=False))
