"""Scheduled effects, prequential streams, drift alarms, kill and resume of a stream."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import cli
from suds_exp.errors import ConfigError
from suds_exp.sim.schedule import Change, parse_change
from suds_exp.store import Store
from suds_exp.stream import (
    TIMING_COLUMNS,
    PageHinkley,
    StreamSettings,
    run_stream,
    run_trial,
    simulate_stream_samples,
    stream_rows,
    summarise,
)

REPO = Path(__file__).resolve().parents[1]
JAM_AT = 25.0
#: The stated alarm delay bound for a flipper jam, s after the change (at 1 Hz).
MAX_ALARM_DELAY_S = 10.0
FAST = dict(n_components=8)


@pytest.fixture(scope="module")
def jam():
    """A 1-Hz trial of gait O whose flippers jam closed at 25 s, and an unchanged one."""
    changed = simulate_stream_samples("O", 1.0, 50, [Change("flippers=locked", JAM_AT)], seeds=[0])
    steady = simulate_stream_samples("O", 1.0, 50, [], seeds=[1])
    return changed, steady


def test_schedules_parse_and_bad_ones_are_one_line_errors(tmp_path):
    assert parse_change("flippers=locked@40s") == Change("flippers=locked", 40.0)
    assert parse_change("hinge_damping.damping=80 @ 12.5") == Change(
        "hinge_damping.damping=80", 12.5
    )
    for text, match in [
        ("flippers=locked", "NAME=VALUE@TIME"),
        ("gravity=on@40s", "effect 'gravity'"),
        ("flippers=locked@-3s", "must be > 0"),
        ("flippers=jammed@40s", "flippers"),
    ]:
        with pytest.raises(ConfigError, match=match):
            parse_change(text)
    runner = CliRunner()
    base = ["simulate", "--out", str(tmp_path / "x"), "--gaits", "O", "--freqs", "1"]
    out = runner.invoke(
        cli.app, [*base, "--repeats", "1", "--cycles", "10", "--effect", "flippers=locked@40s"]
    )
    assert out.exit_code == 2
    assert "40 s is past the end of trial sim_O_1000mHz_r01" in out.output
    assert len(out.output.strip().splitlines()) == 1
    assert not list((tmp_path / "x").glob("*.tsv"))
    out = runner.invoke(cli.app, [*base, "--effect", "bogus=1@4s"])
    assert out.exit_code == 2 and "effect 'bogus'" in out.output


def test_a_jam_changes_the_physics_only_after_its_time(jam):
    changed, _ = jam
    nominal = simulate_stream_samples("O", 1.0, 50, [], seeds=[0])
    a = changed[changed["trial_id"] == 1].reset_index(drop=True)
    before = a["t"] < JAM_AT
    np.testing.assert_allclose(a.loc[before, "vx"], nominal.loc[before, "vx"], rtol=0, atol=1e-9)
    after = a["t"] > JAM_AT + 1
    # flippers held closed from the jam on, while the nominal ones keep opening
    assert np.abs(a.loc[after, ["rp_1", "rp_2", "rp_3", "rp_4"]].to_numpy()).max() < 1e-6
    assert nominal.loc[after, ["rp_1", "rp_3"]].to_numpy().max() > 0.2
    assert abs(a.loc[after, "vx"].mean() - nominal.loc[after, "vx"].mean()) > 0.2 * abs(
        nominal.loc[after, "vx"].mean()
    )


def test_a_jam_is_alarmed_and_the_online_learner_recovers_while_the_batch_one_does_not(jam):
    changed, steady = jam
    settings = StreamSettings()
    rows = []
    for tid, trial in pd.concat([changed, steady]).groupby("trial_id"):
        for model, params in (("GMR", FAST), ("OnlineGMR", FAST)):
            r = run_trial(trial, model, params, settings)
            r["change_s"] = JAM_AT if tid == 1 else None
            rows.append(r)
    summary = summarise(pd.concat(rows, ignore_index=True))
    online, batch = summary["models"]["OnlineGMR"], summary["models"]["GMR"]
    assert online["recovered"] == 1 and batch["recovered"] == 0, summary["models"]
    assert batch["alarmed"] == 1 and batch["alarm_delay_s_median"] <= MAX_ALARM_DELAY_S
    assert online["alarmed"] == 1 and online["alarm_delay_s_median"] <= MAX_ALARM_DELAY_S
    assert batch["false_alarm_rate"] == 0 and online["false_alarm_rate"] == 0


def test_page_hinkley_alarms_on_a_rise_and_not_on_a_steady_or_falling_error():
    rng = np.random.default_rng(0)
    steady = np.exp(0.2 * rng.standard_normal(200))
    ph = PageHinkley()
    assert not any(ph.update(x)[1] for x in steady)
    ph = PageHinkley()
    assert not any(ph.update(x)[1] for x in np.geomspace(10, 1, 50))
    ph = PageHinkley()
    alarms = [ph.update(x)[1] for x in np.r_[steady[:30], 2.5 * steady[30:60]]]
    assert not any(alarms[:30]) and 30 <= alarms.index(True) < 36


CHILD = """
import sys, pandas as pd
from suds_exp.store import Store
from suds_exp.stream import run_stream
samples = pd.read_parquet(sys.argv[1])
run_stream(Store(sys.argv[2]), "s", ["GMR", "OnlineGMR"], change_at=20.0, samples=samples,
           progress=False, on_unit=lambda n: print("unit", n, flush=True))
print("done", flush=True)
"""


def cycles_table(store: Store) -> pd.DataFrame:
    return stream_rows(store, "s").drop(columns=list(TIMING_COLUMNS))


def test_kill_and_resume_of_a_stream_gives_identical_rows(tmp_path, jam):
    changed, _ = jam
    samples = changed[changed["t"] < 30].reset_index(drop=True)
    path = tmp_path / "samples.parquet"
    samples.to_parquet(path)
    reference = Store(tmp_path / "reference.duckdb")
    run_stream(
        reference, "s", ["GMR", "OnlineGMR"], change_at=20.0, samples=samples, progress=False
    )
    expected = cycles_table(reference)
    assert len(expected) == 2 * 20 and expected["change_s"].eq(20.0).all()

    db = tmp_path / "killed.duckdb"
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(path), str(db)],
        cwd=REPO,
        stdout=subprocess.PIPE,
        text=True,
    )
    line = child.stdout.readline()
    assert line.startswith("unit"), line
    child.send_signal(signal.SIGKILL)
    child.wait()
    child.stdout.close()
    partial = cycles_table(Store(db))
    assert 0 < len(partial) < len(expected)
    again = run_stream(
        Store(db), "s", ["GMR", "OnlineGMR"], change_at=20.0, samples=samples, progress=False
    )
    assert again.done_before == 1 and again.done_now == 1
    pd.testing.assert_frame_equal(cycles_table(Store(db)), expected, check_exact=True)
    # a continuation with other options is refused, naming the difference
    with pytest.raises(Exception, match="different definition"):
        run_stream(Store(db), "s", ["GMR"], change_at=20.0, samples=samples, progress=False)


@pytest.mark.slow
def test_stream_command_on_simulated_captures(tmp_path):
    runner = CliRunner()
    db = str(tmp_path / "s.duckdb")
    out = runner.invoke(
        cli.app,
        [
            "simulate",
            "--out",
            str(tmp_path / "sim"),
            "--gaits",
            "O",
            "--freqs",
            "1",
            "--repeats",
            "1",
            "--cycles",
            "30",
            "--effect",
            "medium_compaction=on@20s",
            "--ingest",
            "--db",
            db,
        ],
    )
    assert out.exit_code == 0, out.output
    assert runner.invoke(cli.app, ["preprocess", "--db", db, "-q"]).exit_code == 0
    png = tmp_path / "err.png"
    out = runner.invoke(
        cli.app,
        ["stream", "jam", "--models", "GMR,OnlineGMR", "--db", db, "--json", "--plot", str(png)],
    )
    assert out.exit_code == 0, out.output
    doc = json.loads(out.stdout)
    assert doc["run"]["done_now"] == 2 and png.is_file()
    assert {t["change_s"] for t in doc["trials"]} == {20.0}
    assert doc["models"]["GMR"]["alarmed"] == 1
    out = runner.invoke(cli.app, ["stream", "late", "--db", db, "--change-at", "500"])
    assert out.exit_code == 2 and "past the end of trial" in out.output


@pytest.mark.slow
def test_no_alarm_on_unchanged_streams_in_at_least_95_percent_of_20_seeds():
    steady = simulate_stream_samples("O", 1.0, 40, [], seeds=list(range(100, 120)))
    rows = [
        run_trial(trial, model, FAST, StreamSettings())
        for _, trial in steady.groupby("trial_id")
        for model in ("GMR", "OnlineGMR")
    ]
    rows = pd.concat(rows, ignore_index=True)
    rows["change_s"] = None
    for model, m in summarise(rows)["models"].items():
        assert m["trials"] == 20
        assert m["false_alarm_rate"] <= 0.05, (model, m)
