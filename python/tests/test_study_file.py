"""`asperity.study_file` is `asperity study file`: the file read by the front-end layer's one
reader (`asperity_app::study::file`), the study run in the same folder layout with the same
numbers (the CLI writes alpha.csv and curve.csv byte for byte from Python's folder), its refusals in the CLI's words."""

import pytest

import asperity

from conftest import cli_error

ALPHA = """kind = "alpha"
method = "mdr"
n = [128, 256]
hurst = "0:1:0.5"
samples = 6
seed = 3
"""

CURVE = """kind = "curve"
method = "bem"
n = 32
hurst = [0.5, "0.8:0.8:0.1"]
samples = 3
seed = 2
resistivity = [1, 2]
"""


@pytest.mark.parametrize("text, table", [(ALPHA, "alpha.csv"), (CURVE, "curve.csv")])
def test_a_study_file_gives_the_cli_s_tables_byte_for_byte(cli, tmp_path, text, table):
    path = tmp_path / "s.toml"
    path.write_text(text)
    cli("study", "file", path, "--out", tmp_path / "cli", "--quiet")
    ours = asperity.study_file(path, tmp_path / "py")
    # The CLI takes Python's folder as the same study (it refuses another one), finds it
    # done and writes its table from Python's checkpoints: byte for byte its own.
    cli("study", "file", path, "--out", tmp_path / "py", "--quiet")
    assert (tmp_path / "py" / table).read_bytes() == (tmp_path / "cli" / table).read_bytes()
    with open(tmp_path / "cli" / table) as fh:
        header = fh.readline().strip().split(",")
        first = dict(zip(header, fh.readline().strip().split(",")))
    assert list(ours.rows[0]) == header
    column = "alpha" if table == "alpha.csv" else "stiffness"
    assert ours.rows[0][column] == float(first[column])


@pytest.mark.parametrize("text", [
    "kind = \"alpha\"\nmethod = \"mdr\"\nn = 128\nhurst = 0.5\nsamples = 2\nnokey = 1\n",
    "kind = \"curve\"\nmethod = \"mdr\"\nn = 128\nhurst = 0.5\nsamples = 2\nfull_sweep = true\n",
    "kind = \"alpha\"\nmethod = \"mdr\"\nn = 128\nhurst = 0.5\nsamples = 2\npoisson = 0.3\n",
    "kind = \"alpha\"\nmethod = \"fem\"\nn = 128\nhurst = 0.5\nsamples = 2\n",
    "kind = \"alpha\"\nmethod = \"mdr\"\nn = 128\nhurst = \"0:1:x\"\nsamples = 2\n",
])
def test_a_bad_study_file_is_refused_in_the_cli_s_words(cli, tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    theirs = cli_error(cli("study", "file", path, "--out", tmp_path / "o", ok=False))
    with pytest.raises(ValueError) as ours:
        asperity.study_file(path, tmp_path / "p")
    assert str(ours.value) == theirs
    assert not (tmp_path / "p").exists()
