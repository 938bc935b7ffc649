"""One name for one thing across commands: the bootstrap count is `--boots`, a learner
`--model` (several: `--models`), a frequency `--freqs`, the simulator `--config` and
`--effect`, parallel workers `-j/--jobs`; the old spellings still parse for one release,
hidden from the help (CHANGELOG.md lists them)."""

from __future__ import annotations

import re

import pytest
import typer.main
from typer.testing import CliRunner

from cli import app

runner = CliRunner()
#: (command, old name, new name, a value for it)
RENAMED = [
    (("findings",), "--boot", "--boots", "5"),
    (("survey",), "--n-boot", "--boots", "5"),
    (("gait", "predict"), "--boot", "--boots", "5"),
    (("gait", "predict"), "--learner", "--model", "GMR"),
    (("gait", "predict"), "--freq", "--freqs", "1/2"),
    (("gait", "design"), "--learner", "--model", "GMR"),
    (("gait", "design"), "--freq", "--freqs", "1/2"),
    (("gait", "connection"), "--learner", "--model", "GMR"),
    (("plan", "next"), "--learner", "--model", "GMR"),
    (("plan", "loop"), "--learner", "--model", "GMR"),
    (("discrepancy",), "--model", "--config", "nominal.toml"),
    (("discrepancy",), "--model-effect", "--effect", "flippers=absent"),
]
IDS = [f"{' '.join(c)} {old}" for c, old, _, _ in RENAMED]
#: what each command needs before it can fail on something other than its options
NEEDS = {
    ("gait", "predict"): ["--gait-file", "none.toml"],
    ("plan", "next"): ["--goal", "none"],
    ("plan", "loop"): ["--goal", "none"],
}


def _flags(command: tuple[str, ...]) -> set[str]:
    out = runner.invoke(app, [*command, "--help"], env={"COLUMNS": "200"})
    assert out.exit_code == 0, out.output
    return set(re.findall(r"(?<![\w-])--?[a-z][a-z-]*", out.output))


@pytest.mark.parametrize(("command", "old", "new", "value"), RENAMED, ids=IDS)
def test_the_new_name_is_shown_and_the_old_one_hidden(command, old, new, value):
    flags = _flags(command)
    assert new in flags
    if old != "--model":  # discrepancy's old --model is hidden; --model is a learner elsewhere
        assert old not in flags


@pytest.mark.parametrize(("command", "old", "new", "value"), RENAMED, ids=IDS)
def test_the_old_name_still_parses(command, old, new, value, tmp_path):
    db = tmp_path / "empty.duckdb"
    args = [*command, *NEEDS.get(command, [])]
    args += ["c"] if command in {("findings",), ("survey",)} else []
    if command == ("discrepancy",) and old == "--model":
        value = str(tmp_path / value)
    out = runner.invoke(app, [*args, old, value, "--db", str(db)])
    assert "No such option" not in out.output, out.output
    assert out.exit_code == 2, out.output  # refused for what is missing, not the option


def _leaves(group=None, prefix=()):
    group = group or typer.main.get_command(app)
    for name, command in group.commands.items():
        if hasattr(command, "commands"):
            yield from _leaves(command, (*prefix, name))
        else:
            yield (*prefix, name), command


LEAVES = dict(_leaves())


@pytest.mark.parametrize("command", sorted(LEAVES), ids=" ".join)
def test_one_name_for_one_thing(command):
    shown = {
        flag: param
        for param in LEAVES[command].params
        if not param.hidden
        for flag in [*param.opts, *param.secondary_opts]
    }
    assert not {"--learner", "--freq", "--boot", "--n-boot", "--model-effect"} & set(shown)
    if "--model" in shown:  # a learner, never a file
        assert shown["--model"].metavar == "LEARNER"
    if "--jobs" in shown:
        assert "-j" in shown
    # every command can answer a script: demo narrates, the others print a result
    assert "--json" in shown


def test_help_keeps_the_brackets_of_an_extra():
    """rich read ``[pose]`` as a style tag and printed "(needs suds-exp)"."""
    out = runner.invoke(app, ["ingest", "--help"], env={"COLUMNS": "200"})
    assert "(needs suds-exp[pose])" in out.output, out.output
