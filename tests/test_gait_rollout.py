"""The gait rollout's array path (`Learner.predict_array` on `Columns`, the table built
once per frequency) gives the numbers of the public path (`predict` on `gait_samples`'s
frame) bit for bit, for every registered learner: the designer's search depends on it."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.gait.design import circle
from suds_exp.gait.motion import cycle_motion, integrate_twists, recorded_cycles, se2_exp
from suds_exp.gait.predict import (
    MEASURED,
    N_CYCLES,
    SAMPLES_PER_CYCLE,
    FittedMap,
    GaitTable,
    build_learner,
    gait_samples,
)
from suds_exp.models.registry import REGISTRY
from suds_exp.testing.synthetic_swimmer import make_samples

#: Baselines whose fits and step-by-step rollouts take seconds to minutes: slow suite.
SLOW = ("MLP", "GBT")
CASES = [(info.name, {}) for info in REGISTRY] + [
    ("GMR", {"branching": "filter"}),
    ("GMR", {"branching": "history"}),
]
PARAMS = [
    pytest.param(
        name,
        params,
        id=name + "".join(f"-{v}" for v in params.values()),
        marks=[pytest.mark.slow] if name.split("+")[0] in SLOW else [],
    )
    for name, params in CASES
]
FREQ = 0.5


@pytest.fixture(scope="module")
def train():
    return make_samples(6, seed=1, noise_r=0.005, noise_dr=0.05, n_trials=2)


def _fitted(train, name, params):
    # the baselines take a seed so that two fits agree; the paper's learners have theirs
    model = build_learner(name, params)
    if "random_state" in model.get_params():
        model.set_params(random_state=0)
    k = sum(1 for c in train.columns if c.startswith("rp_") and c[3:].isdigit())
    rp0 = train[[f"rp_{j + 1}" for j in range(k)]].mean().to_numpy(float)
    return FittedMap(model.fit(train), k, rp0)


@pytest.mark.parametrize(("name", "params"), PARAMS)
def test_the_array_path_predicts_and_rolls_out_what_predict_does(train, name, params):
    fitted = _fitted(train, name, params)
    gait = circle(0.9, 2, "tilted", lag=0.4)
    frame = gait_samples(gait, FREQ, fitted.k, fitted.rp0)
    table = GaitTable.of(FREQ, fitted.k, fitted.rp0).columns(gait)
    assert list(table.data) == list(frame.columns)
    public = fitted.model.predict(frame)
    fast = fitted.model.predict_array(table)
    assert fast.shape == public.shape
    assert fast.tobytes() == np.ascontiguousarray(public.to_numpy(float)).tobytes()
    # the rollout as it was written before the array path: frame, predict, integrate
    vb = public[["vx", "vy", "wz"]].to_numpy(float)
    poses = integrate_twists(vb, 1 / (FREQ * SAMPLES_PER_CYCLE))
    memoryless = fitted.k == 0 and getattr(fitted.model, "branching", "none") == "none"
    assert not memoryless  # the swimmer has r_p: every learner rolls N_CYCLES cycles
    assert len(frame) == N_CYCLES * SAMPLES_PER_CYCLE + 1
    want = cycle_motion(poses, SAMPLES_PER_CYCLE, MEASURED, vb[:, 0])
    for _ in range(2):  # the second time from the map's cached rollout
        got = fitted.motion(gait, FREQ)
        assert got.per_cycle.tobytes() == want.per_cycle.tobytes()
        assert (got.forward_mm, got.lateral_mm, got.turn_rad, got.mean_vx_mm_s) == (
            want.forward_mm,
            want.lateral_mm,
            want.turn_rad,
            want.mean_vx_mm_s,
        )


def test_a_shared_table_is_read_only(train):
    table = GaitTable.of(FREQ, 2, np.zeros(2))
    first = table.columns(circle(1.0, 1))
    with pytest.raises(ValueError, match="read-only"):
        first["t"][0] = 1.0
    second = table.columns(circle(0.5, 1))
    assert first["t"] is second["t"] and first["ra_1"] is not second["ra_1"]


def test_a_recording_is_cut_into_whole_periods_from_its_first_sample():
    # a constant twist moves the body by exp(xi T) each period; a recording of 4.3
    # periods has 4 whole ones
    dt, period = 0.01, 2.0
    xi = np.array([12.0, -3.0, 0.4])
    twists = np.tile(xi, (int(round(4.3 * period / dt)) + 1, 1))
    cycles = recorded_cycles(twists, dt, period)
    assert cycles.shape == (4, 3)
    np.testing.assert_allclose(cycles, np.tile(se2_exp(xi[None], period), (4, 1)), atol=1e-9)
    assert recorded_cycles(twists[:150], dt, period).shape == (0, 3)
