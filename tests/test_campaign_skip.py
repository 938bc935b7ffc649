"""Leaving out the (condition, training size) cells the data cannot supply (--skip-infeasible):
stored in the definition, kept on resume, named in status and report; refused by default."""

from __future__ import annotations

import json

import pandas as pd
import pytest
from typer.testing import CliRunner

import cli
from suds_exp.campaign import CampaignError, CampaignOptions, SampleBank, run_campaign
from suds_exp.campaign.status import campaign_status
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db
from suds_exp.testing.synthetic_samples import synthetic_samples

SHORT = ("D+", 0.5)


@pytest.fixture(scope="module")
def samples() -> pd.DataFrame:
    """O at 0.5 and 1 Hz with long trials; D+ at 0.5 Hz with trials of 2-3 complete cycles."""
    long = synthetic_samples(conditions=(("O", 0.5), ("O", 1.0)))
    short = synthetic_samples(conditions=(SHORT,), cycles=(3.5, 4.5), seed=1)
    short["trial_id"] += long["trial_id"].max()
    return pd.concat([long, short], ignore_index=True)


@pytest.fixture(scope="module")
def room(samples) -> dict:
    """Complete cycles of the short condition: in all, and outside its longest trial."""
    bank = SampleBank.build(samples)
    cycles = [bank.n_cycles(i) for i in bank.trials_of(SHORT)]
    return {"total": sum(cycles), "best": sum(cycles) - min(cycles)}


def options(room, **kw) -> CampaignOptions:
    base = dict(models=["phase-only"], boots=2, train_cycles=2, sweep=[1, room["best"] + 1])
    return CampaignOptions(**{**base, **kw})


def test_default_refuses_and_leaves_the_database_as_it_was(db, samples, room):
    store = Store(db)
    store.upgrade()
    before = dump_db(db)
    with pytest.raises(CampaignError, match=r"D\+@0\.5: .*skip_infeasible"):
        run_campaign(store, "c", options(room), samples=samples, progress=False)
    assert_same_db(before, dump_db(db))


def test_skipped_cells_are_stored_left_out_resumed_and_named(db, samples, room):
    store = Store(db)
    big = room["best"] + 1
    summary = run_campaign(
        store, "c", options(room, skip_infeasible=True), samples=samples, progress=False
    )
    (definition,) = store.query_df("SELECT definition FROM campaigns WHERE name = 'c'").definition
    definition = json.loads(definition)
    assert definition["options"]["skip_infeasible"] is True
    assert definition["skipped_cells"] == [
        {"condition": "D+@0.5", "n_cycles": big, "pairs": "same-condition"}
    ]
    # 3 conditions: 9 pairs x 2 boots + 3 same-condition pairs x 2 boots x 2 sweep sizes,
    # less the 2 draws of the skipped cell
    assert summary.total_jobs == 9 * 2 + 3 * 2 * 2 - 2
    assert summary.to_dict()["skipped_cells"] == definition["skipped_cells"]
    rows = store.query_df("SELECT * FROM results WHERE campaign = 'c'")
    assert len(rows) == summary.total_jobs and rows["error"].isna().all()
    short = (rows.train_gait == "D+") & (rows.test_gait == "D+")
    assert sorted(rows.loc[short, "n_cycles"].unique()) == [1, 2]
    assert (rows.n_cycles == big).sum() == 2 * 2  # the two O conditions still have it

    # resume without the option: the stored definition keeps the cells out
    again = run_campaign(store, "c", CampaignOptions(), samples=samples, progress=False)
    assert again.total_jobs == summary.total_jobs and again.done_now == 0
    # asking for refusal on a campaign that skips is a different definition
    with pytest.raises(CampaignError, match="skip_infeasible"):
        run_campaign(
            store, "c", CampaignOptions(skip_infeasible=False), samples=samples, progress=False
        )

    status = campaign_status(store, "c")
    assert status["skipped_cells"] == definition["skipped_cells"]
    runner = CliRunner()
    out = runner.invoke(cli.app, ["status", "c", "--db", str(db)])
    assert out.exit_code == 0 and f"D+@0.5 x {big} cycles (same-condition pairs)" in out.stdout


def test_a_condition_with_too_few_cycles_in_all_loses_all_its_draws_of_that_size(db, samples, room):
    store = Store(db)
    n = room["total"] + 1
    summary = run_campaign(
        store,
        "c",
        CampaignOptions(
            models=["phase-only"],
            boots=1,
            train_cycles=n,
            train_conditions="O@0.5,D+@0.5",
            test_conditions="O@0.5",
            skip_infeasible=True,
        ),
        samples=samples,
        progress=False,
    )
    assert summary.extra["skipped_cells"] == [
        {"condition": "D+@0.5", "n_cycles": n, "pairs": "all"}
    ]
    rows = store.query_df("SELECT train_gait FROM results WHERE campaign = 'c'")
    assert summary.total_jobs == 1 and set(rows.train_gait) == {"O"}


def test_cli_skip_infeasible_and_the_report_names_the_cells(
    db, samples, room, monkeypatch, tmp_path
):
    import suds_exp.preprocess as preprocess

    class Version:  # a preprocessing version named v1 whose samples are `samples`
        name = "v1"

        def samples(self, trials=None):
            return samples

    monkeypatch.setattr(preprocess, "get_version", lambda store, ref=None: Version())
    runner = CliRunner()
    base = ["run", "c", "--db", str(db), "--prep", "v1", "--models", "phase-only,TLS"]
    base += ["--boots", "2", "--train-cycles", "2", "--sweep", f"1,{room['best'] + 1}"]
    out = runner.invoke(cli.app, base)
    assert out.exit_code == 2 and "--skip-infeasible" in out.output
    assert len(out.output.strip().splitlines()) == 1
    out = runner.invoke(cli.app, [*base, "--skip-infeasible", "--json"])
    assert out.exit_code == 0, out.output
    doc = json.loads(out.stdout)
    assert doc["skipped_cells"][0]["condition"] == "D+@0.5"
    out = runner.invoke(cli.app, ["status", "c", "--db", str(db), "--json"])
    assert json.loads(out.stdout)["skipped_cells"] == doc["skipped_cells"]
    out = runner.invoke(cli.app, ["report", "c", "--db", str(db), "--out", str(tmp_path / "r")])
    assert out.exit_code == 0, out.output
    page = (tmp_path / "r" / "index.html").read_text()
    assert f"D+@0.5 x {room['best'] + 1} cycles (same-condition pairs)" in page
