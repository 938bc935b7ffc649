"""Physics invariants of the granular RFT swimmer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from suds_exp.sim import (
    EFFECT_NAMES,
    GAITS,
    SimConfig,
    effect_library,
    gait_shape,
    residual_units,
    set_effect,
    simulate_prescribed,
    truth_markers,
)

DT = 0.01


def gait_path(gait: str, freq: float, cycles: float, dt: float = DT, phase0: float = 0.3):
    t = np.arange(0, cycles / freq + dt / 2, dt)
    return gait_shape(gait, 2 * math.pi * freq * t + phase0)


def test_no_shape_change_and_relaxed_springs_gives_no_motion():
    phi = np.tile([0.4, -0.7], (300, 1))
    for effects in ([], ["hinge_damping=on", "body_inertia=on", "asymmetric_drag=on"]):
        cfg = SimConfig()
        for e in effects:
            cfg = set_effect(cfg, e)
        out = simulate_prescribed(phi, DT, cfg, pose0=[10.0, -5.0, 0.2])
        assert np.allclose(out["pose"], [10.0, -5.0, 0.2], atol=1e-9, rtol=0)
        assert np.abs(out["vel"]).max() < 1e-9
        assert np.all(out["flippers"] == 0.0)


def test_rate_independence_twice_as_fast_doubles_body_velocity():
    # same path sampled at the same points: f at dt, 2f at dt/2
    cfg = SimConfig()
    slow = simulate_prescribed(gait_path("D+", 0.5, 2.0, DT), DT, cfg)
    fast = simulate_prescribed(gait_path("D+", 1.0, 2.0, DT / 2), DT / 2, cfg)
    assert slow["pose"].shape == fast["pose"].shape
    scale = np.abs(slow["vel"]).max(axis=0)
    assert np.allclose(fast["vel"], 2 * slow["vel"], atol=1e-4 * scale.max(), rtol=0)
    assert np.allclose(fast["pose"], slow["pose"], atol=1e-4)
    assert np.allclose(fast["flippers"], slow["flippers"], atol=1e-6)
    # flippers must have moved, or the check above says little about the hinges
    assert slow["flippers"].max() > 0.3


def test_rate_dependence_appears_with_damping_or_inertia():
    for effect in ("hinge_damping=on", "body_inertia=on"):
        cfg = set_effect(SimConfig(), effect)
        slow = simulate_prescribed(gait_path("O", 0.5, 2.0, DT), DT, cfg)
        fast = simulate_prescribed(gait_path("O", 1.0, 2.0, DT / 2), DT / 2, cfg)
        assert np.abs(fast["vel"] - 2 * slow["vel"]).max() > 1.0, effect


def test_mirror_symmetry():
    phi = gait_path("S+", 1.0, 3.0)
    flippers0 = np.array([0.2, 0.5, 0.0, 0.3])
    out = simulate_prescribed(phi, DT, SimConfig(), flippers0=flippers0)
    mir = simulate_prescribed(-phi, DT, SimConfig(), flippers0=flippers0[[1, 0, 3, 2]])
    sign = np.array([1.0, -1.0, -1.0])
    assert np.allclose(mir["pose"], out["pose"] * sign, atol=1e-5)
    assert np.allclose(mir["vel"], out["vel"] * sign, atol=1e-4)
    assert np.allclose(mir["flippers"], out["flippers"][:, [1, 0, 3, 2]], atol=1e-7)
    assert np.abs(out["pose"][-1, :2]).max() > 10  # it did move


def test_force_torque_residual_of_every_step_below_tolerance():
    cfg = SimConfig()
    force_n, torque_nmm = residual_units(cfg)
    phis = np.stack([gait_path(g, 1.0, 3.0) for g in GAITS])
    out = simulate_prescribed(phis, DT, cfg)
    worst = np.nanmax(out["residual"])
    # stated tolerance: cfg.solver.tol scaled units = 1e-8 * 6 N (forces), * 600 N mm
    assert worst <= cfg.solver.tol
    assert worst * force_n < 1e-6 and worst * torque_nmm < 1e-4


def test_flipper_angles_stay_within_stops():
    cfg = SimConfig()
    amax = math.radians(cfg.hinges.open_stop_deg)
    paths = [gait_path(g, f, 3.0) for g in ("O", "D+") for f in (1 / 3, 1.0)]
    n = min(len(p) for p in paths)
    phis = np.stack([p[:n] for p in paths])
    out = simulate_prescribed(phis, DT, cfg, flippers0=np.full((4, 4), 3.0))
    fl = out["flippers"]
    assert fl.min() >= 0.0 and fl.max() <= amax + 1e-12
    assert np.isclose(fl.max(), amax)  # some flipper reaches its open stop
    assert (fl == 0.0).any()  # and some rests closed


def _motion(cfg, freqs=(1 / 3, 1.0), drive=False):
    """Velocities and markers of an O gait; drive=True: the path is the servo command
    and the trial has a bed of its own (what effects acting there need)."""
    res = []
    for f in freqs:
        out = simulate_prescribed(
            gait_path("O", f, 4.0),
            DT,
            cfg,
            pose0=[0, 0, 0],
            commanded=drive,
            trial_seeds=[(7,)] if drive else None,
        )
        markers = truth_markers(
            {
                "x": out["pose"][:, 0],
                "y": out["pose"][:, 1],
                "theta": out["pose"][:, 2],
                "phi1": out["phi"][:, 0],
                "phi2": out["phi"][:, 1],
                **{f"flipper_{i + 1}": out["flippers"][:, i] for i in range(4)},
            },
            cfg,
        )
        res.append((out["vel"], markers))
    return res


@pytest.fixture(scope="module")
def nominal_motion():
    return _motion(SimConfig())


@pytest.fixture(scope="module")
def nominal_driven():
    return _motion(SimConfig(), drive=True)


@pytest.mark.parametrize("name", EFFECT_NAMES)
def test_each_effect_on_changes_motion_and_off_does_not(name, nominal_motion, nominal_driven):
    spec = next(e for e in effect_library() if e["name"] == name)
    if spec["replay"] != "exact":
        # servo, bed: a replay of joint angles without the trial's seed cannot see them
        on_replay = _motion(set_effect(SimConfig(), f"{name}=on"))
        for (v, m), (v0, m0) in zip(on_replay, nominal_motion, strict=True):
            assert np.array_equal(v, v0) and np.array_equal(m, m0)
        nominal_motion = nominal_driven
    on = _motion(set_effect(SimConfig(), f"{name}=on"), drive=spec["replay"] != "exact")
    if name == "spoke_oscillation":
        # a measurement effect: body motion unchanged, spoke markers move differently
        off = _motion(set_effect(SimConfig(), f"{name}=off"))
        for (v_on, m_on), (v_off, m_off) in zip(on, off, strict=True):
            assert np.array_equal(v_on, v_off)
            assert np.abs(m_on - m_off).max() > 0.5
            assert np.abs(m_on[:, [0, 1, 3, 4, 6]] - m_off[:, [0, 1, 3, 4, 6]]).max() == 0
        return
    changed = max(np.abs(v - v0).max() for (v, _), (v0, _) in zip(on, nominal_motion, strict=True))
    assert changed > 1.0, f"{name} on did not change the body velocity"
    if spec["nominal_state"] == "off":
        off = _motion(
            set_effect(set_effect(SimConfig(), f"{name}=on"), f"{name}=off"),
            drive=spec["replay"] != "exact",
        )
        for (v, m), (v0, m0) in zip(off, nominal_motion, strict=True):
            assert np.array_equal(v, v0) and np.array_equal(m, m0)


def test_effects_change_motion_in_distinguishable_ways(nominal_motion):
    """...among the effects a replay of measured angles can see (the candidates)."""
    signatures = {}
    for spec in effect_library():
        name = spec["name"]
        if name == "spoke_oscillation" or spec["replay"] != "exact":
            continue
        on = _motion(set_effect(SimConfig(), f"{name}=on"))
        d = np.concatenate(
            [(v - v0).ravel() for (v, _), (v0, _) in zip(on, nominal_motion, strict=True)]
        )
        signatures[name] = d / np.linalg.norm(d)
    names = list(signatures)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            corr = abs(float(signatures[a] @ signatures[b]))
            assert corr < 0.95, f"{a} and {b} change the motion alike (|corr| {corr:.3f})"


def test_flippers_matter():
    locked = set_effect(SimConfig(), "flippers=locked")
    free = simulate_prescribed(gait_path("O", 0.5, 4.0), DT, SimConfig())
    lock = simulate_prescribed(gait_path("O", 0.5, 4.0), DT, locked)
    vx_free, vx_lock = free["vel"][200:, 0].mean(), lock["vel"][200:, 0].mean()
    assert abs(vx_free - vx_lock) > 0.05 * abs(vx_lock)


def test_batched_trials_equal_single_trials():
    cfg = SimConfig()
    a = gait_path("O", 1.0, 2.0)
    b = gait_path("S-", 0.5, 1.0)[: len(a) - 50]
    batch = np.zeros((2, len(a), 2))
    batch[0], batch[1, : len(b)] = a, b
    out = simulate_prescribed(batch, DT, cfg, n_frames=[len(a), len(b)])
    one = simulate_prescribed(b, DT, cfg)
    assert np.array_equal(out["vel"][1, : len(b)], one["vel"])
    assert np.isnan(out["vel"][1, len(b) :]).all()


@pytest.mark.slow
def test_default_dataset_physics_converges_and_keeps_flippers_within_stops():
    from suds_exp.sim import plan_trials, simulate_trials

    cfg = SimConfig()
    specs = plan_trials()
    truths = simulate_trials(specs, cfg)
    assert max(np.nanmax(t["residual"]) for t in truths) <= cfg.solver.tol
    amax = math.radians(cfg.hinges.open_stop_deg)
    for t in truths:
        fl = np.column_stack([t[f"flipper_{i}"] for i in range(1, 5)])
        assert fl.min() >= 0 and fl.max() <= amax + 1e-12
    # its speed (target 300x real time per core) is measured by benchmarks/speed/sim.py
