"""The `asperity` command the Python package installs (issue 36 item 6): the command line
compiled into the extension module, run by the console script `asperity._cli:main`. It must
be the same program as the cargo-built binary: same outputs byte for byte, same one-line
errors and exit statuses."""

import subprocess
import sys
from pathlib import Path

from conftest import cli_path


def installed_command() -> Path:
    """The console script pip (or `maturin develop`) put beside this interpreter."""
    script = Path(sys.executable).parent / "asperity"
    assert script.exists(), (
        f"the package's `asperity` command is missing at {script}: install the package with "
        "`pip install ./python` (it installs the command with the module)"
    )
    return script


def run(exe, *args, cwd=None):
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, cwd=cwd)


def test_the_installed_command_is_the_compiled_in_command_line():
    script = installed_command()
    text = script.read_text(errors="replace")
    assert "asperity._cli" in text, text


def test_version_and_help_are_the_binarys():
    script, binary = installed_command(), cli_path()
    for args in (["--version"], ["surface", "--help"], ["study", "alpha", "--help"]):
        mine, theirs = run(script, *args), run(binary, *args)
        assert (mine.returncode, mine.stdout) == (theirs.returncode, theirs.stdout), args


def test_a_surface_and_its_statistics_are_bit_identical(tmp_path):
    script, binary = installed_command(), cli_path()
    surface = ["surface", "--n", "48", "--m", "40", "--hurst", "0.7", "--seed", "11"]
    assert run(script, *surface, "--out", tmp_path / "a.npy").returncode == 0
    assert run(binary, *surface, "--out", tmp_path / "b.npy").returncode == 0
    assert (tmp_path / "a.npy").read_bytes() == (tmp_path / "b.npy").read_bytes()
    mine = run(script, "stats", tmp_path / "a.npy", "--size", "1")
    theirs = run(binary, "stats", tmp_path / "a.npy", "--size", "1")
    assert mine.returncode == theirs.returncode == 0, mine.stderr
    assert mine.stdout == theirs.stdout


def test_a_bad_input_is_the_same_one_line_error_with_status_2(tmp_path):
    script, binary = installed_command(), cli_path()
    for args in (
        ["surface", "--n", "0", "--hurst", "0.5", "--out", tmp_path / "x.npy"],
        ["stats", tmp_path / "missing.npy", "--size", "1"],
        ["no-such-command"],
    ):
        mine, theirs = run(script, *args), run(binary, *args)
        assert mine.returncode == theirs.returncode == 2, (args, mine.stderr)
        assert mine.stderr == theirs.stderr, args
        assert len(mine.stderr.decode().strip().splitlines()) == 1, mine.stderr


def test_an_interrupt_removes_unfinished_outputs_and_exits_130(tmp_path):
    # The command line's own Ctrl-C handling runs in the package's command too (it installs
    # it in the console script's process): status 130 and the same closing line.
    import signal
    import time

    args = ["study", "alpha", "--method", "bem", "--n", "256", "--hurst", "0.5",
            "--samples", "40", "--out", tmp_path / "d"]
    proc = subprocess.Popen([str(installed_command()), *map(str, args)],
                            stderr=subprocess.PIPE, text=True)
    time.sleep(3)
    proc.send_signal(signal.SIGINT)
    err = proc.communicate(timeout=60)[1]
    assert proc.returncode == 130, err
    assert err.strip().splitlines()[-1].startswith("interrupted: unfinished outputs removed")
    assert not (tmp_path / "d" / "alpha.csv").exists()


def test_reproduce_is_a_python_call_that_writes_the_clis_files(tmp_path):
    import pytest

    import asperity

    folder = asperity.reproduce("fig15.1", tmp_path / "py")
    assert folder == str(tmp_path / "py")
    subprocess.run([str(cli_path()), "reproduce", "fig15.1", "--out", str(tmp_path / "cli")],
                   check=True, capture_output=True)
    name = "fig15_1.csv"
    ours = (tmp_path / "py" / "fig15.1" / name).read_bytes()
    assert ours == (tmp_path / "cli" / "fig15.1" / name).read_bytes()
    with pytest.raises(ValueError, match="fig99") as e:
        asperity.reproduce("fig99", tmp_path / "bad")
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match="not made by .*--force"):
        asperity.reproduce("fig15.1", tmp_path / "py", setting="quick")
