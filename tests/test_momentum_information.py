"""What the velocity history adds (`momentum_information`): "helps" on a swimmer whose
body lags, "does not help" on one that does not, and in `findings --json`."""

from __future__ import annotations

import json

import pandas as pd
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.analysis.momentum_info import MOMENTUM_COLUMNS, momentum_information
from suds_exp.store import Store
from suds_exp.testing.synthetic_results import synthetic_results
from suds_exp.testing.synthetic_swimmer import make_samples

FREQUENCIES = (1 / 3, 1 / 2, 1.0)


def swimmers(body_tau: float):
    """Two trials at each of the paper's frequencies and each trial's frequency."""
    frames = [
        make_samples(
            6,
            frequency_hz=f,
            n_trials=2,
            seed=i,
            body_tau=body_tau,
            passive="none",
            first_trial_id=1 + 2 * i,
        )
        for i, f in enumerate(FREQUENCIES)
    ]
    samples = pd.concat(frames, ignore_index=True)
    return samples, samples.groupby("trial_id")["frequency_hz"].first()


@pytest.mark.slow
def test_helps_with_a_lag_and_does_not_without():
    lag = momentum_information(*swimmers(0.3), n_boot=100)
    none = momentum_information(*swimmers(0.0), n_boot=100)
    assert list(lag.columns) == list(MOMENTUM_COLUMNS)
    assert list(lag["held_out_hz"]) == ["0.333", "0.5", "1", "all"]
    overall = lag.iloc[-1]
    assert overall["verdict"] == "helps" and overall["ratio_high"] < 1
    assert overall["tau_vx_s"] == pytest.approx(0.3, rel=0.2)
    # the one time constant that best predicts each held-out speed
    assert set(lag["tau_s"]) == {overall["tau_s"]}
    assert overall["tau_s"] == pytest.approx(0.3, rel=0.2)
    assert none.iloc[-1]["verdict"] == "does not help"
    assert none.iloc[-1]["tau_s"] < 0.05
    assert none.iloc[-1]["ratio_low"] >= 0.95


def test_one_frequency_is_not_measurable():
    samples, freq = swimmers(0.3)
    one = samples[samples["frequency_hz"] == 0.5]
    assert momentum_information(one, freq, n_boot=10).empty


def test_findings_json_has_momentum_information_even_without_samples(tmp_path):
    store = Store(tmp_path / "f.duckdb")
    with store.write() as conn:
        store.insert_df(conn, "results", synthetic_results("synthetic", seed=1))
    args = ["findings", "synthetic", "--db", str(store.path), "--boot", "5"]
    r = CliRunner().invoke(app, [*args, "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["momentum_information"] == []
    r = CliRunner().invoke(app, args)
    assert "what the velocity history adds: not measurable" in r.stdout
