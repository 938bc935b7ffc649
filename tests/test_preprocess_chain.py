"""Body pose from the whole kinematic chain (`chain_pose`) and the weighted local-polynomial
differentiator, on synthetic robots with a known pose."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import savgol_filter

from suds_exp.errors import ConfigError
from suds_exp.preprocess.body_frame import body_pose
from suds_exp.preprocess.body_model import SwimmerModel
from suds_exp.preprocess.chain import chain_pose, chain_settings
from suds_exp.preprocess.clean import clean_tracks
from suds_exp.preprocess.kinematics import kinematics, measure
from suds_exp.preprocess.params import DEFAULTS, resolve_params
from suds_exp.preprocess.rates import body_velocity, derivative, local_polynomial
from suds_exp.testing.synthetic_captures import synthetic_trials


def _pose_errors(xy, heading, truth):
    """RMS position (mm) and heading (rad) errors after removing the constant offsets of the
    plane frame (the capture is tilted)."""
    d = np.column_stack([xy - truth[["x", "y"]].to_numpy(), heading - truth.theta.to_numpy()])
    d[:, 2] = np.unwrap(d[:, 2])
    d -= d.mean(axis=0)
    return np.sqrt(np.mean(d[:, :2] ** 2)), np.sqrt(np.mean(d[:, 2] ** 2))


def test_noise_free_chain_pose_is_the_segment_pose():
    trials = synthetic_trials(n_cycles=4, noise_mm=0.0)
    measured = [measure(t.xyz) for t in trials]
    joints = SwimmerModel().fit_joints(measured)
    for t, m in zip(trials, measured, strict=True):
        pose = body_pose(m.frames, joints)
        # unsmoothed relative angles: the same pose to rounding
        xy, heading = chain_pose(m.local, m.frames, joints, 1, 7)
        np.testing.assert_allclose(xy, pose.xy, atol=1e-6)
        np.testing.assert_allclose(heading, pose.heading, atol=1e-9)
        # the default smoothing of a smooth gait moves it by far less than the marker noise
        window = chain_settings(DEFAULTS, t.rate_hz, t.frequency_hz, len(xy))
        xy, heading = chain_pose(m.local, m.frames, joints, *window)
        assert np.abs(xy - pose.xy).max() < 0.02
        assert np.abs(heading - pose.heading).max() < 2e-4


def test_chain_pose_is_less_noisy_than_the_segment_pose_and_so_is_the_velocity():
    trials = synthetic_trials(n_cycles=6, noise_mm=0.2, n_jumps=3, n_dropouts=3, seed=20)
    measured = [measure(clean_tracks(t.xyz).xyz) for t in trials]
    joints = SwimmerModel().fit_joints(measured)
    seg_xy, seg_th, ch_xy, ch_th, seg_v, ch_v = [], [], [], [], [], []
    for t, m in zip(trials, measured, strict=True):
        segments = kinematics(m, joints)
        chain = kinematics(
            m, joints, chain_settings(DEFAULTS, t.rate_hz, t.frequency_hz, len(t.truth))
        )
        np.testing.assert_array_equal(chain.ra, segments.ra)  # shape from the segment frames
        for kin, xy_errs, th_errs, v_errs in (
            (segments, seg_xy, seg_th, seg_v),
            (chain, ch_xy, ch_th, ch_v),
        ):
            exy, eth = _pose_errors(kin.xy, kin.heading, t.truth)
            xy_errs.append(exy)
            th_errs.append(eth)
            vb = body_velocity(kin.xy, kin.heading, 0.01, 21, 3, "triweight")
            v_errs.append(
                np.sqrt(np.mean((vb - t.truth[["vx", "vy", "wz"]].to_numpy()) ** 2, axis=0))
            )
    assert np.mean(ch_xy) < 0.85 * np.mean(seg_xy)
    assert np.mean(ch_th) < 0.7 * np.mean(seg_th)
    assert np.all(np.mean(ch_v, axis=0) < np.mean(seg_v, axis=0))


def test_versions_choose_the_body_fit():
    assert chain_settings(DEFAULTS, 100.0, 0.5, 4000) == (61, 7)  # 0.3 cycles at 2 s
    assert chain_settings(DEFAULTS, 100.0, None, 4000) == (61, 7)  # chain_window_s
    assert chain_settings(resolve_params({"body_fit": "segments"}), 100.0, 0.5, 4000) is None
    # versions made before body_fit existed keep their segment pose
    old = {k: v for k, v in DEFAULTS.items() if not k.startswith(("body_fit", "chain_"))}
    assert chain_settings(old, 100.0, 0.5, 4000) is None
    with pytest.raises(ConfigError, match="body_fit=joint: expected one of chain, segments"):
        resolve_params({"body_fit": "joint"})
    with pytest.raises(ConfigError, match="sg_kernel=gauss: expected one of triweight, box"):
        resolve_params({"sg_kernel": "gauss"})
    with pytest.raises(ConfigError, match="chain_polyorder=12: must be 1..9"):
        resolve_params({"chain_polyorder": 12})


def test_weighted_local_polynomial_is_exact_for_its_order_and_box_is_savitzky_golay():
    t = np.arange(300) * 0.01
    x = 3 * t**3 - 2 * t + 1
    for kernel in ("triweight", "box"):
        np.testing.assert_allclose(derivative(x, 0.01, 21, 3, kernel), 9 * t**2 - 2, atol=1e-8)
    y = np.column_stack([t**7 - t**2, np.sin(3 * t)])
    ends = savgol_filter(y, 61, 7, axis=0, mode="interp")
    np.testing.assert_allclose(local_polynomial(y, 61, 7), ends, atol=1e-9)
    noise = np.random.default_rng(0).normal(size=(400, 2))
    for deriv in (0, 1):
        np.testing.assert_allclose(
            local_polynomial(noise, 31, 5, "box", deriv),
            savgol_filter(noise, 31, 5, deriv=deriv, axis=0, mode="interp"),
            atol=1e-10,
        )
    # long windows and high orders stay well conditioned (scipy's fit does not at 121/8)
    long = np.random.default_rng(1).normal(scale=0.01, size=2000) + np.sin(np.arange(2000) / 150)
    smooth = local_polynomial(long, 121, 8)
    assert np.abs(smooth - np.sin(np.arange(2000) / 150)).max() < 0.01
    # frequency response at the default windows: the triweight window keeps more of the
    # band (closer to the ideal 2 pi f) and leaks almost nothing above it (no side lobes)
    impulse = np.zeros(401)
    impulse[200] = 1.0
    f = np.fft.rfftfreq(401)  # cycles per frame
    for window in (13, 21, 27):
        gain = {
            k: np.abs(np.fft.rfft(derivative(impulse, 1.0, window, 3, k)))
            for k in ("box", "triweight")
        }
        band, above = f < 0.3 / window, f > 0.2
        ideal = 2 * np.pi * f[band]
        assert np.sum((gain["triweight"][band] - ideal) ** 2) < np.sum(
            (gain["box"][band] - ideal) ** 2
        )
        assert np.sum(gain["triweight"][above] ** 2) < 0.2 * np.sum(gain["box"][above] ** 2)
