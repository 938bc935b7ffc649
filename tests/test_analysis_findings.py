"""The findings table (F1-F10) on synthetic results whose answers are known.

With no noise every draw of a cell has the same RMS error, so each statistic has an exact
value computable by hand from the planted numbers (on the 100 ln scale: a ratio of two
learners is exp(difference / 100)), and every bootstrap replicate gives that value too.
With noise, the intervals must cover the planted values.
"""

from __future__ import annotations

import csv
import io
import json

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.analysis import load_results
from suds_exp.analysis.findings import FINDINGS, findings, findings_summary, findings_table
from suds_exp.store import Store
from suds_exp.testing.synthetic_results import synthetic_results

# TLS 100, TLS+SUDS 30, GMR 50, GMR+SUDS 20, phase-only 210 (100 ln mm/s) at 30 cycles
PLANTED = {"Intercept": 100.0, "SUDS": -70.0, "GMR": -50.0, "SUDS:GMR": 40.0}
SIZES = (1, 2, 3, 10, 20, 30)
FREQ_POWER = 0.3  # error scaled by (test frequency / Hz) ** 0.3: grows with frequency


def _rows(campaign: str, noise: float = 0.0, seed: int = 1, **kw) -> pd.DataFrame:
    rows = synthetic_results(
        campaign,
        PLANTED,
        n_boot=kw.pop("n_boot", 1),
        n_cycles=kw.pop("n_cycles", SIZES),
        phase_only_offset=110.0,
        noise=noise,
        slopes={"phase-only": 0, "TLS": 0, "TLS+SUDS": 0, "GMR": 0, "GMR+SUDS": -0.5},
        seed=seed,
        **kw,
    )
    rows["rmse_vx"] *= rows["test_frequency_hz"] ** FREQ_POWER
    return rows


@pytest.fixture(scope="module")
def store(tmp_path_factory) -> Store:
    store = Store(tmp_path_factory.mktemp("findings") / "f.duckdb")
    frames = [
        _rows("exact"),
        _rows("noisy", noise=20.0, n_boot=3, n_cycles=(30,), seed=5),
        _rows("nosweep", n_cycles=(30,)),
        _rows("nophase", models=("TLS", "TLS+SUDS", "GMR", "GMR+SUDS")),
    ]
    with store.write() as conn:
        for frame in frames:
            store.insert_df(conn, "results", frame)
    return store


def _by_id(table: pd.DataFrame) -> pd.DataFrame:
    return table.set_index("id")


def test_every_statistic_has_its_hand_computed_value_on_noiseless_results(store):
    t = _by_id(findings(store, "exact", n_boot=20))
    e = np.exp
    # GMR+SUDS at n cycles: 20 - 50 ln(n / 30); "high" sizes are >= 6 (median of 1..30)
    gmrs = {n: 20 - 50 * np.log(n / 30) for n in SIZES}
    expected = {
        "F1": e((210 - 100) / 100),  # phase-only against the worst other learner (TLS)
        "F2": e((210 - 100) / 100),
        "F3": e((100 - 30) / 100),  # same at every size (TLS and TLS+SUDS have no slope)
        "F4": e((100 - 50) / 100),
        "F5": e((50 - gmrs[20]) / 100),  # median of sizes 10, 20, 30 is the 20-cycle one
        "F6": -0.5,
        "F7": (0.5 / (1 / 3)) ** FREQ_POWER,  # the smaller of the two frequency steps
        "F8a": e((30 - 50) / 100),  # TLS+SUDS against GMR at 1-3 cycles
        "F8b": e((gmrs[2] - 30) / 100),  # median of GMR+SUDS at 1, 2, 3 cycles
        "F9a": ((30 - 100) + (20 - 50)) / 2,  # balanced design: the average SUDS effect
        "F9b": ((50 - 100) + (20 - 30)) / 2,
        "F9c": 40.0,
        "F10": e((20 - 50) / 100),
    }
    assert list(t.index) == [f.id for f in FINDINGS]
    for key, value in expected.items():
        assert t.loc[key, "value"] == pytest.approx(value, rel=1e-6, abs=1e-6), key
        # no noise: every bootstrap replicate has the same value
        assert t.loc[key, "low"] == pytest.approx(value, rel=1e-6, abs=1e-6), key
        assert t.loc[key, "high"] == pytest.approx(value, rel=1e-6, abs=1e-6), key
    holds = {"F1", "F2", "F3", "F4", "F5", "F6", "F7", "F8b", "F9a", "F9b", "F9c"}
    for key in t.index:
        assert t.loc[key, "verdict"] == ("holds" if key in holds else "fails"), key
        assert bool(t.loc[key, "holds"]) == (key in holds)
    summary = findings_summary(t.reset_index()).set_index("finding")["verdict"]
    assert summary["F8"] == "fails" and summary["F9"] == "holds" and summary["F10"] == "fails"
    assert len(summary) == 10


def test_intervals_cover_the_planted_values_and_shrink_to_them(store):
    t = _by_id(findings(store, "noisy", n_boot=300, confidence=0.999))
    planted = {"F2": np.exp(1.1), "F4": np.exp(0.5), "F9a": -50.0, "F9b": -30.0, "F9c": 40.0}
    for key, value in planted.items():
        assert t.loc[key, "low"] < value < t.loc[key, "high"], (key, t.loc[key].to_dict())
    # 2025 draws at 30 cycles, sd 20 on 100 ln: the GLM interval is a few units wide
    assert t.loc["F9c", "high"] - t.loc["F9c", "low"] < 15


def test_missing_data_is_not_measurable_with_the_reason(store):
    t = _by_id(findings(store, "nosweep", n_boot=5))
    for key in ("F5", "F6"):
        assert t.loc[key, "verdict"] == "not measurable"
        assert "sweep" in t.loc[key, "reason"] and "--" not in t.loc[key, "reason"]
        assert pd.isna(t.loc[key, "holds"])
        assert np.isnan(t.loc[key, "value"])
    for key in ("F8a", "F8b"):
        assert t.loc[key, "verdict"] == "not measurable" and "3 cycles" in t.loc[key, "reason"]
    assert t.loc["F4", "verdict"] == "holds"
    t = _by_id(findings(store, "nophase", n_boot=5))
    for key in ("F1", "F2"):
        assert t.loc[key, "verdict"] == "not measurable"
        assert t.loc[key, "reason"] == "the campaign has no phase-only results"
    assert findings_summary(t.reset_index()).set_index("finding").loc["F1", "verdict"] == (
        "not measurable"
    )


def test_the_bootstrap_is_reproducible_from_its_seed(store):
    results = load_results(store, "noisy")
    a = findings_table(results, n_boot=30, seed=3)
    b = findings_table(results, n_boot=30, seed=3)
    c = findings_table(results, n_boot=30, seed=4)
    pd.testing.assert_frame_equal(a, b)
    assert not np.allclose(a["low"].dropna(), c["low"].dropna())
    np.testing.assert_allclose(a["value"].dropna(), c["value"].dropna())


def test_cli_findings_json_and_bad_input(store):
    runner = CliRunner()
    out = runner.invoke(
        app, ["findings", "exact", "--db", str(store.path), "--boots", "10", "--json"]
    )
    assert out.exit_code == 0, out.output
    doc = json.loads(out.stdout)
    assert doc["campaign"] == "exact" and doc["main_cycles"] == 30 and doc["n_boot"] == 10
    assert [r["id"] for r in doc["statistics"]] == [f.id for f in FINDINGS]
    assert len(doc["findings"]) == 10
    assert doc["headline"].startswith("8 of 10 findings hold (8 holds, 2 fails)")
    f1 = doc["statistics"][0]
    assert f1["verdict"] == "holds" and f1["holds"] is True and f1["low"] <= f1["value"]
    out = runner.invoke(app, ["findings", "nosweep", "--db", str(store.path), "--boots", "5"])
    assert out.exit_code == 0 and "not measurable" in out.stdout and "F10" in out.stdout
    out = runner.invoke(app, ["findings", "exact", "--db", str(store.path), "--boots", "-1"])
    assert out.exit_code == 2 and "--boots" in out.output and len(out.output.splitlines()) == 1
    out = runner.invoke(app, ["findings", "nope", "--db", str(store.path)])
    assert out.exit_code == 2 and "'nope'" in out.output


def test_cli_findings_csv_gives_each_table_unrounded(store):
    runner = CliRunner()
    args = ["findings", "exact", "--db", str(store.path), "--boots", "10"]
    out = runner.invoke(app, [*args, "--csv"])
    assert out.exit_code == 0, out.output
    rows = list(csv.DictReader(io.StringIO(out.stdout)))
    assert [r["id"] for r in rows] == [f.id for f in FINDINGS]
    doc = json.loads(runner.invoke(app, [*args, "--json"]).stdout)
    assert float(rows[0]["value"]) == doc["statistics"][0]["value"]  # not rounded for show
    # no samples behind these results: the passive table is its header alone
    out = runner.invoke(app, [*args, "--csv", "--table", "passive"])
    assert out.exit_code == 0, out.output
    assert out.stdout.splitlines() == [
        "frequency_hz,n_pairs,rmse_ra,rmse_ra_rp,gain,gain_low,gain_high"
    ]
    out = runner.invoke(app, [*args, "--csv", "--table", "nope"])
    assert out.exit_code == 2 and "--table 'nope'" in out.output
    assert "findings, passive, momentum" in out.output


def test_cli_output_flags_that_contradict_are_refused(store):
    # --table picks the table --csv prints; alone, or beside --json, it would be dropped
    runner = CliRunner()
    args = ["findings", "exact", "--db", str(store.path), "--boots", "10"]
    for extra, named in [
        (["--table", "passive"], "--table"),
        (["--csv", "--json"], "--json"),
        (["--json", "--table", "passive"], "--table"),
    ]:
        out = runner.invoke(app, [*args, *extra])
        assert out.exit_code == 2, (extra, out.output)
        assert named in out.output and len(out.output.splitlines()) == 1
    out = runner.invoke(app, ["sql", "SELECT 1 AS x", "--db", str(store.path), "--json", "--csv"])
    assert out.exit_code == 2 and "--csv" in out.output
