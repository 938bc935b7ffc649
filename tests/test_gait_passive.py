"""What the passive shape adds (`passive_information`), planted and absent, and in
`suds-exp findings --json`."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.analysis.passive import PASSIVE_COLUMNS, passive_information
from suds_exp.store import Store
from suds_exp.testing.synthetic_results import synthetic_results


def smooth(rng, sd: float, n: int) -> np.ndarray:
    """A smooth random series (n,): white noise of sd through a 40-sample mean."""
    return np.convolve(rng.normal(0, sd, n + 40), np.ones(40) / 40, "valid")[:n]


def synthetic_samples(rp_weight: float, seed: int = 0) -> pd.DataFrame:
    """Two gaits x two frequencies x 4 trials of 8 cycles (100 samples each): r_a on a
    circle with smooth random deviations, r_p smooth random (independent of r_a), and
    vx = 20 + 5 cos(2 phase) + 4 (r_a deviation) + rp_weight (r_p) + noise (mm/s)."""
    rng = np.random.default_rng(seed)
    rows, tid = [], 0
    for gait in ("O", "D+"):
        for f in (0.5, 1.0):
            for _ in range(4):
                tid += 1
                n = 800
                phase = 2 * np.pi * np.arange(n) / 100
                dev, rp = smooth(rng, 0.6, n), smooth(rng, 3.0, n)
                vx = 20 + 5 * np.cos(2 * phase) + 4 * dev + rp_weight * rp + rng.normal(0, 0.3, n)
                rows.append(
                    pd.DataFrame(
                        {
                            "trial_id": tid,
                            "frame": np.arange(n),
                            "t": np.arange(n) / (100 * f),
                            "phase": phase,
                            "cycle": np.arange(n) // 100,
                            "ra_1": np.cos(phase) + dev,
                            "ra_2": np.sin(phase),
                            "dra_1": -np.sin(phase),
                            "dra_2": np.cos(phase),
                            "rp_1": rp,
                            "vx": vx,
                            "gait": gait,
                            "frequency_hz": f,
                        }
                    )
                )
    return pd.concat(rows, ignore_index=True)


def test_planted_passive_information_gives_a_gain_and_none_gives_about_one():
    with_rp = passive_information(synthetic_samples(2.0), n_boot=50, order=4)
    without = passive_information(synthetic_samples(0.0), n_boot=50, order=4)
    assert list(with_rp.columns) == list(PASSIVE_COLUMNS)
    assert list(with_rp["frequency_hz"]) == [0.5, 1.0]
    assert (with_rp["n_pairs"] == 2 * 12).all()
    assert (with_rp["gain_low"] > 2).all()
    assert (without["gain"] < 1.1).all() and (without["gain_low"] < 1.05).all()
    assert (with_rp["gain_low"] <= with_rp["gain"]).all()
    assert (with_rp["gain"] <= with_rp["gain_high"]).all()


def test_findings_json_has_passive_information_even_without_samples(tmp_path):
    store = Store(tmp_path / "f.duckdb")
    rows = synthetic_results("synthetic", seed=1)
    with store.write() as conn:
        store.insert_df(conn, "results", rows)
    r = CliRunner().invoke(
        app, ["findings", "synthetic", "--db", str(store.path), "--boot", "5", "--json"]
    )
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert doc["passive_information"] == []
    r = CliRunner().invoke(app, ["findings", "synthetic", "--db", str(store.path), "--boot", "5"])
    assert "what the passive shape adds: not measurable" in r.stdout


@pytest.mark.parametrize("bad", [{"n_boot": 5, "order": 2}])
def test_no_passive_columns_is_an_error(bad):
    from suds_exp.errors import AnalysisError

    frame = synthetic_samples(0.0).drop(columns=["rp_1"])
    with pytest.raises(AnalysisError, match="no passive shape"):
        passive_information(frame, **bad)
