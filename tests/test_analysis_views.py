"""SQL views of migration 004: labels on every pair of conditions, plain-DuckDB access,
and agreement between the views and the Python tables."""

from __future__ import annotations

import itertools

import duckdb
import numpy as np
import pandas as pd
import pytest

from suds_exp.analysis import AnalysisError, iqr_table, load_results, synthetic_results
from suds_exp.store import Store

GAITS = ["S+", "S-", "O", "D-", "D+"]
FREQS = [0.333333, 0.5, 1.0]

# Written out by hand (not computed) so the view is checked against the definition:
# same = 0 steps on S+, S-, O, D-, D+; near = 1 step; far = more.
GAIT_SIM = {
    "S+": {"S+": "same", "S-": "near", "O": "far", "D-": "far", "D+": "far"},
    "S-": {"S+": "near", "S-": "same", "O": "near", "D-": "far", "D+": "far"},
    "O": {"S+": "far", "S-": "near", "O": "same", "D-": "near", "D+": "far"},
    "D-": {"S+": "far", "S-": "far", "O": "near", "D-": "same", "D+": "near"},
    "D+": {"S+": "far", "S-": "far", "O": "far", "D-": "near", "D+": "same"},
}
# (train Hz, test Hz) -> model-period (1/train) against data-period (1/test).
PERIOD_REL = {
    (0.333333, 0.333333): "=", (0.333333, 0.5): ">", (0.333333, 1.0): ">",
    (0.5, 0.333333): "<", (0.5, 0.5): "=", (0.5, 1.0): ">",
    (1.0, 0.333333): "<", (1.0, 0.5): "<", (1.0, 1.0): "=",
}  # fmt: skip
FLAGS = {  # model -> (suds, gmr, phase_only)
    "phase-only": (False, False, True),
    "TLS": (False, False, False),
    "TLS+SUDS": (True, False, False),
    "GMR": (False, True, False),
    "GMR+SUDS": (True, True, False),
}


@pytest.fixture
def store(tmp_path) -> Store:
    store = Store(tmp_path / "views.duckdb")
    rows = synthetic_results("grid", n_boot=1, seed=3)
    with store.write() as conn:
        store.insert_df(conn, "results", rows)
    return store


def test_every_pair_of_the_15_conditions_is_labelled_as_defined(store):
    got = store.query_df(
        "SELECT model, train_gait, train_frequency_hz, test_gait, test_frequency_hz, gait_steps, "
        "gait_sim, period_rel, freq_sim, suds, gmr, phase_only, model_period_s, data_period_s "
        "FROM results_labelled WHERE campaign = 'grid'"
    )
    conditions = list(itertools.product(GAITS, FREQS))
    assert len(got) == len(FLAGS) * 15 * 15
    seen = set()
    for r in got.itertuples():
        key = (r.train_gait, r.train_frequency_hz, r.test_gait, r.test_frequency_hz)
        seen.add(key)
        assert r.gait_sim == GAIT_SIM[r.train_gait][r.test_gait], key
        assert r.gait_steps == abs(GAITS.index(r.train_gait) - GAITS.index(r.test_gait)), key
        assert r.period_rel == PERIOD_REL[(r.train_frequency_hz, r.test_frequency_hz)], key
        assert r.freq_sim == ("same" if r.period_rel == "=" else "different"), key
        assert (r.suds, r.gmr, r.phase_only) == FLAGS[r.model], r.model
        assert r.model_period_s == pytest.approx(1 / r.train_frequency_hz)
        assert r.data_period_s == pytest.approx(1 / r.test_frequency_hz)
    assert seen == {(a, b, c, d) for (a, b), (c, d) in itertools.product(conditions, conditions)}


def test_views_work_from_a_plain_duckdb_connection(store):
    # What the stock `duckdb` CLI does: open the file, no suds-exp code involved.
    con = duckdb.connect(str(store.path), read_only=True)
    try:
        counts = dict(
            con.sql("SELECT gait_sim, count(*) FROM results_labelled GROUP BY ALL").fetchall()
        )
        axis = con.sql("SELECT gait FROM gait_axis ORDER BY position").fetchall()
        cats = con.execute("SELECT count(*) FROM results_categories").fetchall()[0][0]
    finally:
        con.close()
    # Per (train, test) gait pair x 3 x 3 frequencies x 5 learners: 5 same, 8 near, 12 far.
    assert counts == {"same": 5 * 45, "near": 8 * 45, "far": 12 * 45}
    assert [a for (a,) in axis] == GAITS
    assert cats == 5 * 2 * 3  # learners x freq_sim x gait_sim (one training size)


@pytest.mark.parametrize("pairs", ["same-condition", "same-frequency"])
def test_iqr_view_agrees_with_the_python_table(store, pairs):
    view = store.query_df(
        "SELECT * FROM results_iqr WHERE campaign = 'grid' AND pairs = ?", [pairs]
    )
    table = iqr_table(load_results(store, "grid"), pairs=pairs)
    merged = table.merge(
        view.assign(frequency_hz=view["frequency_hz"].round(6)),
        on=["frequency_hz", "model", "n_cycles"],
        suffixes=("", "_view"),
    )
    assert len(merged) == len(table) == len(view) == 3 * 5
    # Per frequency and learner: 5 same-condition pairs, or 25 gait pairings.
    assert (merged["n"] == {"same-condition": 5, "same-frequency": 25}[pairs]).all()
    for col in ("n", "q1", "median", "q3", "iqr"):
        np.testing.assert_allclose(merged[col], merged[f"{col}_view"], rtol=1e-12)


def test_failed_jobs_are_left_out_and_unknown_campaigns_refused(store):
    bad = synthetic_results("broken", n_boot=1, models=("TLS",), seed=4).head(3)
    bad["rmse_vx"] = [np.nan, 0.0, 2.0]
    with store.write() as conn:
        store.insert_df(conn, "results", bad)
    assert load_results(store, "broken")["rmse_vx"].tolist() == [2.0]
    with pytest.raises(AnalysisError, match="'nope'.*grid"):
        load_results(store, "nope")
    assert isinstance(load_results(store, "grid"), pd.DataFrame)
