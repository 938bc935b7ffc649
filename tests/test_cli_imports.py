"""Small commands start fast: `--version`, `--help`, `trials`, `sql` and `status` import
none of the heavy libraries that only learning, statistics, plots or the simulator need."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

HEAVY = ("sklearn", "statsmodels", "matplotlib", "numba")
PROBE = """
import json, sys
from typer.testing import CliRunner
import cli
CliRunner().invoke(cli.app, json.loads(sys.argv[1]))
print(json.dumps(sorted(m for m in {heavy!r} if m in sys.modules)))
"""


@pytest.fixture(scope="module")
def db(tmp_path_factory):
    path = tmp_path_factory.mktemp("small") / "s.duckdb"
    from typer.testing import CliRunner

    import cli

    assert CliRunner().invoke(cli.app, ["init", "--db", str(path)]).exit_code == 0
    return path


@pytest.mark.parametrize(
    "args",
    [["--version"], ["--help"], ["trials"], ["sql", "SELECT 1 AS one"], ["status", "c"]],
    ids=lambda a: a[0],
)
def test_a_small_command_imports_no_heavy_library(db, args):
    argv = [*args, "--db", str(db)] if not args[0].startswith("--") else args
    out = subprocess.run(
        [sys.executable, "-c", PROBE.format(heavy=HEAVY), json.dumps(argv)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert json.loads(out.stdout.splitlines()[-1]) == [], out.stdout


@pytest.mark.parametrize(
    "args",
    [
        ["trials"],
        ["trials", "--csv"],
        ["sql", "SELECT 1 AS one"],
        ["status", "c"],
        ["status", "c", "--csv"],
    ],
    ids=" ".join,
)
def test_trials_sql_and_status_read_without_pandas_or_sqlalchemy(db, args):
    """They read a few rows through DuckDB alone (`suds_exp.store.rows`)."""
    probe = PROBE.format(heavy=("pandas", "sqlalchemy"))
    out = subprocess.run(
        [sys.executable, "-c", probe, json.dumps([*args, "--db", str(db)])],
        capture_output=True,
        text=True,
        check=True,
    )
    assert json.loads(out.stdout.splitlines()[-1]) == [], out.stdout
