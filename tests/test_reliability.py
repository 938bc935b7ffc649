"""Every writing path keeps the promise: one writer at a time, a damaged file
refused, file-system errors and refusals in one line with the database byte-identical,
Ctrl-C and kill -9 ending a campaign and its workers cleanly.

The probe itself is `suds_exp/testing/reliability_probe.py`
(`python -m suds_exp.testing.reliability_probe`
prints the counts of the long version); these tests run a few of its cases, the long ones
marked slow.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import duckdb
import pytest
from typer.testing import CliRunner

import cli
from suds_exp.errors import StoreError
from suds_exp.store import Store
from suds_exp.store import lock as write_lock
from suds_exp.store.engine import lock_holder
from suds_exp.testing import reliability_probe as probe

REPO = Path(__file__).resolve().parents[1]
runner = CliRunner()


@pytest.fixture(scope="module")
def data(tmp_path_factory) -> probe.Data:
    """Synthetic captures (2 gaits x 2 repeats x 12 cycles), ingested and preprocessed."""
    return probe.build(tmp_path_factory.mktemp("reliability"))


def fresh(base: Path, tmp_path: Path) -> Path:
    db = tmp_path / "suds.duckdb"
    shutil.copy(base, db)
    return db


def one_line_refusal(args: list[str], db: Path, says: str = "") -> str:
    """Run ``args`` through the CLI on ``db``: exit 2, one line on stderr containing
    ``says``, no traceback, the file byte-identical; returns the line."""
    before = probe.digest(db)
    res = runner.invoke(cli.app, [*args, "--db", str(db)])
    lines = [x for x in res.stderr.splitlines() if x.strip()]
    assert res.exit_code == 2 and len(lines) == 1, (args, res.output)
    assert "Traceback" not in res.output and says in lines[0], (args, lines[0])
    assert probe.digest(db) == before, args
    return lines[0]


def test_refused_options_leave_the_database_byte_identical_and_names_free(data, tmp_path):
    db = fresh(data.prepped, tmp_path)
    blocker = tmp_path / "a-file"
    blocker.write_text("in the way of a folder\n")
    cases = [
        (["run", "c", "--model-param", "GMR.n_components=abc"], "--model-param"),
        (["run", "c", "--backend", "dask", "--scheduler", "tcp://127.0.0.1:1"], "no dask"),
        (["stream", "s", "--models", "GMR,GradualGMR+SUDS", "--warmup", "3"], "GradualGMR"),
        (["stream", "s", "--change-at", "-5"], "--change-at '-5': expected a time > 0"),
        (["stream", "s", "--change-at", "abc"], "--change-at 'abc': expected a time"),
        (["stream", "s", "--plot", str(blocker / "x.png")], "--plot: folder"),
        (["findings", "c", "--boots", "0"], "--boots 0"),
        (["discrepancy", "--out", str(blocker / "d")], "--out: report folder"),
        (["report", "c", "--out", str(blocker / "r")], "--out: report folder"),
    ]
    t = time.perf_counter()
    for args, says in cases:
        one_line_refusal(args, db, says)
    assert time.perf_counter() - t < 60  # the scheduler is refused at once, not after 30 s
    con = duckdb.connect(str(db), read_only=True)
    assert con.execute("SELECT count(*) FROM campaigns").fetchone()[0] == 0
    assert con.execute("SELECT count(*) FROM streams").fetchone()[0] == 0
    con.close()


def test_a_fixed_model_parameter_then_creates_the_campaign(data, tmp_path):
    """A refused parameter does not take the name: the corrected one is accepted."""
    db = fresh(data.prepped, tmp_path)
    one_line_refusal(["run", "c", "--models", "TLS", "--model-param", "TLS.n_bins=x"], db)
    res = runner.invoke(
        cli.app,
        [
            "run",
            "c",
            "--models",
            "TLS",
            "--model-param",
            "TLS.n_bins=8",
            "--boots",
            "1",
            "--train-cycles",
            "3",
            "-q",
            "--db",
            str(db),
        ],
    )
    assert res.exit_code == 0 and "created" in res.output, res.output


HOLD = """
import sys, time
from suds_exp.store.lock import WriteLock
with WriteLock(sys.argv[1], "preprocess", "v9"):
    print("held", flush=True)
    time.sleep(60)
"""


def test_a_second_writer_is_refused_in_one_line_naming_the_holder(data, tmp_path, monkeypatch):
    db = fresh(data.prepped, tmp_path)
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(db)], cwd=REPO, stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout.readline().strip() == "held"
        monkeypatch.setattr(write_lock, "WRITE_WAIT_S", 0.3)
        named = f"preprocess 'v9' (pid {holder.pid} on "
        for args in (
            ["init"],
            ["ingest", str(data.captures), "--manifest", str(data.manifest)],
            ["preprocess", "--name", "v2", "--param", "k=3"],
            ["run", "c", "--models", "TLS", "--boots", "1", "--train-cycles", "3"],
            ["stream", "s", "--models", "GMR", "--warmup", "3"],
            ["discrepancy", "--name", "d", "--out", str(tmp_path / "d")],
        ):
            line = one_line_refusal(args, db, named)
            assert "another run" not in line and "campaign" not in line
    finally:
        holder.kill()
        holder.wait()


READER = """
import sys, time, duckdb
con = duckdb.connect(sys.argv[1])
print("open", flush=True)
time.sleep(60)
"""


def test_a_process_holding_the_file_is_named_with_its_whole_path_and_pid(tmp_path):
    db = tmp_path / "x.y.duckdb"
    Store(db).upgrade()
    child = subprocess.Popen(
        [sys.executable, "-c", READER, str(db)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert child.stdout.readline().strip() == "open"
        with pytest.raises(duckdb.IOException) as exc:
            duckdb.connect(str(db), read_only=True)
        text = lock_holder(exc.value)
        assert f"pid {child.pid}" in text and text.startswith("/"), text
        assert "." in text.split(", pid")[0]  # the program's path is not cut at a "."
    finally:
        child.kill()
        child.wait()


def test_a_duplicate_that_passes_the_lock_is_refused_by_the_schema_in_one_line(data, tmp_path):
    db = fresh(data.prepped, tmp_path)
    before = probe.dump(db)
    with pytest.raises(StoreError, match="refused a duplicate") as exc, Store(db).write() as c:
        c.exec_driver_sql("INSERT INTO prep_trials SELECT * FROM prep_trials LIMIT 1")
    assert "\n" not in str(exc.value)
    with pytest.raises(StoreError, match="refused a duplicate"), Store(db).write() as c:
        for _ in range(2):
            c.exec_driver_sql(
                "INSERT INTO discrepancy_runs (name, start_model, options, train_trials, "
                "test_trials, started_at) VALUES ('d', '{}', '{}', '[]', '[]', now())"
            )
    assert probe.same(probe.dump(db), before)


def damaged(data: probe.Data, folder: Path) -> dict[str, Path]:
    return probe._damaged_copies(data, folder)


@pytest.mark.parametrize("kind", ["cut at a 4 KiB boundary", "a corrupted block"])
def test_a_damaged_database_is_refused_by_every_command_and_never_written(data, tmp_path, kind):
    db = damaged(data, tmp_path / "damaged")[kind]
    files = sorted(p.name for p in db.parent.iterdir())
    for args in probe.every_command(data, tmp_path):
        one_line_refusal(args, db, "truncated or damaged")
    assert sorted(p.name for p in db.parent.iterdir()) == files  # not even a lock file


def test_a_healthy_database_passes_the_block_check_after_every_kind_of_write(data, tmp_path):
    from suds_exp.store.integrity import _verified, check_file

    db = fresh(data.prepped, tmp_path)
    for args in (
        ["run", "c", "--models", "phase-only,TLS", "--boots", "2", "--train-cycles", "3"],
        ["stream", "s", "--models", "GMR", "--warmup", "3"],
        ["preprocess", "--name", "v2", "--param", "k=3"],
    ):
        assert runner.invoke(cli.app, [*args, "-q", "--db", str(db)]).exit_code == 0
        _verified.clear()
        check_file(db)


@pytest.fixture
def read_only_fs(data):
    with probe.read_only_mount(data.prepped) as point:
        if point is None:
            pytest.skip("cannot mount a read-only tmpfs here (needs root)")
        yield point


def test_a_read_only_file_system_gives_one_line_and_stores_nothing(data, tmp_path, read_only_fs):
    db = read_only_fs / "suds.duckdb"
    for args in (
        ["init"],
        ["ingest", str(data.captures), "--manifest", str(data.manifest)],
        ["preprocess", "--name", "v2", "--param", "k=3"],
        ["run", "c", "--models", "TLS", "--boots", "1"],
        ["stream", "s", "--models", "GMR", "--warmup", "3"],
    ):
        one_line_refusal(args, db, "read-only file system")
    outside = fresh(data.prepped, tmp_path)
    for args in (
        ["report", "c", "--out", str(read_only_fs / "reports" / "c")],
        ["discrepancy", "--out", str(read_only_fs / "reports" / "d")],
        ["stream", "s", "--models", "GMR", "--plot", str(read_only_fs / "reports" / "s.png")],
    ):
        one_line_refusal(args, outside, "read-only file system")


def start_run(db: Path, backend: str, boots: int = 12) -> subprocess.Popen:
    return probe.start(probe.campaign_args(backend, boots), db, db.parent)


def wait_workers(p: subprocess.Popen, n: int = 2, timeout: float = 60) -> set[int]:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        below = probe.descendants(p.pid)
        if len(below) >= n:
            return below
        assert p.poll() is None, p.communicate()
        time.sleep(0.1)
    raise AssertionError("no workers started")


@pytest.mark.skipif(sys.platform != "linux", reason="reads /proc")
def test_kill_9_of_a_loky_run_leaves_no_worker_after_10_s(data, tmp_path):
    """(That the killed run then continues to the same rows: the slow probe below.)"""
    db = fresh(data.prepped, tmp_path)
    p = start_run(db, "loky", boots=4)
    wait_workers(p)
    time.sleep(1.0)
    killed = probe.kill9(p, time.perf_counter())
    assert killed.orphans == 0, f"{killed.orphans} processes alive after 10 s"


@pytest.mark.skipif(os.name != "posix", reason="process groups")
def test_ctrl_c_to_the_process_group_of_a_loky_run_is_one_line_and_status_130(data, tmp_path):
    db = fresh(data.prepped, tmp_path)
    p = start_run(db, "loky")
    wait_workers(p)
    time.sleep(1.0)
    os.killpg(p.pid, signal.SIGINT)
    r = probe.finish(p, time.perf_counter())
    lines = [x for x in (r.stdout + r.stderr).splitlines() if x.strip()]
    assert r.code == 130 and len(lines) == 1 and "stopped" in lines[0], r.stdout + r.stderr


@pytest.mark.slow
@pytest.mark.skipif(os.name != "posix", reason="process groups")
@pytest.mark.parametrize("after_s", [0.5, 3.0])
def test_ctrl_c_to_the_process_group_of_a_dask_run_is_one_line_and_status_130(
    data, tmp_path, after_s
):
    db = fresh(data.prepped, tmp_path)
    p = start_run(db, "dask", boots=60)  # long enough to be running at ``after_s``
    wait_workers(p, 1)
    time.sleep(after_s)  # while the cluster starts, and once it runs
    r, _ = probe.ctrl_c(p, time.perf_counter())
    lines = [x for x in (r.stdout + r.stderr).splitlines() if x.strip()]
    assert r.code == 130 and len(lines) == 1 and "stopped" in lines[0], r.stdout + r.stderr


@pytest.mark.parametrize("offset", [1.4, pytest.param(0.0, marks=pytest.mark.slow)])
def test_two_preprocess_runs_never_store_a_sample_twice(data, tmp_path, offset):
    db = fresh(data.ingested, tmp_path)
    t = time.perf_counter()
    a = probe.start(["preprocess", "--name", "v1"], db, tmp_path)
    time.sleep(offset)
    b = probe.start(["preprocess", "--name", "v1"], db, tmp_path)
    for r in (probe.finish(a, t), probe.finish(b, t)):
        assert r.code == 0 and not r.traceback, r.stderr
    assert probe.duplicates(db) == []
    con = duckdb.connect(str(db), read_only=True)
    assert con.execute("SELECT count(*) FROM prep_trials").fetchone()[0] == 4
    con.close()


@pytest.mark.slow
def test_every_pair_of_writers_at_several_offsets_is_safe(data):
    names = ["init", "ingest", "preprocess", "stream", "run", "discrepancy"]
    tally = probe.probe_pairs(data, [0.0, 0.7, 1.4], names)
    assert tally.ok == tally.total, tally.failures


@pytest.mark.slow
def test_kill_9_at_several_moments_of_every_writer_resumes_identically(data):
    names = ["ingest", "preprocess", "stream", "run", "run-dask", "discrepancy"]
    resumed, orphans = probe.probe_kill(data, [0.25, 0.5, 0.8], names)
    assert resumed.ok == resumed.total, resumed.failures
    assert orphans.ok == orphans.total, orphans.failures


@pytest.mark.slow
def test_every_bad_input_of_the_probe_is_one_line_with_the_database_unchanged(data):
    tally, _ = probe.probe_bad_inputs(data)
    assert tally.ok == tally.total, tally.failures
