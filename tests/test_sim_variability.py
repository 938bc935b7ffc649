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
#: The robot's variability effects switched on (off in the nominal robot).
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
    assert np.abs(a["pose"][-1, :2] - c["pose"][-1, :2]).max() > 0.1
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
    [
        "servo.compliance_rad_per_n_m=2",
        "bed_heterogeneity.correlation_mm=5",
        "hinge_friction=-1",
        "grain_contacts.cv=1.5",
        "grain_contacts.correlation_mm=100",
        "bed_depth.correlation_mm=10",
    ],
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


def _uniform_bed(cfg: SimConfig) -> SimConfig:
    for item in ("bed_depth=off", "bed_packing=off", "bed_heterogeneity=off"):
        cfg = set_effect(cfg, item)
    return cfg


def test_bed_depth_leaves_a_rigid_robot_with_locked_flippers_unchanged():
    # a common factor on every element's drag: quasi-static RFT is scale free
    cmd = _command(0.5, 4.0)
    rigid = _uniform_bed(set_effect(set_effect(SimConfig(), "flippers=locked"), "servo=off"))
    deep = set_effect(rigid, "bed_depth.cv=0.4")
    a = simulate_prescribed(cmd, DT, rigid, commanded=True, trial_seeds=[(4, 1)])
    b = simulate_prescribed(cmd, DT, deep, commanded=True, trial_seeds=[(4, 1)])
    assert np.abs(a["pose"] - b["pose"]).max() < 1e-6


def test_bed_depth_loads_compliant_servos_differently_along_the_tub():
    cmd = _command(0.5, 8.0)
    servo = _uniform_bed(set_effect(SimConfig(), "servo.compliance_rad_per_n_m=0.2"))
    deep = set_effect(servo, "bed_depth.cv=0.4")
    lag = []
    for cfg in (servo, deep):
        out = simulate_prescribed(cmd, DT, cfg, commanded=True, trial_seeds=[(4, 1)])
        err = np.sqrt(((out["phi"] - cmd) ** 2).sum(axis=1))
        cycles = err[: 4 * 200].reshape(4, 200).mean(axis=1)
        lag.append(cycles)
    # the servo lags by the same amount every cycle on a uniform bed, not on a varied one
    assert np.ptp(lag[0][1:]) < 0.01
    assert np.ptp(lag[1][1:]) > 3 * np.ptp(lag[0][1:])


def test_bed_depth_field_is_a_body_scale_factor_of_mean_one():
    cfg = set_effect(_uniform_bed(SimConfig()), "bed_depth.cv=0.3")
    values = []
    for seed in range(300):
        modes, scale = draw_bed(cfg, (seed,))
        values.append(bed_multiplier(modes, scale, np.zeros((2, 2)), body_xy=[50.0, -20.0])[0])
        # without a local field the factor is the same at every element of the robot
        spread = bed_multiplier(modes, scale, np.array([[-160.0, 0.0], [160.0, 0.0]]), [0, 0])
        assert spread[0] == pytest.approx(spread[1])
    values = np.array(values)
    assert abs(values.mean() - 1.0) < 0.05
    assert 0.22 < values.std() < 0.38


def test_grain_contacts_are_deterministic_per_seed_and_absent_from_a_replay():
    cmd = _command(0.5, 4.0)
    cfg = set_effect(SimConfig(), "grain_contacts.cv=0.5")
    nominal = set_effect(cfg, "grain_contacts=off")
    a = simulate_prescribed(cmd, DT, cfg, commanded=True, trial_seeds=[(2, 1)])
    b = simulate_prescribed(cmd, DT, cfg, commanded=True, trial_seeds=[(2, 1)])
    c = simulate_prescribed(cmd, DT, cfg, commanded=True, trial_seeds=[(2, 2)])
    assert np.array_equal(a["vel"], b["vel"])
    assert np.abs(a["vel"] - c["vel"]).max() > 1.0
    # a replay cannot know the grains a trial met: it sees the mean medium
    replay = simulate_prescribed(cmd, DT, cfg)
    assert np.array_equal(replay["vel"], simulate_prescribed(cmd, DT, nominal)["vel"])


def test_grain_contacts_keep_the_motion_rate_independent():
    # the contacts renew with slip distance, not time: the same shape path driven three
    # times slower takes the body along the same path
    # rigid servos: a servo's back-EMF is a rate, which would rightly break the symmetry
    cfg = set_effect(_uniform_bed(SimConfig()), "grain_contacts.cv=0.5")
    cfg = set_effect(set_effect(cfg, "flippers=locked"), "servo=off")
    t_fast = np.arange(301) * DT
    t_slow = np.arange(901) * DT
    fast = gait_shape("O", 2 * np.pi * 1.0 * t_fast)
    slow = gait_shape("O", 2 * np.pi * (1 / 3) * t_slow)
    a = simulate_prescribed(fast, DT, cfg, commanded=True, trial_seeds=[(9,)])
    b = simulate_prescribed(slow, DT, cfg, commanded=True, trial_seeds=[(9,)])
    end = np.abs(a["pose"][-1, :2] - b["pose"][-1, :2]).max()
    travelled = np.abs(a["pose"][-1, :2] - a["pose"][0, :2]).max()
    assert end < 0.03 * travelled
    # and the fluctuations do move it: with the grains off the path differs
    off = simulate_prescribed(fast, DT, set_effect(cfg, "grain_contacts=off"), commanded=True)
    assert np.abs(off["pose"][-1, :2] - a["pose"][-1, :2]).max() > 5 * end


def test_library_lists_the_new_effects_with_sourced_ranges():
    lib = {e["name"]: e for e in effect_library()}
    for name in ("grain_contacts", "bed_depth"):
        assert lib[name]["replay"] == "mean"
        assert lib[name]["nominal_state"] in ("on", "off")
        main = next(p for p in lib[name]["parameters"] if p["name"] == lib[name]["main"])
        assert main["range"][0] == 0.0 and main["range"][1] > 0
        assert "(" in main["description"]  # a source in brackets


def test_calibrated_example_is_a_valid_config_with_the_variability_on():
    from pathlib import Path

    from suds_exp.sim.config import load_config

    path = Path(__file__).resolve().parents[1] / "examples" / "calibrated_robot.toml"
    state = {e["name"]: e["state"] for e in effect_library(load_config(path))}
    assert state["servo"] == state["bed_depth"] == state["bed_packing"] == "on"
