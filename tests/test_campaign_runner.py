"""Running, resuming and refusing campaigns (library API, CLI and SQL on the DB)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

import cli
from suds_exp.campaign import (
    KEY_COLUMNS,
    CampaignError,
    CampaignOptions,
    campaign_status,
    run_campaign,
)
from suds_exp.campaign.lock import RunLock
from suds_exp.errors import StoreError
from suds_exp.models.registry import LEARNERS
from suds_exp.store import Store
from suds_exp.testing.synthetic_samples import synthetic_samples
from suds_exp.workflows.demo_campaign import demo_campaign, demo_options

OPTIONS = dict(models=["phase-only", "TLS"], boots=2, train_cycles=4, sweep=[1, 2])


@pytest.fixture(scope="module")
def samples() -> pd.DataFrame:
    return synthetic_samples()


def test_a_campaign_fills_one_row_per_job(db, samples, campaign_rows):
    store = Store(db)
    summary = run_campaign(store, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    # 4 conditions: 16 pairs x 2 boots + 4 same-condition pairs x 2 boots x 2 sweep values
    assert summary.total_jobs == (16 * 2 + 4 * 2 * 2) * 2
    assert summary.done_now == summary.total_jobs and summary.failed_now == 0
    frame = campaign_rows(store)
    assert len(frame) == summary.total_jobs
    assert not frame.duplicated(list(KEY_COLUMNS)).any()
    assert frame.error.isna().all() and (frame.rmse_vx > 0).all()
    assert set(frame.n_cycles) == {1, 2, 4}
    for row in frame.itertuples():
        ranges = json.loads(row.train_ranges)
        assert sum(b - a + 1 for _, a, b in ranges) == row.n_cycles
        assert row.test_trial not in json.loads(row.train_trials)
        a, b = json.loads(row.test_range)
        assert b - a + 1 == 4
    # the paired design: every learner sees the same draw
    per_draw = frame.groupby(
        ["train_gait", "train_frequency_hz", "test_gait", "test_frequency_hz", "boot", "n_cycles"]
    )
    assert (per_draw.train_ranges.nunique() == 1).all()
    assert (per_draw.test_range.nunique() == 1).all()
    # the definition holds every option and every learner's parameters
    (definition,) = store.query_df("SELECT definition FROM campaigns WHERE name = 'c'").definition
    stored = json.loads(definition)["options"]
    assert stored["boots"] == 2 and stored["sweep"] == [1, 2]
    assert stored["models"]["phase-only"] == {"order": 10}
    status = campaign_status(store, "c")
    assert status["done"] == status["total"] == summary.total_jobs
    assert [m["done"] for m in status["models"]] == [summary.total_jobs // 2] * 2


def test_resume_skips_finished_jobs_and_reproduces_the_rest(db, tmp_path, samples, campaign_rows):
    store = Store(db)
    full = Store(tmp_path / "full.duckdb")
    run_campaign(full, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    # a partial run: keep some finished rows, as a stop would
    run_campaign(store, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    with store.write() as conn:
        conn.exec_driver_sql("DELETE FROM results WHERE boot = 1 OR model = 'TLS' AND n_cycles = 1")
    kept = len(campaign_rows(store))
    again = run_campaign(store, "c", CampaignOptions(), samples=samples, progress=False)
    assert again.done_before == kept and again.done_now == again.total_jobs - kept
    pd.testing.assert_frame_equal(campaign_rows(store), campaign_rows(full), check_exact=True)
    nothing = run_campaign(store, "c", samples=samples, progress=False)
    assert nothing.done_now == 0 and "already done" in nothing.message()


def test_continuing_with_changed_options_is_refused_naming_the_differences(
    db, samples, campaign_rows
):
    store = Store(db)
    run_campaign(store, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    before = campaign_rows(store)
    with pytest.raises(CampaignError, match=r"boots: 2 -> 3"):
        run_campaign(store, "c", CampaignOptions(boots=3), samples=samples, progress=False)
    with pytest.raises(CampaignError, match=r"models\.TLS\.n_bins"):
        changed = {"phase-only": {}, "TLS": {"n_bins": 7}}
        run_campaign(store, "c", CampaignOptions(models=changed), samples=samples, progress=False)
    with pytest.raises(CampaignError, match=r"trials"):
        fewer = samples[samples.trial_id != 3]
        run_campaign(store, "c", samples=fewer, progress=False)
    pd.testing.assert_frame_equal(campaign_rows(store), before)


def test_a_second_run_on_the_same_database_is_refused(db, samples):
    store = Store(db)
    with (
        RunLock(db, "other"),
        pytest.raises(StoreError, match=": run 'other' .* is writing to this database"),
    ):
        run_campaign(store, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    run_campaign(store, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)


def test_bad_options_are_refused_before_any_work(db, samples):
    store = Store(db)
    cases = [
        (CampaignOptions(models=["TLS", "nope"]), "nope"),
        (CampaignOptions(boots=0), "^boots: 0"),
        (CampaignOptions(mode="sometimes"), "^mode: "),
        (CampaignOptions(train_conditions="S+@2"), "^train_conditions: "),
        (CampaignOptions(train_cycles=200), "O@0.5"),
    ]
    for options, message in cases:
        with pytest.raises(Exception, match=message):
            run_campaign(store, "c", options, samples=samples, progress=False)
    assert store.query_df("SELECT count(*) AS n FROM campaigns").n[0] == 0


def cli_json(command: str, db: Path) -> dict:
    """The JSON document of ``suds-exp COMMAND --db DB --json`` (COMMAND's words split on
    spaces), which must succeed."""
    out = CliRunner().invoke(cli.app, [*command.split(), "--db", str(db), "--json"])
    assert out.exit_code == 0, out.output
    return json.loads(out.stdout)


def test_cli_run_and_status(db, samples, monkeypatch):
    import suds_exp.preprocess as preprocess

    seen = []

    class Version:  # a preprocessing version named v1 whose samples are `samples`
        name = "v1"

        def samples(self, trials=None):
            return samples

    def fake_get_version(store, ref=None):
        seen.append(ref)
        return Version()

    monkeypatch.setattr(preprocess, "get_version", fake_get_version)
    runner = CliRunner()
    doc = cli_json(
        "run c --prep v1 --models phase-only --boots 1 --train-cycles 3 --train-conditions O", db
    )
    assert doc["done_now"] == doc["total_jobs"] == 8 and seen == ["v1"]
    status = cli_json("status c", db)
    assert status["done"] == 8 and status["prep"] == "v1" and not status["running"]
    out = runner.invoke(cli.app, ["status", "c", "--db", str(db)])
    assert "8 / 8 jobs done" in out.stdout
    out = runner.invoke(cli.app, ["status", "c", "--db", str(db), "--csv"])
    assert out.stdout.splitlines() == ["model,done,total,failed", "phase-only,8,8,0"]
    out = runner.invoke(cli.app, ["run", "c", "--db", str(db), "--boots", "2"])
    assert out.exit_code == 2 and "boots: 1 -> 2" in out.output
    out = runner.invoke(cli.app, ["status", "nope", "--db", str(db)])
    assert out.exit_code == 2 and "no campaign 'nope'" in out.output


@pytest.fixture(scope="module")
def captured(tmp_path_factory) -> Path:
    """A database with preprocessed synthetic captures: 2 gaits x 2 frequencies x 2."""
    from suds_exp.preprocess import preprocess
    from suds_exp.testing.synthetic_captures import write_dataset

    folder = tmp_path_factory.mktemp("captured")
    manifest = write_dataset(
        folder / "data", gaits=("O", "D+"), frequencies=(0.5, 1.0), repeats=2, n_cycles=6
    )
    db = folder / "e2e.duckdb"
    out = CliRunner().invoke(
        cli.app,
        ["ingest", str(folder / "data"), "--manifest", str(manifest), "--db", str(db), "--quiet"],
    )
    assert out.exit_code == 0, out.output
    preprocess(Store(db), progress=False)
    return db


def test_cli_runs_all_five_learners_on_preprocessed_captures(tmp_path, captured):
    db = tmp_path / "e2e.duckdb"
    shutil.copy(captured, db)
    runner = CliRunner()
    doc = cli_json("run e2e --boots 1 --train-cycles 3 --test-conditions O@1 --sweep 1", db)
    # 4 train x 1 test conditions + the O@1 same-condition sweep point, x 5 learners
    assert doc["done_now"] == doc["total_jobs"] == (4 + 1) * 5 and doc["failed_now"] == 0
    frame = Store(db).query_df("SELECT * FROM results")
    assert set(frame.model) == {"phase-only", "TLS", "TLS+SUDS", "GMR", "GMR+SUDS"}
    assert frame.rmse_vx.notna().all() and set(frame.test_frequency_hz) == {1.0}
    # the preprocessing version was the only one, so it was chosen and recorded
    (prep,) = Store(db).query_df("SELECT prep_version FROM campaigns").prep_version
    assert prep == "v1"
    out = runner.invoke(cli.app, ["run", "e2e", "--db", str(db), "--mode", "rollout"])
    assert out.exit_code == 2 and "mode" in out.output


def test_demo_options_pick_a_few_conditions_at_the_extreme_frequencies():
    conditions = [(g, f) for g in ("S+", "O", "D-", "D+") for f in (1 / 3, 0.5, 1.0)]
    options = demo_options(synthetic_samples(conditions=conditions), prep="v1")
    chosen = "O@0.333333,O@1,D-@0.333333,D-@1,D+@0.333333,D+@1"
    assert options.train_conditions == options.test_conditions == chosen
    assert list(options.models) == list(LEARNERS) and options.boots == 2
    assert options.train_cycles == 5 and options.sweep == [1, 2]
    short = synthetic_samples(conditions=(("O", 1.0),), trials_per_condition=2, cycles=(4.5, 5))
    assert demo_options(short).train_cycles < 5


@pytest.mark.slow
def test_the_demo_campaign_runs_all_five_learners_on_a_few_conditions(tmp_path, captured):
    db = tmp_path / "demo.duckdb"
    shutil.copy(captured, db)
    summary = demo_campaign(Store(db), jobs=1, progress=False)
    assert summary.done_now == summary.total_jobs > 0 and summary.failed_now == 0
    frame = Store(db).query_df("SELECT * FROM results WHERE campaign = 'demo'")
    assert set(frame.model) == set(LEARNERS)
    assert frame.train_gait.nunique() == 2 and frame.train_frequency_hz.nunique() == 2
    again = demo_campaign(Store(db), jobs=1, progress=False)
    assert again.done_now == 0 and again.remaining == 0
