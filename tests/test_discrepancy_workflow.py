"""The discrepancy workflow through its public faces: CLI, library, SQL tables, report.

Measured data always takes the real path (simulate -> QTM files -> ingest -> preprocess).
The fast tests share one small dataset with a hidden effect; the sweeps over every
effect, seeds, two effects and the null control are `slow`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.discrepancy import candidates_for
from suds_exp.discrepancy.effects import effect_parameters
from suds_exp.sim.config import SimConfig
from suds_exp.store import Store
from suds_exp.workflows.hidden_effects import (
    HIDDEN,
    demo_discrepancy,
    draw_hidden,
    hidden_effect_run,
)

runner = CliRunner()
TAU = 0.2


@pytest.fixture(scope="module")
def inertia_db(tmp_path_factory, inertia_store) -> Path:
    """A store holding a small dataset simulated with body inertia the nominal model lacks."""
    return inertia_store(tmp_path_factory.mktemp("hidden"), tau_s=TAU, seed=3)


@pytest.fixture(scope="module")
def cli_run(inertia_db, tmp_path_factory, discrepancy_json):
    out = tmp_path_factory.mktemp("report") / "disc"
    return discrepancy_json(inertia_db, out, "--max-effects", "2", "--name", "hidden-inertia")


def test_names_the_hidden_effect_with_an_interval_covering_the_truth(cli_run):
    doc, _ = cli_run
    assert doc["named"], doc["outcome"]
    first = doc["named"][0]
    assert first["effect"] == "body_inertia"
    lo, hi = first["ci"]
    assert lo <= TAU <= hi
    assert doc["gap_after"] <= 0.5 * doc["gap_before"]
    # nothing else is named once the effect is in the model
    assert [n["effect"] for n in doc["named"]] == ["body_inertia"]
    # and its strength is constant: named as the cause, not as a partial explanation
    assert first["role"] == "cause"


def test_run_is_stored_in_the_discrepancy_tables(cli_run, inertia_db):
    doc, _ = cli_run
    store = Store(inertia_db)
    run = store.query_df("SELECT * FROM discrepancy_runs WHERE id = ?", [doc["run_id"]])
    assert run.loc[0, "name"] == "hidden-inertia"
    assert json.loads(run.loc[0, "named_effects"]) == ["body_inertia"]
    train, test = json.loads(run.loc[0, "train_trials"]), json.loads(run.loc[0, "test_trials"])
    assert train and test and not set(train) & set(test)
    steps = store.query_df(
        "SELECT step, decision, accepted, value, ci_low, ci_high FROM discrepancy_steps "
        "WHERE run_id = ? ORDER BY step",
        [doc["run_id"]],
    )
    assert steps.decision.tolist()[0] == "accepted"
    assert steps.decision.tolist()[-1] in ("none_significant", "max_effects")
    cands = store.query_df(
        "SELECT candidate, accepted, significant FROM discrepancy_candidates "
        "WHERE run_id = ? AND step = 0",
        [doc["run_id"]],
    )
    assert cands[cands.accepted].candidate.tolist() == ["body_inertia"]
    views = store.query_df(
        "SELECT DISTINCT view FROM discrepancy_localisation WHERE run_id = ?", [doc["run_id"]]
    )
    assert set(views.view) == {"condition", "phase", "shape", "time"}
    checks = store.query_df(
        "SELECT step, effect, significant, test_loss_constant, test_loss_varying "
        "FROM discrepancy_constancy WHERE run_id = ?",
        [doc["run_id"]],
    )
    assert checks.step.tolist() == [0] and checks.effect.tolist() == ["body_inertia"]
    assert not checks.significant.iloc[0] and checks.test_loss_constant.iloc[0] > 0


def test_report_page_is_self_contained(cli_run):
    _, out = cli_run
    page = (out / "index.html").read_text()
    for name in ("condition.png", "phase.png", "time.png", "shape.png", "example.png"):
        assert (out / name).stat().st_size > 1000
        assert name in page
    assert "http://" not in page and "https://" not in page
    assert (out / "steps.csv").exists() and (out / "candidates.md").exists()


def test_demo_reports_the_hidden_effect_and_the_gap(tmp_path, small_sweep):
    summary = demo_discrepancy("drag_anisotropy", seed=4, out=tmp_path / "rep", **small_sweep)
    (hidden,) = summary["hidden"]
    assert hidden == "drag_anisotropy"
    assert summary["named"][0]["effect"] == "drag_anisotropy"
    assert summary["gap_after"] < summary["gap_before"]
    assert (tmp_path / "rep" / "index.html").exists()


def test_user_errors_exit_2(inertia_db):
    for args in (
        ["--alpha", "2"],
        ["--prep", "nope"],
        ["--trials", "a,b"],
        ["--effect", "warp_drive=3"],
    ):
        res = runner.invoke(app, ["discrepancy", "--db", str(inertia_db), *args])
        assert res.exit_code == 2, (args, res.output)


def test_candidates_are_the_effects_the_model_lacks():
    labels = {c.label for c in candidates_for(SimConfig())}
    assert {
        "hinge_damping",
        "body_inertia",
        "asymmetric_drag",
        "drag_anisotropy",
        "medium_compaction",
        "flippers=locked",
        "flippers=absent",
    } <= labels
    # spoke oscillation is on in the nominal robot: not a missing effect
    assert "spoke_oscillation" not in labels
    cfg = SimConfig()
    cfg.effects.flippers.mode = "absent"
    cfg.effects.hinge_damping.damping = 10.0
    labels = {c.label for c in candidates_for(cfg)}
    assert "flippers=free" in labels and "hinge_damping" not in labels


def test_hidden_values_are_drawn_inside_the_realistic_range_away_from_off():
    rng = np.random.default_rng(1)
    for effect, (_, param) in HIDDEN.items():
        spec = next(p for p in effect_parameters(effect) if p["name"] == param)
        lo, hi = spec["range"]
        off = spec["off"] if not isinstance(spec["off"], str) else lo
        for _ in range(20):
            v = draw_hidden(effect, rng)[param]
            assert lo <= v <= hi
            # at least 35% of the way from "off" to the end of the range on its side
            end = hi if v > off else lo
            assert abs(v - off) >= 0.35 * abs(end - off) - 1e-12


def test_hidden_runs_start_from_a_model_without_the_hidden_effect():
    from suds_exp.workflows.hidden_effects import hidden_models

    truth, start = hidden_models({"spoke_oscillation": {"gain": 2.0}})
    assert truth.effects.spoke_oscillation.gain == 2.0
    assert start.effects.spoke_oscillation.gain == 0.0
    assert "spoke_oscillation" in {c.label for c in candidates_for(start)}
    _, start = hidden_models({})
    assert start.effects.spoke_oscillation.gain == SimConfig().effects.spoke_oscillation.gain


def _residual_windows(rng, passive_signal: float):
    """36 windows of 3 gait cycles, as the slow tests' design (3 gaits x 3 frequencies x
    4 trials) with vx, vy, wz and 4 passive-shape channels: noise everywhere, plus a
    phase-locked error of ``passive_signal`` in the last channel only."""
    phase = np.linspace(0, 6 * np.pi, 200)
    conditions = [(g, f) for g in ("S+", "O", "D+") for f in (1 / 3, 0.5, 1.0)]
    info = pd.DataFrame(
        [
            dict(trial_id=4 * c + k, gait=g, frequency_hz=f)
            for c, (g, f) in enumerate(conditions)
            for k in range(4)
        ]
    )
    residual = rng.normal(size=(len(info), len(phase), 7))
    residual[..., 6] += passive_signal * np.sin(phase)
    halves = (info["trial_id"].to_numpy()[::2], info["trial_id"].to_numpy()[1::2])
    return residual, np.tile(phase, (len(info), 1)), info, halves


def test_a_gap_in_the_passive_shape_alone_is_systematic():
    """The gap is measured on every compared channel, r_p included, so its systematic
    test must look at all of them: a model without the spokes' ringing errs in r_p only."""
    from suds_exp.discrepancy.localise import systematic_gap

    rng = np.random.default_rng(0)
    _, p = systematic_gap(*_residual_windows(rng, passive_signal=3.0))
    assert p < 0.01
    _, p_noise = systematic_gap(*_residual_windows(rng, passive_signal=0.0))
    assert p_noise > 0.01


def test_replay_steps_resolve_the_spoke_ringing_at_slow_gaits():
    """At 40 steps per cycle a 1/3 Hz gait would step every 75 ms; the step is capped so
    the spokes' ~5 Hz ringing (excited by accelerations) survives the replay."""
    import pandas as pd

    from suds_exp.discrepancy.replay import ReplaySettings, make_windows

    rows = []
    for tid, f in ((1, 1 / 3), (2, 1.0)):
        t = np.arange(0, 4 / f, 0.01)
        ph = 2 * np.pi * f * t
        rows.append(
            pd.DataFrame(
                dict(
                    trial_id=tid,
                    t=t,
                    phase=ph,
                    ra_1=0.5 * np.sin(ph),
                    ra_2=0.5 * np.cos(ph),
                    vx=1.0,
                    vy=0.0,
                    wz=0.0,
                    gait="S+",
                    frequency_hz=f,
                )
            )
        )
    windows = make_windows(pd.concat(rows), ReplaySettings())
    assert max(g.dt for g in windows.groups) <= 0.025 + 1e-9
    coarse = make_windows(pd.concat(rows), ReplaySettings(max_step_s=0))
    assert max(g.dt for g in coarse.groups) > 0.07


# -- slow sweeps ------------------------------------------------------------------------

SWEEP = dict(gaits=("S+", "O", "D+"), frequencies_hz=(1 / 3, 0.5, 1.0), repeats=4, cycles=(4, 6))


@pytest.mark.slow
@pytest.mark.parametrize("effect", sorted(HIDDEN))
@pytest.mark.parametrize("seed", [11, 12, 13])
def test_each_hidden_effect_is_named_first(effect, seed, tmp_path):
    rng = np.random.default_rng(seed)
    settings = draw_hidden(effect, rng)
    run = hidden_effect_run({effect: settings}, seed=seed, workdir=tmp_path, **SWEEP)
    named = run.result.named
    assert named and named[0]["effect"] == effect, run.result.outcome
    assert named[0]["role"] == "cause", run.result.steps[0].constancy
    lo, hi = named[0]["ci"]
    truth = run.truth(effect)
    assert lo <= truth <= hi, (truth, named[0])
    assert run.result.gap_after <= 0.5 * run.result.gap_before


@pytest.mark.slow
def test_two_hidden_effects_are_both_named(tmp_path):
    hidden = {"body_inertia": {"tau_s": 0.2}, "drag_anisotropy": {"normal_scale": 1.6}}
    run = hidden_effect_run(hidden, seed=21, workdir=tmp_path, **SWEEP)
    assert set(run.named_effects[:2]) == set(hidden), run.result.outcome
    # earlier-named effects are re-fitted with the later ones in the model
    for named in run.result.named:
        lo, hi = named["ci"]
        assert lo <= run.truth(named["effect"]) <= hi, named


@pytest.mark.slow
@pytest.mark.parametrize("seed", [31, 32, 33])
def test_null_control_names_nothing(seed, tmp_path):
    run = hidden_effect_run({}, seed=seed, workdir=tmp_path, **SWEEP)
    assert run.named_effects == [], run.result.named
