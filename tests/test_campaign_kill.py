"""Campaigns survive kill -9, and can be watched (status, sql) while another process runs."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import cli
from suds_exp.campaign import KEY_COLUMNS, CampaignOptions, run_campaign
from suds_exp.store import Store
from tests.test_campaign_grid import synthetic_samples
from tests.test_campaign_runner import results

REPO = Path(__file__).resolve().parents[1]
OPTIONS = dict(models=["phase-only", "TLS"], boots=4, train_cycles=3, sweep=[1, 2])
CHILD = """
import sys, json, pandas as pd
from suds_exp.campaign import CampaignOptions, run_campaign
from suds_exp.store import Store
samples = pd.read_parquet(sys.argv[1])
options = CampaignOptions(**json.loads(sys.argv[3]))
report = lambda n: print("batch", n, flush=True)
run_campaign(Store(sys.argv[2]), "c", options, samples=samples, progress=False,
             batch_rows=int(sys.argv[4]), flush_seconds=0.2, on_batch=report)
print("done", flush=True)
"""


@pytest.fixture(scope="module")
def samples_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("samples") / "samples.parquet"
    synthetic_samples().to_parquet(path)
    return path


def start(samples_file: Path, db: Path, options: dict, batch_rows: int) -> subprocess.Popen:
    return subprocess.Popen(
        [
            sys.executable,
            "-c",
            CHILD,
            str(samples_file),
            str(db),
            json.dumps(options),
            str(batch_rows),
        ],
        cwd=REPO,
        stdout=subprocess.PIPE,
        text=True,
    )


def wait_batches(child: subprocess.Popen, n: int) -> None:
    for _ in range(n):
        line = child.stdout.readline()
        assert line.startswith("batch"), f"child ended early: {line!r}"


def kill_and_resume(tmp_path, samples_file, n_kills: int) -> None:
    samples = pd.read_parquet(samples_file)
    reference = Store(tmp_path / "reference.duckdb")
    run_campaign(reference, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    expected = results(reference)

    db = tmp_path / "killed.duckdb"
    rng = np.random.default_rng(20261121)
    counts = [0]
    for _ in range(n_kills):
        child = start(samples_file, db, OPTIONS, batch_rows=4)
        wait_batches(child, int(rng.integers(1, 4)))
        time.sleep(float(rng.uniform(0, 0.25)))
        child.send_signal(signal.SIGKILL)
        child.wait()
        child.stdout.close()
        now = results(Store(db))
        assert not now.duplicated(list(KEY_COLUMNS[1:])).any()  # one row per job
        assert counts[-1] < len(now) < len(expected)
        counts.append(len(now))
    final = run_campaign(Store(db), "c", samples=samples, progress=False)
    assert final.done_before == counts[-1]
    pd.testing.assert_frame_equal(results(Store(db)), expected, check_exact=True)


def test_sigkill_at_five_random_moments_loses_nothing_it_wrote(tmp_path, samples_file):
    kill_and_resume(tmp_path, samples_file, n_kills=5)


def test_status_and_sql_answer_and_a_second_run_is_refused_while_a_campaign_runs(
    tmp_path, samples_file
):
    db = tmp_path / "busy.duckdb"
    options = dict(OPTIONS, boots=20)
    child = start(samples_file, db, options, batch_rows=2)
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
