"""Shared helpers: the `asperity` binary (ASPERITY_BIN, else target/release/asperity of this
repository) and a runner that returns its stdout and stderr."""

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def cli_path() -> Path:
    path = Path(os.environ.get("ASPERITY_BIN", REPO / "target" / "release" / "asperity"))
    if not path.exists():
        pytest.fail(
            f"the asperity binary is missing at {path}: build it with "
            "`cargo build --release -p asperity-cli` or set ASPERITY_BIN"
        )
    return path


@pytest.fixture
def cli():
    """cli(*args, cwd=..., ok=True) runs the binary; returns the CompletedProcess."""
    exe = cli_path()

    def run(*args, cwd=None, ok=True, env=None):
        result = subprocess.run(
            [str(exe), *map(str, args)], cwd=cwd, capture_output=True, text=True, env=env
        )
        if ok and result.returncode != 0:
            raise AssertionError(f"asperity {' '.join(map(str, args))} failed:\n{result.stderr}")
        return result

    return run


def cli_error(result) -> str:
    """The one-line message after `error: ` of a failed CLI run."""
    lines = [l for l in result.stderr.splitlines() if l.startswith("error: ")]
    assert result.returncode == 2 and len(lines) == 1, result.stderr
    return lines[0][len("error: "):]


def _default_sigint():
    signal.signal(signal.SIGINT, signal.SIG_DFL)


#: Popen keywords for a child that a test interrupts: it starts with SIGINT at its default,
#: so that Python installs its KeyboardInterrupt handler even where this suite runs with
#: SIGINT ignored (a background job of a non-interactive shell, `nohup … &`), which the
#: child would otherwise inherit and keep.
INTERRUPTIBLE = {"preexec_fn": _default_sigint}


def python_script(code: str, *args, env=None, **kwargs):
    """Runs `code` in a fresh interpreter (the test's own Python), interruptible by SIGINT."""
    return subprocess.Popen([sys.executable, "-c", code, *map(str, args)], env=env,
                            **INTERRUPTIBLE, **kwargs)
