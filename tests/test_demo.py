"""`suds-exp demo` end to end: the README's main command (about 1-2 minutes: slow)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.store import Store

README = Path(__file__).resolve().parents[1] / "README.md"

runner = CliRunner()


@pytest.mark.slow
def test_demo_runs_end_to_end_and_is_idempotent(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    first = runner.invoke(app, ["demo", "--json"])
    assert first.exit_code == 0, first.output
    summary = json.loads(first.stdout)
    assert summary["n_trials"] == 60
    assert summary["n_results"] > 0
    assert [f["id"] for f in summary["findings"]][:3] == ["F1", "F2", "F3"]
    assert "findings hold" in summary["findings_headline"]
    assert (tmp_path / "reports" / "demo" / "index.html").is_file()
    assert (tmp_path / "reports" / "discrepancy-demo" / "index.html").is_file()
    assert summary["discrepancy_report"] == str(Path("reports/discrepancy-demo/index.html"))
    assert [n["effect"] for n in summary["discrepancy"]["named"]][:1] == ["body_inertia"]
    store = Store(tmp_path / "suds.duckdb")
    counts = store.query_df(
        "SELECT (SELECT count(*) FROM trials) AS trials, "
        "(SELECT count(*) FROM results WHERE rmse_vx IS NOT NULL) AS results"
    )
    assert counts.trials[0] == 60 and counts.results[0] == summary["n_results"]

    again = runner.invoke(app, ["demo"])
    assert again.exit_code == 0, again.output
    assert "ingested 0 new trials (60 already stored)" in again.stdout
    assert "findings on this SMALL campaign" in again.stdout and "F10" in again.stdout
    assert "reports/demo/index.html and reports/discrepancy-demo/index.html" in again.stdout
    assert store.query_df("SELECT count(*) AS n FROM trials").n[0] == 60
    assert store.query_df("SELECT count(*) AS n FROM results").n[0] == summary["n_results"]


def readme_python() -> str:
    """The README's "From Python" block."""
    text = README.read_text()
    section = text[text.index("## From Python") :]
    return section.split("```python\n", 1)[1].split("```", 1)[0]


@pytest.mark.slow
def test_the_readme_python_snippet_runs_after_the_demo(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert runner.invoke(app, ["demo", "-q"]).exit_code == 0
    namespace: dict = {}
    exec(compile(readme_python(), "README.md (From Python)", "exec"), namespace)
    assert len(namespace["pred"]) == int((namespace["samples"].trial_id == 1).sum())
    assert not namespace["glm"].empty
