"""GMR+P and GMR+SUDS+P: a momentum state learned from samples, rolled forward from the
shape alone (the synthetic swimmer with a known body lag)."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.errors import ConfigError
from suds_exp.models import ModelError, make_model
from suds_exp.testing.synthetic_swimmer import make_samples

LAG = 0.3


def swimmer(body_tau, n_cycles, frequency_hz, seed, first_trial_id=1, n_trials=1):
    return make_samples(
        n_cycles,
        frequency_hz=frequency_hz,
        n_trials=n_trials,
        seed=seed,
        body_tau=body_tau,
        passive="none",
        first_trial_id=first_trial_id,
    )


def rmse_vx(pred, test):
    return float(np.sqrt(np.mean((pred["vx"].to_numpy() - test["vx_true"].to_numpy()) ** 2)))


@pytest.fixture(scope="module")
def lagged():
    train = swimmer(LAG, 12, 0.5, seed=1, n_trials=2)
    test = swimmer(LAG, 6, 1.0, seed=5, first_trial_id=9)
    return train, test


def test_the_time_constant_is_recovered_and_the_lag_predicted(lagged):
    train, test = lagged
    m = make_model("GMR+P").fit(train)
    np.testing.assert_allclose(m.tau_, LAG, rtol=0.2)
    assert m.n_momentum_ == 3
    assert m.time_constant_ == pytest.approx(LAG, rel=0.2)
    gmr = rmse_vx(make_model("GMR").fit(train).predict(test), test)
    assert rmse_vx(m.predict(test), test) <= 0.5 * gmr


def test_without_momentum_it_is_gmr():
    train = swimmer(0.0, 10, 0.5, seed=1, n_trials=2)
    test = swimmer(0.0, 6, 1.0, seed=5, first_trial_id=9)
    m = make_model("GMR+P").fit(train)
    assert m.n_momentum_ == 0
    np.testing.assert_array_equal(m.tau_, 0.0)
    np.testing.assert_allclose(m.predict(test), make_model("GMR").fit(train).predict(test))


def test_no_measured_velocity_is_read_while_predicting(lagged):
    train, test = lagged
    m = make_model("GMR+P").fit(train)
    scrambled = test.assign(vx=0.0, vy=np.nan, wz=1e9)
    np.testing.assert_array_equal(m.predict(scrambled), m.predict(test))
    np.testing.assert_array_equal(m.predict(test.drop(columns=["vx", "vy", "wz"])), m.predict(test))


def test_a_given_time_constant_is_used_and_the_dimension_capped(lagged):
    train, _ = lagged
    m = make_model("GMR+P", tau=(0.2, 0.0, 0.4)).fit(train)
    np.testing.assert_array_equal(m.tau_, [0.2, 0.0, 0.4])
    one = make_model("GMR+P", n_momentum=1).fit(train)
    assert one.n_momentum_ == 1 and np.count_nonzero(one.tau_) == 1


def test_suds_variant_rolls_out_and_keeps_its_passive_outputs():
    train = make_samples(8, seed=1, body_tau=LAG, n_trials=2, noise_r=0.005)
    test = make_samples(4, seed=2, body_tau=LAG, first_trial_id=10, noise_r=0.005)
    for mode in ("measured", "rollout"):
        m = make_model("GMR+SUDS+P", mode=mode).fit(train)
        base = make_model("GMR+SUDS", mode=mode).fit(train)
        pred = m.predict(test)
        assert list(pred.columns) == ["vx", "vy", "wz", "drp_1", "drp_2"]
        assert m.time_constant_ == pytest.approx(LAG, rel=0.3)
        assert rmse_vx(pred, test) < rmse_vx(base.predict(test), test)


@pytest.mark.parametrize("value", [0, 4, 1.5, True, "2"])
def test_a_momentum_dimension_outside_one_to_three_is_refused(lagged, value):
    with pytest.raises(ConfigError, match=r"n_momentum=.*expected an integer from 1 to 3"):
        make_model("GMR+P", n_momentum=value).fit(lagged[0])


def test_bad_time_constants_and_no_body_velocity_are_refused(lagged):
    train, _ = lagged
    with pytest.raises(ConfigError, match="tau="):
        make_model("GMR+P", tau=(0.1, 0.2)).fit(train)
    with pytest.raises(ConfigError, match="tau="):
        make_model("GMR+P", tau=-1.0).fit(train)
    with pytest.raises(ModelError, match="body velocity .* is zero everywhere"):
        make_model("GMR+P").fit(train.assign(vx=0.0, vy=0.0, wz=0.0))
    with pytest.raises(ModelError, match="lacks column"):
        make_model("GMR+SUDS+P").fit(train.drop(columns=["vx"]))


@pytest.mark.parametrize(
    ("models", "zero_velocity", "message"),
    [
        ({"GMR+P": {"n_momentum": 4}}, False, "expected an integer from 1 to 3"),
        ({"GMR": {}, "GMR+SUDS+P": {}}, True, r"GMR\+SUDS\+P learns a momentum state"),
    ],
)
def test_campaign_refuses_bad_momentum_requests_with_the_database_unchanged(
    tmp_path, models, zero_velocity, message
):
    from suds_exp.campaign import CampaignOptions, run_campaign
    from suds_exp.errors import CampaignError
    from suds_exp.store import Store
    from suds_exp.testing.database import dump_db
    from suds_exp.testing.synthetic_samples import synthetic_samples

    samples = synthetic_samples(conditions=(("O", 0.5),), trials_per_condition=2)
    if zero_velocity:
        samples = samples.assign(vx=0.0, vy=0.0, wz=0.0)
    store = Store(tmp_path / "c.duckdb")
    store.upgrade()
    before = dump_db(store.path)
    opts = CampaignOptions(models=models, boots=1, train_cycles=2)
    with pytest.raises(CampaignError, match=message) as err:
        run_campaign(store, "c", opts, samples=samples, progress=False)
    assert "\n" not in str(err.value)
    after = dump_db(store.path)
    assert before.keys() == after.keys()
    for table in before:
        assert before[table].equals(after[table]), table


def test_a_gait_run_backwards_is_warmed_up_over_its_first_cycle(lagged):
    """The state's start is the end of the first cycle of phase travelled either way."""
    train, test = lagged
    m = make_model("GMR+P", tau=LAG).fit(train)
    pred = m.predict(test)
    backwards = test.assign(phase=-test["phase"])
    np.testing.assert_allclose(m.predict(backwards), pred, rtol=1e-12, atol=1e-12)
