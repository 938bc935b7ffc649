"""Gaussian mixture regression (GMR, GMR+SUDS): EM, conditioning, augmentation, rollout."""

import numpy as np
import pandas as pd
import pytest

from suds_exp.models import ModelError, make_model
from suds_exp.models.mixture import conditional_mean, fit_mixture
from suds_exp.testing.synthetic_swimmer import make_samples


def _random_mixture(rng, K, D):
    priors = rng.dirichlet(np.ones(K))
    means = rng.normal(size=(K, D)) * 2
    A = rng.normal(size=(K, D, D))
    cov = A @ np.swapaxes(A, 1, 2) + 0.05 * np.eye(D)
    return priors, means, cov


@pytest.mark.parametrize(
    ("K", "D", "inputs"), [(1, 2, [0]), (5, 7, [0, 1, 2, 3]), (12, 9, [6, 0, 3])]
)
def test_conditional_mean_equals_the_gmr_package(K, D, inputs):
    gmr = pytest.importorskip("gmr")
    rng = np.random.default_rng(K + D)
    priors, means, cov = _random_mixture(rng, K, D)
    X = rng.normal(size=(300, len(inputs))) * 2
    ours = conditional_mean(priors, means, cov, inputs, X)
    theirs = gmr.GMM(K, priors, means, cov).predict(np.array(inputs), X)
    np.testing.assert_allclose(ours, theirs, rtol=1e-8, atol=1e-8)


def test_em_is_seeded_and_recovers_separated_clusters():
    rng = np.random.default_rng(0)
    centres = np.array([[0, 0, 0], [6, 0, 0], [0, 6, 0]], float)
    X = np.vstack([c + rng.normal(size=(300, 3)) * [1, 0.5, 0.2] for c in centres])
    a = fit_mixture(X, 3, rng=np.random.default_rng(5))
    b = fit_mixture(X, 3, rng=np.random.default_rng(5))
    np.testing.assert_array_equal(a.means, b.means)
    assert a.converged
    found = a.means[np.argsort(a.means[:, 0] + 2 * a.means[:, 1])]
    np.testing.assert_allclose(found, centres, atol=0.15)
    np.testing.assert_allclose(np.sort(a.priors), [1 / 3] * 3, atol=0.02)


def test_em_survives_degenerate_data():
    """Duplicated points, a constant column and exact collinearity: regularised, finite."""
    rng = np.random.default_rng(1)
    x = rng.normal(size=200)
    X = np.column_stack([x, 2 * x, np.zeros(200), np.repeat(rng.normal(size=20), 10)])
    mix = fit_mixture(X, 8, reg_covar=1e-4, rng=np.random.default_rng(0))
    assert np.isfinite(mix.means).all() and np.isfinite(mix.covariances).all()
    assert (np.linalg.eigvalsh(mix.covariances) > 0).all()
    with pytest.raises(ModelError, match="n_components"):
        fit_mixture(X[:5], 8)


def test_homogeneous_augmentation_makes_predictions_rate_independent():
    """v_b is homogeneous of degree 1 in dr_a/dt: running the test twice as fast must
    predict exactly twice the velocity, whatever was learned."""
    train = make_samples(10, passive="travel", velocity="finsler", seed=4)
    test = make_samples(3, passive="travel", velocity="finsler", seed=5, first_trial_id=7)
    fast = test.assign(t=test["t"] / 2, dra_1=2 * test["dra_1"], dra_2=2 * test["dra_2"])
    for name in ("GMR", "GMR+SUDS"):
        m = make_model(name, speed_floor=1e-9).fit(train)
        np.testing.assert_allclose(m.predict(fast), 2 * m.predict(test), rtol=1e-9, atol=1e-9)


def test_homogeneous_augmentation_extrapolates_to_another_frequency():
    """Trained at 1/2 Hz, tested at 1 Hz on a rate-independent system."""
    kw = dict(passive="travel", velocity="finsler", noise_r=0.005, noise_dr=0.05)
    train = make_samples(30, seed=1, **kw)
    test = make_samples(10, seed=2, frequency_hz=1.0, first_trial_id=9, **kw)
    err = {}
    for aug in ("homogeneous", "none"):
        pred = make_model("GMR", augment=aug).fit(train).predict(test)
        err[aug] = np.sqrt(((pred["vx"] - test["vx"]) ** 2).mean())
    assert err["homogeneous"] < 0.3 * err["none"]


def test_gmr_suds_rollout_follows_the_passive_trajectory():
    """A mixture only knows dr_p/dt where it has seen r_p, so the training trials start
    from scattered passive states; the test trial starts displaced inside that range.
    Rollout stays within a fraction of r_p's spread (TLS+SUDS, linear in r_p, does
    better, see test_models_tls)."""
    kw = dict(passive="lag", velocity="linear", noise_v=0.3, noise_w=0.005)
    rng = np.random.default_rng(0)
    train = pd.concat(
        [
            make_samples(
                5, seed=i, first_trial_id=i, rp_start=tuple(rng.uniform(-0.5, 0.5, 2)), **kw
            )
            for i in range(6)
        ],
        ignore_index=True,
    )
    test = make_samples(5, seed=99, first_trial_id=99, rp_start=(0.3, -0.3), **kw)
    m = make_model("GMR+SUDS", mode="rollout").fit(train)
    rolled = m.rollout(test).to_numpy()
    truth = test[["rp_true_1", "rp_true_2"]].to_numpy()
    rms = np.sqrt(((rolled - truth) ** 2).mean(axis=0))
    assert (rms < 0.25 * truth.std(axis=0)).all(), rms / truth.std(axis=0)
    np.testing.assert_allclose(rolled[0], test[["rp_1", "rp_2"]].to_numpy()[0])
    # without the passive dynamics (r_p frozen at its start) it would be far worse
    frozen = np.sqrt(((truth - truth[0]) ** 2).mean(axis=0))
    assert (rms < 0.3 * frozen).all()


def test_a_robot_standing_still_predicts_no_motion():
    """Most of the trial at rest (median shape speed 0): no division by zero, and zero
    shape velocity gives zero body velocity under the homogeneous augmentation."""
    train = make_samples(5, seed=1)
    rest = train.index < 0.6 * len(train)
    still = train.copy()
    still.loc[rest, ["dra_1", "dra_2", "vx", "vy", "wz", "drp_1", "drp_2"]] = 0.0
    for name in ("GMR", "GMR+SUDS"):
        pred = make_model(name).fit(still).predict(still)
        assert np.isfinite(pred.to_numpy()).all()
        assert np.abs(pred[rest].to_numpy()).max() < 1e-9


def test_bic_chooses_among_the_candidates():
    train = make_samples(10, passive="travel", velocity="finsler", seed=4)
    m = make_model("GMR", select_k="bic", k_candidates=(1, 8)).fit(train)
    assert m.n_components_ == 8  # one Gaussian cannot follow a gait loop
    assert len(m.priors_) == 8 and np.isfinite(m.bic_)
    fixed = make_model("GMR", n_components=8).fit(train)
    np.testing.assert_allclose(m.predict(train), fixed.predict(train))
