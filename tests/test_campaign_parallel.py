"""The same campaign gives the same numbers in-process, on 2 loky workers and on dask."""

from __future__ import annotations

import pandas as pd
import pytest

from suds_exp.campaign import CampaignOptions, run_campaign
from suds_exp.store import Store
from suds_exp.testing.synthetic_samples import synthetic_samples

OPTIONS = dict(models=["phase-only", "TLS+SUDS"], boots=2, train_cycles=3, sweep=[1])
N_JOBS = (9 * 2 + 3 * 2) * 2


@pytest.fixture(scope="module")
def samples() -> pd.DataFrame:
    return synthetic_samples(conditions=(("O", 0.5), ("D+", 1.0), ("S-", 1.0)))


@pytest.fixture(scope="module")
def reference(tmp_path_factory, samples, campaign_rows) -> pd.DataFrame:
    one = Store(tmp_path_factory.mktemp("one") / "one.duckdb")
    run_campaign(one, "c", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    frame = campaign_rows(one)
    assert len(frame) == N_JOBS
    return frame


def run_on(tmp_path, samples, campaign_rows, **kw) -> pd.DataFrame:
    store = Store(tmp_path / "x.duckdb")
    summary = run_campaign(
        store, "c", CampaignOptions(**OPTIONS), samples=samples, chunk_jobs=3, progress=False, **kw
    )
    assert summary.done_now == N_JOBS
    return campaign_rows(store)


def test_two_loky_workers_give_the_rows_of_one(tmp_path, samples, reference, campaign_rows):
    rows = run_on(tmp_path, samples, campaign_rows, jobs=2)
    pd.testing.assert_frame_equal(rows, reference, check_exact=True)


def test_a_two_process_dask_local_cluster_gives_the_rows_of_one_worker(
    tmp_path, samples, reference, campaign_rows
):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        rows = run_on(
            tmp_path,
            samples,
            campaign_rows,
            jobs=2,
            backend="dask",
            scheduler=cluster.scheduler_address,
        )
    pd.testing.assert_frame_equal(rows, reference, check_exact=True)


def test_a_one_thread_dask_cluster_runs_the_jobs_on_its_worker_a_few_draws_a_task(
    tmp_path, samples, reference, campaign_rows
):
    distributed = pytest.importorskip("dask.distributed")
    store = Store(tmp_path / "x.duckdb")
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
        distributed.get_task_stream(client) as stream,
    ):
        summary = run_campaign(
            store,
            "c",
            CampaignOptions(**OPTIONS),
            samples=samples,
            backend="dask",
            scheduler=cluster.scheduler_address,
            progress=False,
        )
        workers = set(client.scheduler_info()["workers"])
    assert summary.done_now == N_JOBS
    pd.testing.assert_frame_equal(campaign_rows(store), reference, check_exact=True)
    # every job ran on the worker, not in this process, in fewer tasks than draws
    tasks = [t for t in stream.data if t["key"].startswith("run_chunk")]
    assert 1 < len(tasks) < N_JOBS // len(OPTIONS["models"])
    assert {t["worker"] for t in tasks} == workers


def test_dask_tasks_hold_a_second_of_jobs_and_shrink_to_a_draw_at_the_end():
    """Tasks of ~1 s at the job time seen so far (few tasks: each costs the scheduler and
    the client milliseconds), the last ones a draw each (the workers finish together)."""
    from suds_exp.campaign.cluster import TaskSizer, regroup

    draws = [[((k,), ["a"] * 5)] for k in range(400)]  # 400 draws of 5 jobs
    sizer = TaskSizer(2000, threads=2)
    sizer.seen([{"fit_seconds": 0.008, "predict_seconds": 0.002}] * 10)  # 10 ms a job
    sizes = [sum(len(names) for _, names in task) for task in regroup(iter(draws), sizer)]
    assert sum(sizes) == 2000
    assert sizes[0] == 100 and sizes[-4:] == [5] * 4
    assert sizes == sorted(sizes, reverse=True) and len(sizes) < 40
