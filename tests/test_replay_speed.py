"""The demo's fast paths give the same numbers: the simulator's trials run in parallel
without sharing state, the replay's window configurations equal deep-copied ones, and the
smoothing's interior does not depend on how its edges are fitted."""

from __future__ import annotations

import copy
import dataclasses

import numba
import numpy as np
from scipy.signal import savgol_filter

from suds_exp.discrepancy.replay import _window_configs
from suds_exp.sim.config import SimConfig
from suds_exp.sim.mechanics import simulate_prescribed


def _batch():
    t = np.arange(120) * 0.01
    phi = np.stack(
        [
            np.stack([0.8 * np.cos(2 * np.pi * t + i), 0.7 * np.sin(2 * np.pi * t)], -1)
            for i in range(5)
        ]
    )
    configs = []
    for i in range(5):
        c = SimConfig()
        c.effects.body_inertia.tau_s = (0.0, 0.2, 0.0, 0.4, 0.1)[i]
        c.effects.medium_compaction.rate_per_m = (0.0, 0.5, 0.0, 0.0, 1.0)[i]
        configs.append(c)
    return phi, configs, np.array([120, 80, 1, 2, 120])


def test_each_trial_of_a_batch_is_what_it_is_alone_on_any_number_of_threads():
    phi, configs, n = _batch()
    together = simulate_prescribed(phi, 0.01, configs, n_frames=n)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        serial = simulate_prescribed(phi, 0.01, configs, n_frames=n)
    finally:
        numba.set_num_threads(threads)
    for key in ("pose", "vel", "flippers", "phi", "residual", "iterations"):
        assert np.array_equal(together[key], serial[key], equal_nan=True), key
    # in reverse order and one at a time: no trial sees another's work arrays
    for k in range(len(configs)):
        alone = simulate_prescribed(phi[k : k + 1], 0.01, [configs[k]], n_frames=n[k : k + 1])
        for key in ("pose", "vel", "flippers", "residual", "iterations"):
            assert np.array_equal(together[key][k], alone[key][0], equal_nan=True), (k, key)


def _deep_window_config(cfg: SimConfig, d0_m: float, tol: float) -> SimConfig:
    """The replay's window configuration as it was made before: a deep copy, modified."""
    out = copy.deepcopy(cfg)
    out.solver.tol = tol
    c = cfg.effects.medium_compaction.rate_per_m
    if c > 0 and d0_m > 0:
        grow = 1.0 + c * d0_m
        out.effects.drag_anisotropy.normal_scale = cfg.effects.drag_anisotropy.normal_scale * grow
        out.effects.medium_compaction.rate_per_m = c / grow
    return out


def test_window_configs_equal_deep_copies_and_leave_the_models_unchanged():
    _, configs, _ = _batch()
    before = [dataclasses.asdict(c) for c in configs]
    d0 = np.array([0.0, 0.35, 1.2])
    got = _window_configs(configs, d0, 1e-7)
    assert len(got) == len(configs) * len(d0)
    for i, cfg in enumerate(configs):
        for k, d in enumerate(d0):
            want = _deep_window_config(cfg, float(d), 1e-7)
            assert dataclasses.asdict(got[i * len(d0) + k]) == dataclasses.asdict(want)
    assert [dataclasses.asdict(c) for c in configs] == before


def test_savgol_interior_is_the_same_whatever_the_edge_mode():
    rng = np.random.default_rng(3)
    x = rng.normal(size=(6, 200, 12)).cumsum(axis=1)
    interp = savgol_filter(x, 31, 3, axis=1)
    constant = savgol_filter(x, 31, 3, axis=1, mode="constant")
    assert np.array_equal(interp[:, 15:-15], constant[:, 15:-15])
    assert not np.array_equal(interp[:, :15], constant[:, :15])
