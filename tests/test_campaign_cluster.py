"""A campaign on a real dask cluster over TCP (scheduler and workers as separate processes
on 127.0.0.1) survives a killed worker and a killed scheduler: the run that loses its
scheduler says so in one line with exit status 3 and the resume hint, and the re-run
gives the rows of a local run."""

from __future__ import annotations

import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

import cli
from suds_exp.store import Store

pytestmark = pytest.mark.slow

BIN = Path(sys.executable).parent
RUN = ["run", "c", "--models", "phase-only,TLS", "--boots", "60", "--train-cycles", "2", "-q"]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _scheduler(port: int) -> subprocess.Popen:
    cmd = [str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port)]
    cmd += ["--dashboard-address", "127.0.0.1:0"]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _worker(address: str) -> subprocess.Popen:
    cmd = [
        str(BIN / "dask"),
        "worker",
        address,
        "--nthreads",
        "1",
        "--host",
        "127.0.0.1",
        "--preload",
        "suds_exp.campaign.dask_worker",
    ]
    cmd += ["--dashboard-address", "127.0.0.1:0", "--no-nanny"]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _kill(*procs: subprocess.Popen) -> None:
    for p in procs:
        if p.poll() is None:
            p.send_signal(signal.SIGKILL)
        p.wait(timeout=30)


def _wait_for(address: str, n_workers: int) -> None:
    from dask.distributed import Client

    with Client(address, timeout=30) as client:
        client.wait_for_workers(n_workers, timeout=60)


def _n_tasks(dask_scheduler) -> int:
    return len(dask_scheduler.tasks)


def _wait_for_tasks(address: str, child: subprocess.Popen, timeout_s: float = 180) -> None:
    """Until the run's client has given the scheduler tasks (a loaded machine takes its
    time to start ``suds-exp run``: a fixed wait would kill the cluster before it connects)."""
    from dask.distributed import Client

    with Client(address, timeout=30) as client:
        deadline = time.monotonic() + timeout_s
        while client.run_on_scheduler(_n_tasks) == 0:
            assert child.poll() is None, child.communicate()
            assert time.monotonic() < deadline, "the run gave the scheduler no task"
            time.sleep(0.2)


@pytest.fixture(scope="module")
def version_db(tmp_path_factory) -> Path:
    pytest.importorskip("dask.distributed")
    folder = tmp_path_factory.mktemp("cluster")
    db = folder / "base.duckdb"
    runner = CliRunner()
    args = ["simulate", "--out", str(folder / "sim"), "--gaits", "O,S+", "--freqs", "1/2,1"]
    args += ["--repeats", "2", "--cycles", "4", "--ingest", "--db", str(db), "-q"]
    assert runner.invoke(cli.app, args).exit_code == 0
    assert runner.invoke(cli.app, ["preprocess", "--db", str(db), "-q"]).exit_code == 0
    return db


def test_a_killed_worker_and_a_killed_scheduler_lose_nothing(tmp_path, version_db, campaign_rows):
    local = tmp_path / "local.duckdb"
    shutil.copy(version_db, local)
    out = CliRunner().invoke(cli.app, [*RUN, "--db", str(local)])
    assert out.exit_code == 0, out.output
    expected = campaign_rows(Store(local))

    db = tmp_path / "cluster.duckdb"
    shutil.copy(version_db, db)
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    scheduler = _scheduler(port)
    workers = [_worker(address) for _ in range(2)]
    try:
        _wait_for(address, 2)
        cmd = [str(BIN / "suds-exp"), *RUN, "--db", str(db), "--backend", "dask"]
        cmd += ["--scheduler", address]
        child = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        _wait_for_tasks(address, child)
        time.sleep(2)
        _kill(workers[0])  # its jobs go to the other worker
        time.sleep(5)
        assert child.poll() is None, child.communicate()
        _kill(scheduler)
        _, err = child.communicate(timeout=120)
    finally:
        _kill(scheduler, *workers)
    lines = err.strip().splitlines()
    assert child.returncode == 3, err
    assert len(lines) <= 3, err
    assert "dask cluster lost" in err and "run the same command to continue" in err

    scheduler = _scheduler(port)
    workers = [_worker(address) for _ in range(2)]
    try:
        _wait_for(address, 2)
        again = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    finally:
        _kill(scheduler, *workers)
    assert again.returncode == 0, again.stderr
    pd.testing.assert_frame_equal(campaign_rows(Store(db)), expected, check_exact=True)
