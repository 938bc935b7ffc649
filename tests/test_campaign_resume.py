"""Resuming costs what is left to do, not what is done: the finished jobs stay in DuckDB."""

from __future__ import annotations

import tracemalloc

import pandas as pd
import pytest

from suds_exp.campaign import CampaignOptions, enumerate_draws, run_campaign
from suds_exp.campaign.bank import rounded_conditions
from suds_exp.campaign.job import RESULT_COLUMNS
from suds_exp.store import Store
from suds_exp.testing import synthetic_results
from suds_exp.testing.synthetic_samples import synthetic_samples

MODELS = ["phase-only", "TLS"]


@pytest.fixture(scope="module")
def samples() -> pd.DataFrame:
    return synthetic_samples()


def finished_rows(samples: pd.DataFrame, campaign: str, boots: int) -> pd.DataFrame:
    """One stored-looking row for every job of the campaign's grid (no learner runs)."""
    have = rounded_conditions(samples)
    keys = [(d, m) for d in enumerate_draws(campaign, have, have, boots, 4, []) for m in MODELS]
    return synthetic_results.finished_rows(keys, campaign, 4)[list(RESULT_COLUMNS)]


def resume_peak(store: Store, campaign: str, samples: pd.DataFrame):
    """The summary of a re-run and the peak of Python memory it allocated, in bytes."""
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        summary = run_campaign(store, campaign, samples=samples, progress=False)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return summary, peak


def test_resuming_a_finished_campaign_does_not_load_its_finished_jobs(db, samples):
    store = Store(db)
    store.upgrade()
    sizes = {"small": 10, "big": 600}  # 320 and 19,200 finished jobs
    for name, boots in sizes.items():
        with store.write() as conn:
            store.insert_df(conn, "results", finished_rows(samples, name, boots))
        options = CampaignOptions(models=MODELS, boots=boots, train_cycles=4)
        created = run_campaign(store, name, options, samples=samples, progress=False)
        assert created.done_now == 0 and created.remaining == 0
    run_campaign(store, "small", samples=samples, progress=False)  # imports, caches
    small, small_peak = resume_peak(store, "small", samples)
    big, big_peak = resume_peak(store, "big", samples)
    assert (small.done_before, big.done_before) == (320, 19_200)
    assert big.remaining == 0 and "already done" in big.message()
    # A set of the finished keys takes ~200 bytes of Python objects a job (~4 MB here);
    # counting them in DuckDB costs nothing per job on this side.
    assert big_peak - small_peak < 1_000_000, (small_peak, big_peak)


def test_only_the_jobs_left_are_run_and_nothing_is_stored_twice(db, samples):
    store = Store(db)
    store.upgrade()
    rows = finished_rows(samples, "c", 3)
    # a row of another campaign with the same job key, and one outside the grid, count
    # for nothing
    stray = rows.iloc[:2].assign(campaign=["other", "c"], boot=[0, 99])
    left = rows["boot"].eq(2) & rows["model"].eq("TLS")
    with store.write() as conn:
        store.insert_df(conn, "results", pd.concat([rows[~left], stray], ignore_index=True))
    options = CampaignOptions(models=MODELS, boots=3, train_cycles=4)
    summary = run_campaign(store, "c", options, samples=samples, progress=False)
    assert summary.done_before == int((~left).sum())
    assert summary.done_now == int(left.sum()) and summary.remaining == 0
    counts = store.query_df(
        "SELECT boot, model, count(*) AS n, count(DISTINCT (train_gait, train_frequency_hz, "
        "test_gait, test_frequency_hz)) AS pairs FROM results WHERE campaign = 'c' "
        "AND boot < 3 GROUP BY ALL ORDER BY ALL"
    )
    assert counts["n"].eq(counts["pairs"]).all() and counts["n"].nunique() == 1
    ran = store.query_df(
        "SELECT count(*) AS n FROM results WHERE campaign = 'c' AND fit_seconds <> 0.1"
    )["n"].item()
    assert ran == int(left.sum())
