"""GMR+F on a synthetic swimmer whose map has a known asymmetry (Finsler contact)."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.models import make_model
from suds_exp.testing.synthetic_swimmer import make_samples


def swimmer(ratio, n_cycles, frequency_hz, seed, first_trial_id=1):
    return make_samples(
        n_cycles,
        frequency_hz=frequency_hz,
        n_trials=2,
        seed=seed,
        passive="none",
        velocity="asymmetric",
        asymmetry=ratio,
        first_trial_id=first_trial_id,
    )


def rmse(model, train, test):
    pred = model.fit(train).predict(test)[["vx", "vy"]].to_numpy()
    return float(np.sqrt(np.mean((pred - test[["vx_true", "vy_true"]].to_numpy()) ** 2)))


@pytest.mark.parametrize("frequency_hz", [0.5, 1.0])
def test_on_a_linear_map_gmr_f_is_as_good_as_gmr(frequency_hz):
    train, test = swimmer(1.0, 10, 0.5, 1), swimmer(1.0, 5, frequency_hz, 7, 10)
    assert rmse(make_model("GMR+F"), train, test) <= 1.05 * rmse(make_model("GMR"), train, test)


def test_the_swimmer_s_asymmetry_is_what_was_asked():
    """Closing a joint moves the body `asymmetry` times as far as opening it."""
    one, two = swimmer(1.0, 2, 0.5, 1), swimmer(2.5, 2, 0.5, 1)
    closing = two["dra_1"] < 0
    # with dr_a/dt of one sign only, the map is that sign's linear map
    only = (np.sign(two["dra_1"]) == np.sign(two["dra_2"])) & closing
    np.testing.assert_allclose(two.loc[only, "vx_true"], 2.5 * one.loc[only, "vx_true"])
