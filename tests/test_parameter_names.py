"""The library's errors name Python parameters; the CLI shows the same errors with flags."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.campaign import run_campaign
from suds_exp.commands.discrepancy import parse_exclude
from suds_exp.discrepancy import DiscrepancyOptions
from suds_exp.discrepancy.options import check_options
from suds_exp.errors import CampaignError, ConfigError, DiscrepancyError, SudsError
from suds_exp.preprocess import resolve_params
from suds_exp.store import Store

runner = CliRunner()
PACKAGE = Path(__file__).resolve().parents[1] / "suds_exp"


#: A flag (``--trials``) or a command (``suds-exp run``) written in a string.
CLI_WORDS = re.compile(r"(?<![\w-])--[a-z]|suds-exp [a-z]")


def cli_words_in_errors(source: str) -> list[tuple[int, str]]:
    """(line, text) of each string literal in a raise statement or a call of an error
    class (``...Error(...)``, ``NotMeasurable(...)``) that names a flag or a command."""
    found = set()
    for node in ast.walk(ast.parse(source)):
        func = getattr(node, "func", None)
        called = getattr(func, "id", None) or getattr(func, "attr", "")
        if isinstance(node, ast.Raise) or (
            isinstance(node, ast.Call) and (called.endswith("Error") or called == "NotMeasurable")
        ):
            for sub in ast.walk(node):
                if isinstance(sub, ast.Constant) and isinstance(sub.value, str):
                    if CLI_WORDS.search(sub.value):
                        found.add((sub.lineno, sub.value))
    return sorted(found)


def test_no_library_error_names_a_flag_or_a_command():
    """Only the command layer (suds_exp/commands/, cli.py) speaks flags and commands."""
    found = [
        f"{path.relative_to(PACKAGE)}:{line}: {text!r}"
        for path in sorted(PACKAGE.rglob("*.py"))
        if "commands" not in path.relative_to(PACKAGE).parts[:1]
        for line, text in cli_words_in_errors(path.read_text())
    ]
    assert not found, "\n".join(found)


def test_the_scan_finds_flags_and_commands():
    source = (
        "def f(x):\n"
        "    if x:\n"
        "        raise ConfigError(f'bad {x}; try --trials 1-3')\n"
        "    raise StoreError('no database; run `suds-exp init`')\n"
        "def g():\n"
        "    raise errors.PreprocessError('k-means: a name with a dash, not a flag')\n"
    )
    assert [line for line, _ in cli_words_in_errors(source)] == [3, 4]


def test_the_library_speaks_python(tmp_path):
    store = Store(tmp_path / "db.duckdb")
    with pytest.raises(CampaignError, match="^scheduler needs backend dask$") as exc:
        run_campaign(store, "x", scheduler="tcp://127.0.0.1:1")
    assert exc.value.param == ("scheduler", "backend")
    with pytest.raises(DiscrepancyError, match="^max_effects -1: must be >= 0$"):
        check_options(DiscrepancyOptions(max_effects=-1))
    with pytest.raises(DiscrepancyError, match="^exclude 'gravity': unknown effect"):
        parse_exclude("gravity")
    with pytest.raises(ConfigError, match="^params k=99: must be between 1 and"):
        resolve_params({"k": 99})


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["run", "x", "--scheduler", "tcp://127.0.0.1:1"], "--scheduler needs --backend dask"),
        (["discrepancy", "--max-effects", "-1"], "--max-effects -1: must be >= 0"),
        (["discrepancy", "--exclude-candidates", "gravity"], "--exclude-candidates 'gravity'"),
        (["preprocess", "--param", "k=99"], "--param k=99: must be between 1 and"),
        (["preprocess", "--preset", "papers"], "--preset papers: unknown preset;"),
        (["simulate", "--out", "x", "--freqs", "fast"], "--freqs 'fast': expected Hz values"),
        (["discrepancy", "--effect", "flippers"], "--effect 'flippers': expected"),
    ],
)
def test_the_cli_shows_flags(tmp_path, args, says):
    res = runner.invoke(app, [*args, "--db", str(tmp_path / "db.duckdb")])
    assert res.exit_code == 2, res.output
    assert says in res.stderr, res.stderr


def test_the_library_advises_a_step_and_the_cli_adds_its_command(tmp_path):
    from suds_exp.campaign import campaign_status
    from suds_exp.preprocess import preprocess

    db = tmp_path / "db.duckdb"
    Store(db).upgrade()
    with pytest.raises(CampaignError, match="start one first$") as exc:
        campaign_status(Store(db), "x")
    assert exc.value.step == "run"
    out = runner.invoke(app, ["status", "x", "--db", str(db)])
    assert out.exit_code == 2
    assert out.stderr.strip().endswith("start one first (`suds-exp run NAME`)")
    with pytest.raises(SudsError, match="ingest some first$"):
        preprocess(Store(db), progress=False)
    out = runner.invoke(app, ["preprocess", "--db", str(db)])
    assert out.exit_code == 2 and "ingest some first (`suds-exp ingest`)" in out.stderr
