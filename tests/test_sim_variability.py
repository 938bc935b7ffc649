"""The variability a real granular robot has: compliant servos, a bed drawn per trial,
hinge friction per flipper, and a design that always feeds the paper's sweep."""

from __future__ import annotations

import collections

import numpy as np
import pytest

from suds_exp.errors import ConfigError
from suds_exp.sim import SimConfig, effect_library, plan_trials, set_effect, simulate_prescribed
from suds_exp.sim.bed import bed_multiplier, draw_bed
from suds_exp.sim.gaits import gait_shape

DT = 0.01
#: The variability of issue 17 switched on (off in the nominal robot).
VARIABILITY = (
    "servo.compliance_rad_per_n_m=0.05",
    "bed_heterogeneity.spatial_cv=0.2",
    "bed_packing.trial_cv=0.15",
    "hinge_friction.torque_n_mm=10",
)


def _varied(*more: str) -> SimConfig:
    cfg = SimConfig()
    for item in VARIABILITY + more:
        cfg = set_effect(cfg, item)
    return cfg


def _command(freq: float, seconds: float) -> np.ndarray:
    t = np.arange(int(round(seconds / DT)) + 1) * DT
    return gait_shape("O", 2 * np.pi * freq * t)


def test_servo_lags_under_load_more_at_high_frequency():
    cfg = _varied()
    lag = {}
    for f in (1 / 3, 1.0):
        cmd = _command(f, 3 / f)
        out = simulate_prescribed(cmd, DT, cfg, commanded=True)
        assert np.isfinite(out["phi"]).all()
        lag[f] = float(np.sqrt(np.mean((out["phi"] - cmd) ** 2)))
        # the realised stroke is smaller than the commanded one
        assert np.ptp(out["phi"][:, 0]) < np.ptp(cmd[:, 0])
    assert lag[1 / 3] > 0.02
    assert lag[1.0] > 1.5 * lag[1 / 3]


def test_stiff_servo_and_replay_follow_the_angles_exactly():
    cmd = _command(0.5, 2.0)
    stiff = _varied("servo=off")
    for cfg, commanded in ((stiff, True), (_varied(), False)):
        out = simulate_prescribed(cmd, DT, cfg, commanded=commanded)
        assert np.array_equal(out["phi"], cmd)


def test_servo_stall_torque_limits_the_stroke():
    cmd = _command(0.5, 4.0)
    strokes = []
    for stall in (1.0, 6.0):
        cfg = _varied(f"servo.stall_torque_n_m={stall}")
        strokes.append(np.ptp(simulate_prescribed(cmd, DT, cfg, commanded=True)["phi"][:, 0]))
    assert strokes[0] < strokes[1] - 0.1


def test_bed_field_is_deterministic_per_seed_and_differs_between_seeds():
    cmd = _command(0.5, 4.0)
    cfg = _varied()
    a = simulate_prescribed(cmd, DT, cfg, commanded=True, trial_seeds=[(1, 2)])
    b = simulate_prescribed(cmd, DT, cfg, commanded=True, trial_seeds=[(1, 2)])
    c = simulate_prescribed(cmd, DT, cfg, commanded=True, trial_seeds=[(1, 3)])
    assert np.array_equal(a["pose"], b["pose"])
    assert np.abs(a["pose"][-1, :2] - c["pose"][-1, :2]).max() > 1.0
    # the servo feels the bed: a different bed, a different realised stroke
    assert np.abs(a["phi"] - c["phi"]).max() > 1e-3


def test_bed_field_has_mean_one_its_cv_and_its_correlation_length():
    cfg = _varied("bed_heterogeneity.spatial_cv=0.3", "bed_packing=off")
    near, far, values = [], [], []
    rng = np.random.default_rng(0)
    for seed in range(200):
        modes, scale = draw_bed(cfg, (seed,))
        assert scale == 1.0
        p = rng.uniform(-500, 500, size=2)
        pts = np.array([p, p + [10.0, 0.0], p + [0.0, 1500.0]])
        m = bed_multiplier(modes, scale, pts)
        values.append(m[0])
        near.append(m[:2])
        far.append(m[[0, 2]])
    values = np.array(values)
    assert abs(values.mean() - 1.0) < 0.06
    assert 0.2 < values.std() / values.mean() < 0.4
    near, far = np.array(near), np.array(far)
    assert np.corrcoef(near.T)[0, 1] > 0.9
    assert abs(np.corrcoef(far.T)[0, 1]) < 0.3
    # no seed: the mean bed
    modes, scale = draw_bed(cfg, None)
    assert np.allclose(bed_multiplier(modes, scale, np.zeros((3, 2))), 1.0)


def test_hinge_friction_differs_from_flipper_to_flipper():
    cmd = _command(0.5, 4.0)
    even = _varied("hinge_friction.spread=0")
    base = simulate_prescribed(cmd, DT, even)["flippers"]
    mirror = simulate_prescribed(-cmd, DT, even)["flippers"][:, [1, 0, 3, 2]]
    # equal hinges: the mirrored drive mirrors the flippers
    assert np.abs(base - mirror).max() < 1e-6
    uneven = simulate_prescribed(cmd, DT, _varied())["flippers"]
    uneven_m = simulate_prescribed(-cmd, DT, _varied())["flippers"][:, [1, 0, 3, 2]]
    assert np.abs(uneven - uneven_m).max() > 1e-3


@pytest.mark.parametrize(
    "item",
    ["servo.compliance_rad_per_n_m=2", "bed_heterogeneity.correlation_mm=5", "hinge_friction=-1"],
)
def test_out_of_range_values_name_the_parameter_and_range(item):
    with pytest.raises(ConfigError, match=r"effects\.\w+\.\w+: .* outside its range"):
        set_effect(SimConfig(), item)


def test_library_says_what_a_replay_does_with_each_effect():
    replay = {e["name"]: e["replay"] for e in effect_library()}
    assert replay["servo"] == "none"
    assert replay["bed_heterogeneity"] == replay["bed_packing"] == "mean"
    assert replay["hinge_friction"] == "exact"


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 17])
def test_default_design_leaves_48_cycles_outside_any_test_trial(seed):
    cycles = collections.defaultdict(list)
    for spec in plan_trials(seed=seed):
        assert 10 <= spec.n_cycles <= 30
        cycles[(spec.gait, spec.frequency_hz)].append(spec.n_cycles)
    for counts in cycles.values():
        # each trial loses at most its partial first and last cycle
        assert sum(counts) - min(counts) - 2 * (len(counts) - 1) >= 48
