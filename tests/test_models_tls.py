"""TLS and TLS+SUDS against known answers on synthetic swimmers."""

import numpy as np
import pandas as pd
import pytest

from suds_exp.models import make_model
from suds_exp.models.tls import tls_solve
from suds_exp.testing.synthetic_swimmer import connection, make_samples


def _tiny_problem(rng, n=40):
    t = np.arange(n) * 0.05
    ra = rng.normal(size=(n, 2)) * [0.5, 0.3]
    dra = rng.normal(size=(n, 2)) * [2.0, 1.5]
    delta = ra - ra.mean(axis=0)
    X = np.hstack([delta, dra, (delta[:, :, None] * dra[:, None, :]).reshape(n, 4)])
    truth = rng.normal(size=8)
    vx = 3.0 + X @ truth + 0.05 * rng.standard_normal(n)
    frame = pd.DataFrame(
        {
            "trial_id": 1,
            "frame": np.arange(n),
            "t": t,
            "phase": 2 * np.pi * 0.5 * t,
            "ra_1": ra[:, 0],
            "ra_2": ra[:, 1],
            "dra_1": dra[:, 0],
            "dra_2": dra[:, 1],
            "vx": vx,
            "vy": -vx,
            "wz": 0.1 * vx,
        }
    )
    return frame, X, ra, dra


def test_tls_equals_a_direct_svd_solution_on_a_tiny_problem():
    """One bin, constant mean gait, no truncation: the model is the textbook TLS.

    Direct solution: centre [X y], divide the columns by the documented scales (std of
    r for delta, std of dr_a/dt for its rate, their products for the bilinear terms, std
    of y), take the right singular vector v of the smallest singular value:
    b = -v[:p] / v[p], unscaled; intercept from the means.
    """
    rng = np.random.default_rng(7)
    frame, X, ra, dra = _tiny_problem(rng)
    m = make_model(
        "TLS", n_bins=1, gait_order=0, coef_order=0, tls_gap=1.000001, min_spread=0.0
    ).fit(frame)
    y = frame["vx"].to_numpy()
    s_r, s_d = ra.std(axis=0), dra.std(axis=0)
    sx = np.concatenate([s_r, s_d, np.outer(s_r, s_d).ravel()])
    Z = np.column_stack([(X - X.mean(0)) / sx, (y - y.mean()) / y.std()])
    v = np.linalg.svd(Z)[2][-1]
    b = -v[:-1] / v[-1] / sx * y.std()
    c = y.mean() - X.mean(0) @ b
    direct = c + X @ b
    np.testing.assert_allclose(m.predict(frame)["vx"], direct, rtol=1e-8, atol=1e-8)
    # and it is TLS, not least squares: the two differ measurably on noisy data
    ols = np.linalg.lstsq(np.column_stack([np.ones(len(X)), X]), y, rcond=None)[0]
    assert np.abs(np.column_stack([np.ones(len(X)), X]) @ ols - direct).max() > 1e-6


def test_tls_solve_truncates_collinear_directions_instead_of_exploding():
    rng = np.random.default_rng(1)
    x1 = rng.normal(size=200)
    X = np.column_stack([x1, x1 + 1e-7 * rng.normal(size=200)])  # r_p following r_a
    y = (2.0 * x1 + 0.1 * rng.normal(size=200))[:, None]
    _, B, kept = tls_solve(X, y)
    assert kept == 1
    assert abs(B.sum() - 2.0) < 0.05 and np.abs(B).max() < 10


def test_tls_recovers_the_connection_within_the_gait_tube():
    """v_b = A(r_a) dr_a/dt + noise: the fitted A(phase) is A(r_bar(phase)).

    Within 10 %: TLS treats every scaled column as equally noisy, so with nearly exact
    shapes its errors-in-variables correction over-corrects a little (least squares on the
    same data gets ~3 %); that is the method, not a defect of this implementation.
    """
    data = make_samples(
        40,
        passive="none",
        n_trials=2,
        noise_v=1.0,
        noise_w=0.02,
        noise_r=0.005,
        noise_dr=0.05,
        seed=3,
    )
    m = make_model("TLS").fit(data)
    phase = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    coef = m.coefficients(phase)
    truth = connection(coef["r_bar"])
    err = coef["A"] - truth
    for row in range(3):  # vx, vy, wz: RMS error within 10 % of the map's RMS size
        rel = np.sqrt((err[:, row] ** 2).mean()) / np.sqrt((truth[:, row] ** 2).mean())
        assert rel < 0.1, (row, rel)


def test_tls_suds_rollout_reproduces_the_passive_trajectory():
    """Linear SUDS lag system, noise-free shapes: rollout from a displaced start follows
    the true r_p (the relaxation back to the gait included) to a few thousandths."""
    kw = dict(passive="lag", velocity="linear", noise_v=0.3, noise_w=0.005)
    train = make_samples(30, seed=1, rp_start=(0.3, -0.3), **kw)
    test = make_samples(5, seed=2, first_trial_id=9, rp_start=(0.4, -0.4), **kw)
    m = make_model("TLS+SUDS", mode="rollout", min_spread=0.0).fit(train)
    rolled = m.rollout(test).to_numpy()
    truth = test[["rp_true_1", "rp_true_2"]].to_numpy()
    assert np.abs(rolled - truth).max() < 0.01 * np.ptp(truth)
    # the displaced start matters: the equilibrium path is far from the truth at first
    assert np.abs(truth[0] - truth[50]).max() > 0.2
    # so v_b predicted from the rolled-out r_p is v_b predicted from the measured r_p
    rolled_vx = m.predict(test)["vx"]
    measured_vx = m.set_params(mode="measured").predict(test)["vx"]
    assert np.abs(rolled_vx - measured_vx).max() < 0.05 * test["vx"].std()


@pytest.mark.parametrize("n_cycles", [1, 2])
def test_tls_stays_sane_with_very_few_cycles(n_cycles):
    """With one or two cycles the offsets from the mean gait carry no information; TLS
    must fall back towards the phase-only answer rather than extrapolate wildly."""
    kw = dict(passive="lag", noise_r=0.005, noise_dr=0.05)
    train = make_samples(n_cycles, seed=n_cycles, **kw)
    test = make_samples(10, seed=100, first_trial_id=100, **kw)
    rm = {}
    for name in ("phase-only", "TLS", "TLS+SUDS"):
        pred = make_model(name).fit(train).predict(test)
        rm[name] = np.sqrt(((pred["vx"] - test["vx"]) ** 2).mean())
    assert rm["TLS"] < 1.5 * rm["phase-only"]
    assert rm["TLS+SUDS"] < 1.5 * rm["phase-only"]


def test_phase_only_is_tls_constant_term_at_the_same_phase_resolution():
    """The paper defines phase-only as TLS's phase-dependent constant term: on a robot
    whose shape never leaves its mean gait TLS has nothing else, so both must predict the
    same, including the higher harmonics of v_b that flipper stops put there."""
    t = np.arange(3000) * 0.01
    phase = 2 * np.pi * 0.5 * t
    ra = np.column_stack([np.cos(phase), np.sin(phase)])
    dra = np.pi * np.column_stack([-np.sin(phase), np.cos(phase)])
    vx = 20 + 15 * np.cos(2 * phase) + 4 * np.cos(6 * phase) + 2 * np.sin(8 * phase)
    frame = pd.DataFrame(
        {"trial_id": 1, "frame": np.arange(len(t)), "t": t, "phase": phase,
         "ra_1": ra[:, 0], "ra_2": ra[:, 1], "dra_1": dra[:, 0], "dra_2": dra[:, 1],
         "vx": vx, "vy": 0.1 * vx, "wz": 0.0}
    )  # fmt: skip
    assert (
        make_model("phase-only").get_params()["order"]
        == make_model("TLS").get_params()["gait_order"]
    )
    phase_only = make_model("phase-only").fit(frame).predict(frame)["vx"]
    tls = make_model("TLS").fit(frame).predict(frame)["vx"]
    np.testing.assert_allclose(tls, phase_only, atol=1e-6 * np.abs(vx).max())
    np.testing.assert_allclose(phase_only, vx, atol=1e-6 * np.abs(vx).max())
