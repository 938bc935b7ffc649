"""The learners' public face: make_model, the estimator contract, frames in and out."""

import json

import numpy as np
import pandas as pd
import pytest
from sklearn.base import clone

from suds_exp.errors import ConfigError, SudsError
from suds_exp.models import (
    FINSLER_MODELS,
    MODEL_NAMES,
    MOMENTUM_MODELS,
    ModelError,
    make_model,
)
from suds_exp.testing.synthetic_swimmer import make_samples

VARIANTS = [(name, {}) for name in MODEL_NAMES] + [
    ("TLS+SUDS", {"mode": "rollout"}),
    ("GMR+SUDS", {"mode": "rollout"}),
    ("GMR", {"branching": "filter"}),
    ("GMR", {"branching": "history"}),
    ("GMR", {"augment": "dilation"}),
    *((name, {}) for name in MOMENTUM_MODELS),
    ("GMR+SUDS+P", {"mode": "rollout"}),
    *((name, {}) for name in FINSLER_MODELS),
    ("GMR+F", {"branching": "history"}),
]
IDS = [n + "".join(f"-{v}" for v in p.values()) for n, p in VARIANTS]


@pytest.fixture(scope="module")
def data():
    train = make_samples(8, seed=1, noise_r=0.005, noise_dr=0.05, n_trials=2)
    test = make_samples(4, seed=2, noise_r=0.005, noise_dr=0.05, first_trial_id=10, n_trials=2)
    return train, test


def test_make_model_knows_the_five_names():
    assert set(MODEL_NAMES) == {"phase-only", "TLS", "TLS+SUDS", "GMR", "GMR+SUDS"}
    with pytest.raises(ConfigError, match="unknown model 'CNN'"):
        make_model("CNN")  # MLP is a survey baseline now (tests/test_models_sklearn.py)
    with pytest.raises(ConfigError, match="unknown parameter"):
        make_model("TLS", n_bin=3)
    assert issubclass(ModelError, SudsError)


@pytest.mark.parametrize(("name", "params"), VARIANTS, ids=IDS)
def test_fit_predict_contract(data, name, params):
    train, test = data
    m = make_model(name, **params)
    assert m.get_params()  # everything needed to re-create it
    assert m.fit(train) is m
    test = test.set_index(pd.RangeIndex(1000, 1000 + len(test)))
    pred = m.predict(test)
    expected = ["vx", "vy", "wz"] + (["drp_1", "drp_2"] if "SUDS" in name else [])
    assert list(pred.columns) == expected
    assert pred.index.equals(test.index)
    assert np.isfinite(pred.to_numpy()).all()
    # same recipe, same data -> same predictions (the campaign stores get_params()).
    again = type(m)(**m.get_params()).fit(train).predict(test)
    np.testing.assert_array_equal(pred.to_numpy(), again.to_numpy())
    np.testing.assert_array_equal(pred.to_numpy(), clone(m).fit(train).predict(test).to_numpy())
    # the campaign stores the recipe as JSON (tuples come back as lists)
    stored = json.loads(json.dumps(m.get_params(), default=list))
    np.testing.assert_array_equal(
        pred.to_numpy(), make_model(name, **stored).fit(train).predict(test)
    )


@pytest.mark.parametrize(("name", "params"), VARIANTS, ids=IDS)
def test_row_order_and_trials_do_not_matter(data, name, params):
    """Rows may come shuffled; each trial_id is its own time series."""
    train, test = data
    m = make_model(name, **params).fit(train)
    pred = m.predict(test)
    shuffled = test.sample(frac=1.0, random_state=3)
    np.testing.assert_allclose(m.predict(shuffled).loc[test.index], pred, rtol=1e-9, atol=1e-9)
    for _, one in test.groupby("trial_id"):
        np.testing.assert_allclose(m.predict(one), pred.loc[one.index], rtol=1e-9, atol=1e-9)


def test_passive_dimension_is_inferred(data):
    train, test = data
    three = train.assign(rp_3=0.1 * train["rp_1"] ** 2, drp_3=0.2 * train["rp_1"] * train["drp_1"])
    for name in ("TLS+SUDS", "GMR+SUDS"):
        m = make_model(name).fit(three)
        assert m.rp_columns_ == ["rp_1", "rp_2", "rp_3"]
        assert list(m.predict(three).columns)[-1] == "drp_3"


@pytest.mark.parametrize(
    ("name", "params", "match"),
    [
        ("TLS", {"n_bins": 0}, "n_bins"),
        ("TLS", {"n_bins": 4, "coef_order": 3}, "coef_order"),
        ("TLS+SUDS", {"mode": "replay"}, "mode"),
        ("phase-only", {"order": -1}, "order"),
        ("GMR", {"n_components": 0}, "n_components"),
        ("GMR", {"augment": "mirror"}, "augment"),
        ("GMR", {"augment_range": (2.0, 1.0)}, "augment_range"),
        ("GMR", {"reg_covar": 0.0}, "reg_covar"),
        ("GMR+SUDS", {"branching": "sometimes"}, "branching"),
        ("GMR+F", {"augment": "dilation"}, "augment"),
    ],
)
def test_bad_hyper_parameters_are_refused_in_fit(data, name, params, match):
    m = make_model(name, **params)  # stored unchanged, checked by fit
    with pytest.raises(ConfigError, match=match):
        m.fit(data[0])


def test_bad_frames_are_refused(data):
    train, _ = data
    with pytest.raises(ModelError, match="dra_1"):
        make_model("GMR").fit(train.drop(columns=["dra_1"]))
    with pytest.raises(ModelError, match="rp_1"):
        make_model("TLS+SUDS").fit(train.drop(columns=[c for c in train if "rp_" in c]))
    with pytest.raises(ModelError, match="NaN"):
        make_model("TLS").fit(train.assign(vx=np.where(train.index == 5, np.nan, train["vx"])))
    with pytest.raises(ModelError, match="before fit"):
        make_model("GMR").predict(train)


def test_a_gap_inside_a_trial_restarts_the_series(data):
    """Two cycle windows cut from one trial behave like two trials (rollout restarts)."""
    _, test = data
    one = test[test["trial_id"] == test["trial_id"].iloc[0]]
    cut = one[(one["cycle"] - one["cycle"].min()).isin([0, 2])]
    as_two = cut.assign(trial_id=np.where(cut["cycle"] == cut["cycle"].min(), 1, 2))
    train = data[0]
    for name in ("TLS+SUDS", "GMR+SUDS"):
        m = make_model(name, mode="rollout").fit(train)
        np.testing.assert_allclose(m.predict(cut), m.predict(as_two), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", [*MODEL_NAMES, *MOMENTUM_MODELS, *FINSLER_MODELS])
def test_every_hyper_parameter_lands_in_its_own_attribute(name):
    """Subclasses forward their parameters positionally; a swapped pair would go unseen
    by the round-trip test, so set each to a distinct marker and read it back."""
    params = make_model(name).get_params()
    marked = {p: f"marker-{p}" for p in params}
    assert make_model(name, **marked).get_params() == marked
