"""A worker's pieces: sample frames from the bank, learners checked once, the prediction
read for the RMS error, and a run stopped inside a chunk of draws (library API, SQL)."""

from __future__ import annotations

import dataclasses
import signal
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from suds_exp.campaign import CampaignOptions, SampleBank, job, run_campaign
from suds_exp.campaign.job import predicted_velocity
from suds_exp.errors import ConfigError
from suds_exp.models import TLS, make_model
from suds_exp.robot import VB_COLUMNS
from suds_exp.store import Store
from suds_exp.testing.synthetic_samples import synthetic_samples


@pytest.fixture(scope="module")
def bank() -> SampleBank:
    return SampleBank.build(synthetic_samples(conditions=(("O", 0.5), ("O", 1.0))))


def frame_by_column(bank: SampleBank, pieces: list[np.ndarray]) -> pd.DataFrame:
    """The samples frame of ``pieces`` built one array per column."""
    data = np.concatenate(pieces)
    columns = {c: data[:, j] for j, c in enumerate(bank.columns)}
    for c in ("trial_id", "frame", "cycle"):
        columns[c] = columns[c].astype(np.int64)
    return pd.DataFrame(columns)


def test_a_sample_frame_holds_the_bank_rows_of_its_cycles(bank):
    (a, _), (c, _) = bank.runs[0][0], bank.runs[1][0]
    pieces = [bank.rows(0, a, a + 1), bank.rows(1, c, c)]
    frame = bank.frame(pieces)
    pd.testing.assert_frame_equal(frame, frame_by_column(bank, pieces), check_exact=True)
    assert set(frame.cycle[: len(pieces[0])]) == {a, a + 1}
    assert set(frame.cycle[len(pieces[0]) :]) == {c}
    # a learner's shallow copy may gain or overwrite columns: the next learner sees none
    copy = frame.copy(deep=False)
    copy["extra"] = 1.0
    copy["vx"] = 0.0
    pd.testing.assert_frame_equal(frame, frame_by_column(bank, pieces), check_exact=True)


def test_rows_of_a_trial_whose_cycles_do_not_ascend_are_found_too(bank):
    a, _ = bank.runs[0][0]
    col = bank.columns.index("cycle")
    lo, hi = bank.row_start[0], bank.row_stop[0]
    values = bank.values.copy()
    values[lo:hi] = values[lo:hi][::-1]  # the trial's rows in reverse time order
    reversed_bank = dataclasses.replace(bank, values=values)
    block = values[lo:hi]
    expected = block[(block[:, col] >= a) & (block[:, col] <= a + 1)]
    assert len(expected) > 0
    np.testing.assert_array_equal(reversed_bank.rows(0, a, a + 1), expected)
    np.testing.assert_array_equal(bank.rows(0, a, a + 1), expected[::-1])


def _prediction_frames():
    rng = np.random.default_rng(0)
    v = rng.standard_normal((50, 5))
    plain = pd.DataFrame(v, columns=["vx", "vy", "wz", "drp_1", "drp_2"])
    shuffled = plain[["drp_2", "wz", "vx", "drp_1", "vy"]]
    labelled = plain.assign(label="a", vy=np.arange(50))  # a str and an int column
    doubled = pd.DataFrame(v, columns=["vx", "vy", "wz", "x", "x"])
    return [plain, shuffled, labelled, doubled]


@pytest.mark.parametrize("pred", _prediction_frames())
def test_the_predicted_velocity_is_read_by_column_name(pred):
    expected = np.column_stack([pred[c].to_numpy(dtype=float) for c in VB_COLUMNS])
    got = predicted_velocity(pred)
    np.testing.assert_array_equal(got, expected)
    assert got.dtype == np.float64 and got.flags.c_contiguous


def test_a_prediction_without_a_velocity_column_fails_naming_it():
    with pytest.raises(KeyError, match="wz"):
        predicted_velocity(pd.DataFrame({"vx": [1.0], "vy": [2.0]}))


def test_a_learner_is_checked_once_then_built_like_make_model():
    first = make_model("TLS", ridge=1e-6)
    again = make_model("TLS", ridge=1e-3)
    assert again is not first and again.get_params() == TLS(ridge=1e-3).get_params()
    with pytest.raises(ConfigError, match="unknown parameter"):
        make_model("TLS", ridge=1e-6, nonsense=1)


def test_a_run_stopped_inside_a_chunk_resumes_with_every_row_once(
    tmp_path, monkeypatch, campaign_rows
):
    samples = synthetic_samples(conditions=(("O", 0.5), ("D+", 1.0)))
    options = CampaignOptions(models=["phase-only", "TLS"], boots=2, train_cycles=3, sweep=[1])
    full = Store(tmp_path / "full.duckdb")
    run_campaign(full, "c", options, samples=samples, progress=False)

    draws = 0
    make_draw = job.draw_sample

    def ctrl_c_at_the_fifth_draw(*args):
        nonlocal draws
        draws += 1
        if draws == 5:  # the second draw of the second chunk (three draws a chunk)
            signal.raise_signal(signal.SIGINT)
        return make_draw(*args)

    monkeypatch.setattr(job, "draw_sample", ctrl_c_at_the_fifth_draw)
    store = Store(tmp_path / "x.duckdb")
    stopped = run_campaign(store, "c", options, samples=samples, chunk_jobs=6, progress=False)
    assert stopped.interrupted and stopped.done_now == 6  # the first chunk's rows only
    monkeypatch.undo()

    again = run_campaign(store, "c", samples=samples, progress=False)
    assert again.done_before == 6 and again.done_now == again.total_jobs - 6
    pd.testing.assert_frame_equal(campaign_rows(store), campaign_rows(full), check_exact=True)


_FAULTS = """
import resource, sys, threading
import numpy as np
from suds_exp.campaign.job import settle_allocator

def arrays(out):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(200):
        a = np.ones(100_000)  # 800 KB, as a job's frames
        b = a * 2
        del a, b
    out.append(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)

def in_a_thread():  # a dask worker runs its tasks in a thread
    out = []
    t = threading.Thread(target=arrays, args=(out,))
    t.start()
    t.join()
    return out[0]

in_a_thread()
fixed = in_a_thread()
settled = settle_allocator()
in_a_thread()
print(fixed, settled, in_a_thread())
"""


def test_a_worker_with_the_nannys_trim_threshold_stops_faulting_its_arrays_in(tmp_path):
    """dask's nanny starts workers with MALLOC_TRIM_THRESHOLD_=65536; then each array of a
    job in the worker's task thread faults its pages in anew, until the allocator is
    settled (page faults counted, not timed)."""
    import os
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root)}
    for trim, expect_settled in (("65536", True), (None, False)):
        env.pop("MALLOC_TRIM_THRESHOLD_", None)
        if trim:
            env["MALLOC_TRIM_THRESHOLD_"] = trim
        out = subprocess.run(
            [sys.executable, "-c", _FAULTS], env=env, capture_output=True, text=True, check=True
        )
        fixed, settled, after = out.stdout.split()
        assert (settled == "True") is expect_settled
        if trim:
            assert int(fixed) > 20_000 and int(after) < 1_000, out.stdout
        else:
            assert int(fixed) < 1_000, out.stdout


def _chores(dask_worker) -> tuple:
    """Whether the worker samples its task thread's stack, and how often (ms) its event
    loop wakes for its tick, its system monitor and its memory monitor."""
    every = {
        name: dask_worker.periodic_callbacks[name].callback_time
        for name in ("tick", "monitor", "memory_monitor")
        if name in dask_worker.periodic_callbacks
    }
    return "profile" in dask_worker.periodic_callbacks, every


def test_a_preloaded_dask_worker_runs_no_profiler_and_wakes_its_loop_less():
    """Workers started with the preload (as the local cluster and the how-to start them)
    do not sample their task thread's stack, and their event loop wakes at most once a
    second for its chores (dask: every 20, 100 and 500 ms); others keep dask's defaults
    (the check can fail)."""
    pytest.importorskip("distributed")
    from dask.distributed import Client, LocalCluster

    ran = {}
    for preload in ([], ["suds_exp.campaign.dask_worker"]):
        with (
            LocalCluster(
                n_workers=1,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                preload=preload,
            ) as cluster,
            Client(cluster) as client,
        ):
            ran[bool(preload)] = list(client.run(_chores).values())
    [(profiles, default)] = ran[False]
    assert profiles and default == {"tick": 20, "monitor": 500, "memory_monitor": 100}
    [(profiles, quiet)] = ran[True]
    assert not profiles and quiet.keys() == default.keys()
    assert all(quiet[name] >= 1000 for name in quiet), quiet


def test_a_chunk_runs_blas_on_one_thread_and_gives_the_pools_back(bank, monkeypatch):
    """``blas="block"`` (a dask task): every BLAS and OpenMP pool at one thread while the
    chunk's draws run, as the caller had them after, call after call."""
    from threadpoolctl import threadpool_info, threadpool_limits

    def threads() -> list[int]:
        return [pool["num_threads"] for pool in threadpool_info()]

    seen = []
    monkeypatch.setattr(job, "run_draw", lambda *args: seen.append(set(threads())) or [])
    with threadpool_limits(limits=2):
        for _ in range(3):
            assert job.run_chunk(bank, [(None, ["TLS"])], {}, 1, blas="block") == []
            assert set(threads()) == {2}
    assert seen == [{1}] * 3
