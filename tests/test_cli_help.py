"""Help shows what its source says, and its examples work.

Every command and sub-command's ``--help``: no Python type labels (``<bool>``,
``<list[str]>``), a usage line in click's words (``NAME``, ``[PATHS...]``, no ``{name}``),
brackets kept, and an ``Examples:`` paragraph. Each example then runs, as written, on a
small database built once for this file (expensive ones only in the slow suite).
"""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

from cli import app

runner = CliRunner()
ROOT = typer.main.get_command(app)
ELLIPSE = """name = "ellipse"
[phi1]
a0 = 0.0
cos = [1.2]
sin = [0.0]
[phi2]
a0 = 0.0
cos = [0.5753]
sin = [1.0531]
"""
#: examples that simulate, write a report or refit many times: the slow suite runs them
SLOW = {"simulate", "demo", "discrepancy", "report", "gait design", "gait connection", "plan"}


def _commands(group=ROOT, prefix: tuple[str, ...] = ()):
    for name, command in group.commands.items():
        path = (*prefix, name)
        if hasattr(command, "commands"):
            yield path
            yield from _commands(command, path)
        else:
            yield path


COMMANDS = sorted(_commands())


def _get(path: tuple[str, ...]):
    command = ROOT
    for name in path:
        command = command.commands[name]
    return command


LEAVES = [c for c in COMMANDS if not hasattr(_get(c), "commands")]


def examples(path: tuple[str, ...]) -> list[str]:
    """The command lines of a command's ``Examples:`` paragraph, continuations joined."""
    help_text = _get(path).help or ""
    _, found, block = help_text.partition("Examples:\n")
    if not found:
        return []
    lines = block.split("\n\n")[0].replace("\\\n", " ").splitlines()
    return [" ".join(line.split()) for line in lines if line.strip()]


def _help(args: list[str]) -> str:
    out = runner.invoke(app, [*args, "--help"], env={"COLUMNS": "100"})
    assert out.exit_code == 0, out.output
    return out.output


@pytest.mark.parametrize("path", [(), *COMMANDS], ids=lambda p: " ".join(p) or "suds-exp")
def test_help_has_no_type_labels_and_a_plain_usage_line(path):
    text = _help(list(path))
    assert not re.search(r"<(bool|int|str|float|list\[[^]]*\]|Path|path)>", text), text
    usage = next(line for line in text.splitlines() if "Usage:" in line)
    assert "{" not in usage and "}" not in usage, usage
    assert usage.split("Usage:")[1].split()[0] == "suds-exp", usage


def test_a_flag_shows_no_value_and_a_value_its_metavar():
    text = _help(["gait", "predict"])
    assert re.search(r"--json\s+Print", text), text
    assert re.search(r"--model\s+LEARNER", text), text
    assert re.search(r"--trials\s+IDS", text), text
    assert re.search(r"Usage: suds-exp run \[OPTIONS\] NAME\b", _help(["run"]))
    assert "[PATHS...]" in _help(["ingest"])


def test_brackets_in_help_are_kept():
    assert "suds-exp[pose]" in _help(["ingest"])
    assert "[-RANGE, RANGE]" in _help(["connection"])


@pytest.mark.parametrize("path", LEAVES, ids=" ".join)
def test_every_command_shows_an_example_of_itself(path):
    found = examples(path)
    assert found, f"{' '.join(path)} --help has no Examples: paragraph"
    assert all(line.startswith("suds-exp ") for line in found), found
    assert any(f"suds-exp {' '.join(path)} " in f"{line} " for line in found), found
    # each example is a line of its own in the rendered help, not wrapped into prose
    text = _help(list(path))
    assert any(line.strip().startswith(found[0][:40]) for line in text.splitlines()), text


@pytest.fixture(scope="module")
def small(tmp_path_factory) -> Path:
    """A folder with a small database (two gaits at 1/2 Hz, two trials each, preprocessed,
    campaign 'first'), the simulated captures in sim-data/ and a gait file ellipse.toml."""
    work = tmp_path_factory.mktemp("examples")
    (work / "ellipse.toml").write_text(ELLIPSE)
    env = {"SUDS_DB": str(work / "suds.duckdb")}
    for args in (
        ["simulate", "--out", str(work / "sim-data"), "--gaits", "O,D+", "--freqs", "1/2",
         "--repeats", "2", "--cycles", "6", "--ingest", "-q"],
        ["preprocess", "-q"],
        ["run", "first", "--models", "GMR,phase-only", "--boots", "2", "--train-cycles", "2",
         "-q"],
    ):  # fmt: skip
        out = runner.invoke(app, args, env=env)
        assert out.exit_code == 0, out.output
    return work


def _example_params():
    for path in LEAVES:
        for line in examples(path):
            slow = path[0] in SLOW or " ".join(path) in SLOW
            marks = [pytest.mark.slow] if slow else []
            yield pytest.param(line, marks=marks, id=line[:70])


@pytest.mark.parametrize("line", list(_example_params()))
def test_the_example_runs(line, small, tmp_path, monkeypatch):
    work = tmp_path / "work"
    shutil.copytree(small, work, ignore=shutil.ignore_patterns("*.lock"))
    monkeypatch.chdir(work)
    env = {"SUDS_DB": str(work / "suds.duckdb"), "COLUMNS": "80"}
    for step in line.split(" && "):
        args = shlex.split(step)
        assert args[0] == "suds-exp"
        out = runner.invoke(app, args[1:], env=env)
        assert out.exit_code == 0, f"{step}\n{out.output}"
