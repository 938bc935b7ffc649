"""SQL views of migration 004: labels on every pair of conditions, plain-DuckDB access,
and agreement between the views and the Python tables."""

from __future__ import annotations

import itertools
import os
import shutil
import subprocess
import sys
from pathlib import Path

import duckdb
import numpy as np
import pandas as pd
import pytest

from suds_exp.analysis import AnalysisError, iqr_table, load_results
from suds_exp.store import Store
from suds_exp.store.migrate import available_migrations
from suds_exp.testing.synthetic_results import synthetic_results

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


def test_views_run_in_the_stock_duckdb_shell(tmp_path):
    search = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])
    shell = shutil.which("duckdb", path=search)
    if shell is None:
        pytest.skip("no duckdb shell on PATH (the dev extras install it: duckdb-cli)")
    # The shell can be older than the Python library; this file is written in the oldest
    # storage format both read, because the test is about the views' SQL, not the format.
    path = tmp_path / "shell.duckdb"
    con = duckdb.connect(str(path), config={"storage_compatibility_version": "v1.0.0"})
    try:
        for migration in available_migrations():
            con.execute(migration.sql)
        rows = synthetic_results("grid", n_boot=1, seed=3)
        con.register("new_rows", rows)
        con.execute("INSERT INTO results BY NAME SELECT * FROM new_rows")
    finally:
        con.close()
    sql = (
        "SELECT gait_sim, period_rel, count(*) AS n FROM results_labelled GROUP BY ALL "
        "ORDER BY ALL; SELECT count(*) AS n FROM results_iqr; SELECT count(*) AS n FROM "
        "results_categories;"
    )
    out = subprocess.run(
        [shell, "-readonly", "-csv", str(path), "-c", sql],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 0, out.stderr
    lines = out.stdout.split()
    # 5 learners x 25 gait pairs (5 same, 8 near, 12 far) x 9 frequency pairs, of which
    # each period relation <, =, > holds 3.
    expected = [
        f"{g},{p},{5 * k * 3}" for g, k in (("far", 12), ("near", 8), ("same", 5)) for p in "<=>"
    ]
    assert lines[:10] == ["gait_sim,period_rel,n", *expected]
    assert lines[10:] == ["n", str(2 * 3 * 5), "n", str(5 * 2 * 3)]


def test_load_results_in_small_batches_and_a_spilled_sort_is_duckdbs_own_frame(store, monkeypatch):
    from suds_exp.analysis import queries

    expected = load_results(store, "grid")
    # batches of 7 rows under a low memory limit: the same frame, and the
    # database's memory limit given back
    monkeypatch.setattr(queries, "BATCH_ROWS", 7)
    monkeypatch.setattr(queries, "SORT_MEMORY_BYTES", 16 * 2**20)
    got = load_results(store, "grid")
    pd.testing.assert_frame_equal(got, expected, check_exact=True)
    with store.read() as conn:
        raw = conn.connection.driver_connection
        limit = raw.execute("SELECT current_setting('memory_limit')").fetchone()[0]
    assert limit != "16.0 MiB"
    plain = duckdb.connect(str(store.path), read_only=True)
    try:
        order = ["model", "train_gait", "train_frequency_hz", "test_gait",
                 "test_frequency_hz", "n_cycles", "boot"]  # fmt: skip
        direct = plain.execute(
            "SELECT * FROM results_labelled WHERE campaign = 'grid' AND isfinite(ln_rmse_vx) "
            f"ORDER BY {', '.join(order)}"
        ).df()
    finally:
        plain.close()
    np.testing.assert_array_equal(got["rmse_vx"], direct["rmse_vx"])
    assert list(got["model"]) == list(direct["model"])
