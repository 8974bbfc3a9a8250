"""The flag table of docs/python.md ("Every flag of the CLI in Python") cannot drift: every
flag that `asperity CMD --help` lists has a row under its command, every row names a flag
the command has, and every `function(keyword=` the table gives is a keyword that function
(or class, or method) takes; an analysis named there is one of `asperity.ANALYSES`, the
option's own name."""

import importlib
import inspect
import re
from pathlib import Path

import pytest

import asperity

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "python.md"
COMMANDS = ["mdr", "contact", "bem", "stats", "import", "study curve", "study compare"]


def _section() -> str:
    text = GUIDE.read_text()
    start = text.index("## Every flag of the CLI in Python")
    end = text.index("\n## ", start + 1)
    return text[start:end]


def table(command: str) -> dict:
    """The rows under `### \\`asperity COMMAND\\``: flag -> its Python cell."""
    section = _section()
    heading = f"### `asperity {command}`\n"
    assert heading in section, f"no table for asperity {command}"
    body = section[section.index(heading) + len(heading):].split("\n### ")[0]
    rows = re.findall(r"^\| `(--[a-z0-9-]+)` \| (.*) \|$", body, flags=re.M)
    flags = [flag for flag, _ in rows]
    assert len(flags) == len(set(flags)), f"asperity {command}: a flag twice"
    return dict(rows)


def help_flags(cli, command: str) -> list:
    text = cli(*command.split(), "--help").stdout
    # Options are indented 2 (with a short form) or 6 spaces; their help text 10.
    flags = re.findall(r"^ {2,6}(?:-\w, )?(--[a-z0-9-]+)", text, flags=re.M)
    return [f for f in flags if f != "--help"]


def _callable(name: str):
    parts = name.split(".")
    if parts[0] == "plot":
        pytest.importorskip("matplotlib")
        importlib.import_module("asperity.plot")
    obj = asperity
    for part in parts:
        obj = getattr(obj, part)
    return obj


@pytest.mark.parametrize("command", COMMANDS)
def test_every_flag_has_a_row_and_every_row_a_flag(cli, command):
    flags = help_flags(cli, command)
    assert len(flags) >= 1
    rows = table(command)
    assert set(flags) - set(rows) == set(), f"asperity {command}: flags without a row"
    assert set(rows) - set(flags) == set(), f"asperity {command}: rows of no flag"


@pytest.mark.parametrize("command", COMMANDS)
def test_the_keywords_named_exist(command):
    for flag, cell in table(command).items():
        calls = re.findall(r"`([A-Za-z_][\w.]*)\((\w+)=", cell)
        if not calls:
            assert cell.startswith(("—", "(")), f"{flag}: {cell}"
        for name, keyword in calls:
            parameters = inspect.signature(_callable(name)).parameters
            assert keyword in parameters, f"asperity {command} {flag}: {name}({keyword}=)"
        for analysis in re.findall(r'`analysis\(name="(\w+)"\)`', cell):
            assert analysis in asperity.ANALYSES
            assert analysis == flag[2:].replace("-", "_")


def test_every_flag_has_a_python_call():
    gaps = [(c, f) for c in COMMANDS for f, cell in table(c).items() if cell.startswith("—")]
    assert gaps == []
