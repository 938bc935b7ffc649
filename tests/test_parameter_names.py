"""The library's errors name Python parameters; the CLI shows the same errors with flags."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.campaign import run_campaign
from suds_exp.discrepancy import DiscrepancyOptions, parse_exclude
from suds_exp.discrepancy.workflow import check_options
from suds_exp.errors import CampaignError, ConfigError, DiscrepancyError
from suds_exp.preprocess import resolve_params
from suds_exp.store import Store

runner = CliRunner()
PACKAGE = Path(__file__).resolve().parents[1] / "suds_exp"


def test_no_library_error_names_a_flag():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "id", "").endswith("Error"):
                text = ast.get_source_segment(path.read_text(), node) or ""
                if re.search(r"[\"' ]--[a-z]", text):
                    found.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert not found, found


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
        (["discrepancy", "--model-effect", "flippers"], "--model-effect 'flippers': expected"),
    ],
)
def test_the_cli_shows_flags(tmp_path, args, says):
    res = runner.invoke(app, [*args, "--db", str(tmp_path / "db.duckdb")])
    assert res.exit_code == 2, res.output
    assert says in res.stderr, res.stderr
