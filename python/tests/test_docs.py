"""The examples of docs/python.md run as they stand, in order, in a scratch folder."""

import os
import re
from pathlib import Path

import pytest

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "python.md"


def blocks():
    return re.findall(r"```python\n(.*?)```", GUIDE.read_text(), flags=re.S)


def test_the_guide_has_examples():
    assert len(blocks()) >= 8


def test_the_guides_examples_run(tmp_path, capsys):
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        namespace = {}
        for i, code in enumerate(blocks()):
            try:
                exec(compile(code, f"docs/python.md block {i + 1}", "exec"), namespace)
            except Exception as e:  # name the block
                pytest.fail(f"docs/python.md, python block {i + 1}: {type(e).__name__}: {e}")
    finally:
        os.chdir(cwd)
