"""Objects show what matters at a prompt and in a notebook: a learner under its own name
(GMR+SUDS, not GMRSuds), its changed parameters and whether it is fitted; a `Store` its
size and contents; a `Version` its parameters in one short line; a campaign's run its jobs
and best learner. Each also has an HTML table (`_repr_html_`, what Jupyter shows)."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.campaign import CampaignOptions, run_campaign
from suds_exp.models import MODEL_NAMES, make_model
from suds_exp.preprocess import get_version
from suds_exp.store import Store
from suds_exp.testing.synthetic_swimmer import make_samples


@pytest.mark.parametrize("name", ["GMR", "GMR+SUDS", "phase-only"])
def test_a_learner_shows_its_name_and_whether_it_is_fitted(name):
    model = make_model(name)
    assert repr(model) == f"{name}() [not fitted]"
    if "random_state" in model.get_params():
        model.set_params(random_state=3)
    model.fit(make_samples(4, seed=1, n_trials=2))
    text = repr(model)
    assert text.startswith(f"{name}(") and "[fitted: " in text
    if "random_state" in model.get_params():
        assert "random_state=3" in text
    html = model._repr_html_()
    assert f"<strong>{name}</strong>" in html and "fitted: " in html


def test_every_registered_learner_has_a_one_line_repr():
    for name in MODEL_NAMES:
        text = repr(make_model(name))
        assert "\n" not in text and text.endswith("[not fitted]"), text


def test_store_version_and_a_run_show_their_size_and_state(tmp_path):
    runner = CliRunner()
    db = tmp_path / "d.duckdb"
    env = {"SUDS_DB": str(db)}
    for args in (
        ["simulate", "--out", str(tmp_path / "sim"), "--gaits", "O", "--freqs", "1/2",
         "--repeats", "2", "--cycles", "5", "--ingest", "-q"],
        ["preprocess", "-q", "--param", "sg_window_cycles=0.15"],
    ):  # fmt: skip
        assert runner.invoke(app, args, env=env).exit_code == 0
    store = Store(db)
    assert "trials=2, campaigns=0" in repr(store)
    assert "MB" in repr(store) and "<table" in store._repr_html_()

    version = get_version(store)
    text = repr(version)
    assert len(text) < 200, text
    assert "sg_window_cycles=0.15" in text and "fitted yes" in text

    options = CampaignOptions(models=("GMR", "phase-only"), boots=2, train_cycles=2)
    summary = run_campaign(store, "c", options, progress=False)
    text = repr(summary)
    assert f"jobs done {summary.total_jobs} / {summary.total_jobs}" in text
    assert "best learner " in text and "median RMSE vx" in text
    assert "best learner" in summary._repr_html_()
