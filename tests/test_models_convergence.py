"""Held-out error of every learner against the noise floor as training data grows.

System: the synthetic SUDS swimmer (`passive="lag"`, `velocity="linear"`):
v_b = A(r_a, r_p) dr_a/dt + noise (1 mm/s on vx, vy), with r_p a first-order lag of the
actuated shape. Shapes are exact, so the noise floor is the RMS of the output noise.
Training: 2, 10 and 60 cycles of gait O at 1/2 Hz; test: another 20-cycle trial.

Expected, written before measuring:
1. phase-only never approaches the floor (> 5x at every size): it cannot see how a cycle
   departs from the mean gait.
2. Every other learner improves from 2 to 10 to 60 cycles.
3. With 60 cycles the SUDS learners are within 2x the floor, and each beats its
   non-SUDS twin (TLS+SUDS < TLS, GMR+SUDS < GMR): r_p carries information r_a lacks.
4. With 2 cycles GMR beats TLS (the paper's small-data result): phase bins with a linear
   model per bin need many cycles, a mixture over (r_a, dr_a/dt) does not.
"""

import numpy as np
import pytest

from suds_exp.models import MODEL_NAMES, make_model
from suds_exp.testing.synthetic_swimmer import make_samples

SIZES = (2, 10, 60)


@pytest.fixture(scope="module", params=[0, 1], ids=["seed0", "seed1"])
def errors(request):
    s = request.param
    kw = dict(passive="lag", velocity="linear", noise_v=1.0, noise_w=0.02)
    test = make_samples(20, seed=100 + s, first_trial_id=100, **kw)
    floor = np.sqrt(((test["vx"] - test["vx_true"]) ** 2).mean())
    out = {}
    for n in SIZES:
        train = make_samples(n, seed=n + 10 * s, **kw)
        for name in MODEL_NAMES:
            pred = make_model(name).fit(train).predict(test)
            out[name, n] = np.sqrt(((pred["vx"] - test["vx"]) ** 2).mean()) / floor
    return out


def test_phase_only_stays_far_from_the_floor(errors):
    assert all(errors["phase-only", n] > 5 for n in SIZES)


@pytest.mark.parametrize("name", ["TLS", "TLS+SUDS", "GMR", "GMR+SUDS"])
def test_error_falls_with_data(errors, name):
    e = [errors[name, n] for n in SIZES]
    assert e[0] > e[1] > e[2], e


def test_suds_learners_approach_the_floor_and_beat_their_twins(errors):
    assert errors["TLS+SUDS", 60] < 2.0
    assert errors["GMR+SUDS", 60] < 2.0
    assert errors["TLS+SUDS", 60] < errors["TLS", 60]
    assert errors["GMR+SUDS", 60] < errors["GMR", 60]


def test_gmr_wins_with_little_data(errors):
    assert errors["GMR", 2] < errors["TLS", 2]
