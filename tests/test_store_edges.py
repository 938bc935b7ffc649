"""Databases a new user may point `--db` at by mistake: one line naming the file and what
is wrong, exit status 2, and nothing created or changed."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.store import Store

runner = CliRunner()


def listing(folder: Path) -> dict[str, str]:
    """name -> SHA-256 of every file under ``folder``."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def one_line_error(args: list[str], path: Path, says: str) -> None:
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert str(path) in lines[0] and says in lines[0], lines[0]
    assert "Traceback" not in res.output


@pytest.mark.parametrize("command", [["trials"], ["init"], ["preprocess"]])
def test_a_file_that_is_not_a_database(tmp_path, command):
    notes = tmp_path / "notes.txt"
    notes.write_text("shopping: eggs, flour\n")
    before = listing(tmp_path)
    one_line_error([*command, "--db", str(notes)], notes, "not a DuckDB database file")
    assert listing(tmp_path) == before


@pytest.mark.parametrize("command", [["trials"], ["init"]])
def test_a_truncated_database(tmp_path, command):
    whole = tmp_path / "whole.duckdb"
    Store(whole).upgrade()
    data = whole.read_bytes()
    cut = tmp_path / "cut" / "suds.duckdb"
    cut.parent.mkdir()
    cut.write_bytes(data[: len(data) // 3])  # a copy cut short (half would still open)
    before = listing(cut.parent)
    one_line_error([*command, "--db", str(cut)], cut, "truncated or damaged")
    assert listing(cut.parent) == before


@pytest.fixture
def locked_folder(tmp_path) -> Path:
    """A folder this process cannot create files in (root ignores mode bits: then a
    folder of the kernel's read-only /sys, when there is one)."""
    folder = tmp_path / "locked"
    folder.mkdir()
    folder.chmod(0o500)
    for candidate in (folder, Path("/sys")):
        probe = candidate / "suds-probe.tmp"
        try:
            probe.touch()
        except OSError:
            yield candidate
            break
        probe.unlink()
    else:
        pytest.skip("no folder this process cannot write to")
    folder.chmod(0o700)


@pytest.mark.parametrize("name", ["suds.duckdb", "new/suds.duckdb"])
def test_a_folder_that_cannot_be_written(locked_folder, name):
    db = locked_folder / name
    before = sorted(p.name for p in locked_folder.iterdir())
    for command in (["init"], ["preprocess"]):
        one_line_error([*command, "--db", str(db)], db, "cannot create")
    assert sorted(p.name for p in locked_folder.iterdir()) == before
    assert not os.path.exists(db)
