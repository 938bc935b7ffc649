"""GMR+F on a synthetic swimmer whose map has a known asymmetry (Finsler contact)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from suds_exp.errors import ConfigError
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


def both_ways(ratio, n_cycles, frequency_hz, seed, first_trial_id=1):
    """One trial of gait O forwards and one backwards: every shape is passed with both
    signs of its shape velocity, where the two halves of a Finsler map both show."""
    kw = dict(
        frequency_hz=frequency_hz,
        passive="none",
        velocity="asymmetric",
        asymmetry=ratio,
    )
    forwards = make_samples(n_cycles, seed=seed, first_trial_id=first_trial_id, **kw)
    backwards = make_samples(
        n_cycles, seed=seed + 1, first_trial_id=first_trial_id + 1, direction=-1, **kw
    )
    return pd.concat([forwards, backwards], ignore_index=True)


def test_tls_f_recovers_an_asymmetric_map_its_linear_twin_cannot():
    train, test = both_ways(2.5, 10, 0.5, 1), both_ways(2.5, 5, 0.5, 7, 10)
    finsler = rmse(make_model("TLS+F"), train, test)
    assert finsler <= 0.3 * rmse(make_model("TLS+F", split=False), train, test)
    assert finsler <= 0.3 * rmse(make_model("TLS"), train, test)


def test_on_a_linear_map_tls_f_is_as_good_as_its_linear_twin():
    train, test = both_ways(1.0, 10, 0.5, 1), both_ways(1.0, 5, 0.5, 7, 10)
    linear = rmse(make_model("TLS+F", split=False), train, test)
    assert rmse(make_model("TLS+F"), train, test) <= 1.05 * linear


def test_tls_f_is_homogeneous_of_degree_one_in_the_shape_velocity():
    """Trained at 1/2 Hz, TLS+F predicts the gait at 1 Hz: twice the velocity."""
    model = make_model("TLS+F").fit(swimmer(2.5, 10, 0.5, 1))
    test = swimmer(2.5, 2, 0.5, 7, 10)
    faster = test.assign(dra_1=2 * test["dra_1"], dra_2=2 * test["dra_2"], t=test["t"] / 2)
    np.testing.assert_allclose(
        model.predict(faster).to_numpy(), 2 * model.predict(test).to_numpy(), rtol=1e-9
    )


def test_tls_f_on_a_linear_map_is_as_good_as_tls_on_the_training_gait():
    train, test = swimmer(1.0, 10, 0.5, 1), swimmer(1.0, 5, 0.5, 7, 10)
    assert rmse(make_model("TLS+F"), train, test) <= 1.05 * rmse(make_model("TLS"), train, test)


def test_the_backwards_swimmer_passes_the_same_shapes_the_other_way():
    forwards = make_samples(1, passive="none", seed=3, tube=0.0)
    backwards = make_samples(1, passive="none", seed=3, tube=0.0, direction=-1)
    # each backwards shape lies on the forwards gait, its rate reversed
    for _, row in backwards.iloc[::17].iterrows():
        d = np.hypot(forwards["ra_1"] - row["ra_1"], forwards["ra_2"] - row["ra_2"])
        near = forwards.iloc[int(np.argmin(d))]
        assert d.min() < 0.05
        assert np.sign(near["dra_1"]) == -np.sign(row["dra_1"]) or abs(row["dra_1"]) < 0.2


def test_a_direction_other_than_one_or_minus_one_is_refused():
    with pytest.raises(ConfigError, match="direction"):
        make_samples(1, passive="none", direction=0)


def test_tls_f_split_must_be_a_bool():
    with pytest.raises(ConfigError, match="split"):
        make_model("TLS+F", split="yes").fit(swimmer(1.0, 2, 0.5, 1))
