"""Campaigns survive kill -9, and can be watched (status, sql) while another process runs."""

from __future__ import annotations

import json
import signal
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import cli
from suds_exp.campaign import KEY_COLUMNS, CampaignOptions, run_campaign
from suds_exp.store import Store
from suds_exp.testing.synthetic_samples import synthetic_samples

OPTIONS = dict(models=["phase-only", "TLS"], boots=4, train_cycles=3, sweep=[1, 2])


@pytest.fixture(scope="module")
def samples_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("samples") / "samples.parquet"
    synthetic_samples().to_parquet(path)
    return path


def kill_and_resume(
    tmp_path, samples_file, n_kills: int, campaign_rows, start_campaign, wait_batches
) -> None:
    samples = pd.read_parquet(samples_file)
    reference = Store(tmp_path / "reference.duckdb")
    run_campaign(reference, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    expected = campaign_rows(reference)

    db = tmp_path / "killed.duckdb"
    rng = np.random.default_rng(20261121)
    counts = [0]
    for _ in range(n_kills):
        child = start_campaign(samples_file, db, OPTIONS, batch_rows=4)
        wait_batches(child, int(rng.integers(1, 4)))
        time.sleep(float(rng.uniform(0, 0.25)))
        child.send_signal(signal.SIGKILL)
        child.wait()
        child.stdout.close()
        now = campaign_rows(Store(db))
        assert not now.duplicated(list(KEY_COLUMNS[1:])).any()  # one row per job
        assert counts[-1] < len(now) < len(expected)
        counts.append(len(now))
    final = run_campaign(Store(db), "c", samples=samples, progress=False)
    assert final.done_before == counts[-1]
    pd.testing.assert_frame_equal(campaign_rows(Store(db)), expected, check_exact=True)


def test_sigkill_at_five_random_moments_loses_nothing_it_wrote(
    tmp_path, samples_file, campaign_rows, start_campaign, wait_batches
):
    kill_and_resume(tmp_path, samples_file, 5, campaign_rows, start_campaign, wait_batches)


def test_status_and_sql_answer_and_a_second_run_is_refused_while_a_campaign_runs(
    tmp_path, samples_file, start_campaign, wait_batches
):
    db = tmp_path / "busy.duckdb"
    options = dict(OPTIONS, boots=20)
    child = start_campaign(samples_file, db, options, batch_rows=2)
    try:
        wait_batches(child, 2)
        runner = CliRunner()
        out = runner.invoke(cli.app, ["status", "c", "--db", str(db), "--json"])
        assert out.exit_code == 0, out.output
        status = json.loads(out.stdout)
        assert status["running"] and 0 < status["done"] < status["total"]
        assert status["rate_jobs_per_s"] > 0 and status["eta_s"] > 0
        out = runner.invoke(
            cli.app, ["sql", "SELECT count(*) AS n FROM results", "--db", str(db), "--json"]
        )
        assert out.exit_code == 0, out.output
        assert json.loads(out.stdout)[0]["n"] >= status["done"]
        out = runner.invoke(cli.app, ["run", "c", "--db", str(db)])
        assert out.exit_code == 2 and ": run 'c' (pid" in out.output
        assert child.poll() is None
    finally:
        child.send_signal(signal.SIGINT)
        child.wait(timeout=60)
        child.stdout.close()
    # Ctrl-C: the run stopped cleanly, the lock is free and a status says not running
    status = json.loads(
        CliRunner().invoke(cli.app, ["status", "c", "--db", str(db), "--json"]).stdout
    )
    assert not status["running"] and status["done"] < status["total"]
