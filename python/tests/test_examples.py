"""The example scripts of python/examples run and write their plots (matplotlib, Agg)."""

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

pytest.importorskip("matplotlib")


def run(script, *args, cwd):
    result = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)], cwd=cwd,
                            capture_output=True, text=True, env={"MPLBACKEND": "Agg", **__import__("os").environ})
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_bem_load_sweep_example(tmp_path):
    out = run("bem_load_sweep.py", tmp_path / "sweep.png", cwd=tmp_path)
    assert "16 loads" in out
    png = (tmp_path / "sweep.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 10_000


def test_alpha_study_example_resumes_from_its_folder(tmp_path):
    out = run("alpha_study.py", tmp_path / "study", cwd=tmp_path)
    rows = [l.split() for l in out.splitlines() if l[:6].strip().lstrip("-").replace(".", "").isdigit()]
    assert len(rows) == 5
    # α falls with H as eq. (6) says (MDR at N = 4096, 60 lines: within 0.1 of theory).
    for h, alpha, low, high, theory in ((float(x) for x in r) for r in rows):
        assert abs(alpha - theory) < 0.1, (h, alpha, theory)
    assert (tmp_path / "study" / "alpha_vs_h.png").exists()
    # Run again: read back from the checkpoints, the same table.
    assert run("alpha_study.py", tmp_path / "study", cwd=tmp_path) == out
