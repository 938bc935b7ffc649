"""One name for one thing across commands: the bootstrap count is `--boots` wherever a
command has one; the old spellings still parse for one release, hidden from the help."""

from __future__ import annotations

import re

import pytest
from typer.testing import CliRunner

from cli import app

runner = CliRunner()
COMMANDS = {
    ("findings",): "--boot",
    ("survey",): "--n-boot",
    ("gait", "predict"): "--boot",
}


@pytest.mark.parametrize("command", sorted(COMMANDS), ids=" ".join)
def test_boots_is_the_name_and_the_old_one_is_hidden(command):
    out = runner.invoke(app, [*command, "--help"], env={"COLUMNS": "200"})
    assert out.exit_code == 0, out.output
    flags = set(re.findall(r"--[a-z-]+", out.output))
    assert "--boots" in flags
    assert COMMANDS[command] not in flags


@pytest.mark.parametrize("command", sorted(COMMANDS), ids=" ".join)
def test_the_old_name_still_parses(command, tmp_path):
    db = tmp_path / "empty.duckdb"
    args = [*command]
    args += ["--gait-file", str(tmp_path / "none.toml")] if command[0] == "gait" else ["c"]
    out = runner.invoke(app, [*args, COMMANDS[command], "5", "--db", str(db)])
    assert "No such option" not in out.output, out.output
    assert out.exit_code == 2  # refused for the missing campaign or file, not the option


def test_help_keeps_the_brackets_of_an_extra():
    """rich read ``[pose]`` as a style tag and printed "(needs suds-exp)"."""
    out = runner.invoke(app, ["ingest", "--help"], env={"COLUMNS": "200"})
    assert "(needs suds-exp[pose])" in out.output, out.output
