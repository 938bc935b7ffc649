"""Tables fit their output: in a terminal the columns go in blocks as wide as it is (the
key column repeated), piped they are plain aligned lines, and `--csv` / `--json` give the
data whole."""

from __future__ import annotations

import csv
import io
import json

import pytest
from rich.console import Console
from typer.testing import CliRunner

from cli import app
from suds_exp import console
from suds_exp.store.rows import Rows

runner = CliRunner()
WIDE = Rows(
    ("id", *(f"column_{i}" for i in range(12))),
    [(k, *(f"value-{k}-{i}" for i in range(12))) for k in range(3)],
)


@pytest.fixture
def terminal80(monkeypatch):
    screen = io.StringIO()
    monkeypatch.setattr(
        console, "out", Console(file=screen, width=80, force_terminal=True, color_system=None)
    )
    return screen


def test_a_wide_table_in_an_80_column_terminal_goes_in_blocks(terminal80):
    console.print_rows(WIDE, title="wide")
    lines = terminal80.getvalue().splitlines()
    assert max(len(line) for line in lines) <= 80
    text = terminal80.getvalue()
    for i in range(12):  # every column whole, none folded into slivers
        assert f"column_{i}" in text
        assert f"value-2-{i}" in text
    assert text.count("┃ id ") >= 2  # the key column starts every block


def test_piped_a_table_is_plain_lines_a_row_each():
    out = io.StringIO()
    saved = console.out
    console.out = Console(file=out, width=80, force_terminal=False)
    try:
        console.print_rows(WIDE)
    finally:
        console.out = saved
    lines = out.getvalue().splitlines()
    assert len(lines) == 1 + 3
    assert lines[0].split() == list(WIDE.columns)
    assert lines[3].split()[-1] == "value-2-11"


def test_columns_without_values_are_named_not_drawn(terminal80):
    console.print_rows(Rows(("id", "a", "b"), [(1, None, 2.5), (2, None, 3.5)]))
    text = terminal80.getvalue()
    assert "empty columns: a" in text
    assert "┃ a " not in text


@pytest.fixture(scope="module")
def db(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tables")
    db = folder / "t.duckdb"
    assert runner.invoke(app, ["init", "--db", str(db)]).exit_code == 0
    return db


def test_sql_csv_and_json_give_the_same_rows(db):
    query = "SELECT 1 AS a, 'x,y' AS b, NULL AS c UNION ALL SELECT 2, 'z', 1.5 ORDER BY a"
    got = runner.invoke(app, ["sql", query, "--csv", "--db", str(db)])
    assert got.exit_code == 0, got.output
    assert list(csv.reader(io.StringIO(got.stdout))) == [
        ["a", "b", "c"],
        ["1", "x,y", ""],
        ["2", "z", "1.5"],
    ]
    got = runner.invoke(app, ["sql", query, "--json", "--db", str(db)])
    assert json.loads(got.stdout) == [{"a": 1, "b": "x,y", "c": None}, {"a": 2, "b": "z", "c": 1.5}]


def test_trials_piped_keeps_file_names_whole(db, tmp_path):
    got = runner.invoke(app, ["trials", "--db", str(db)])
    assert got.exit_code == 0, got.output
    assert got.stdout.split() == ["id", "file", "format", "gait", "frequency_hz", "repeat",
                                  "sample_rate_hz", "n_frames", "n_markers", "notes"]  # fmt: skip


def test_effects_piped_is_a_line_an_effect_parameter():
    got = runner.invoke(app, ["effects"])
    assert got.exit_code == 0, got.output
    lines = got.stdout.splitlines()
    assert lines[0].split()[:3] == ["effect", "state", "nominal_state"]
    assert any(line.startswith("hinge_damping ") for line in lines)
    got = runner.invoke(app, ["effects", "--csv"])
    assert next(csv.reader(io.StringIO(got.stdout)))[0] == "effect"
