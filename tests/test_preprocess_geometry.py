"""Body frame and shape on a synthetic rigid robot with known pose, angles and flippers:
the tilted motion plane, the motor axes, r_a, the passive state, the PCA and the rates."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.preprocess.body_model import SwimmerModel
from suds_exp.preprocess.kinematics import kinematics, measure
from suds_exp.preprocess.rates import body_velocity, derivative, smooth, window_frames
from suds_exp.preprocess.shape import PassivePCA
from suds_exp.testing.synthetic_captures import MIDDLE_MM, synthetic_trial, synthetic_trials


@pytest.fixture(scope="module")
def clean_trials():
    trials = synthetic_trials(n_cycles=5, noise_mm=0.0)
    return trials, [measure(t.xyz) for t in trials]


def test_plane_is_recovered_from_a_tilted_capture(clean_trials):
    trials, measured = clean_trials
    for m in measured:
        assert (
            abs(m.plane.basis[2] @ np.array([0.6, 0.8, 0.0])) < 1e-9
        )  # tilt axis lies in the plane
        assert m.plane.basis[2][2] == pytest.approx(np.cos(0.03), abs=1e-9)
    # heights above the plane: top markers at 0, flipper markers 25 mm below them
    z = measured[0].plane.project(trials[0].xyz)[..., 2]
    np.testing.assert_allclose(z[:, :2], 0.0, atol=1e-6)  # head top markers
    np.testing.assert_allclose(z[:, 7:], 30.0 - 55.0, atol=1e-6)  # flippers


def test_motor_axes_are_the_points_at_constant_distance(clean_trials):
    trials, measured = clean_trials
    joints = SwimmerModel().fit_joints(measured)
    assert joints.length_mm == pytest.approx(MIDDLE_MM, abs=1e-4)
    assert joints.rms_mm < 1e-4
    # head joint seen from the head top markers' frame (centroid (55, 0), axis to (75, -10))
    angle = np.arctan2(-20.0, 40.0)
    expected = np.array([[np.cos(-angle), -np.sin(-angle)], [np.sin(-angle), np.cos(-angle)]]) @ [
        -55.0,
        0.0,
    ]
    np.testing.assert_allclose(joints.head, expected, atol=1e-4)


def test_noise_free_pose_shape_and_velocity_match_the_truth(clean_trials):
    trials, measured = clean_trials
    joints = SwimmerModel().fit_joints(measured)
    for trial, m in zip(trials, measured, strict=True):
        kin = kinematics(m, joints)
        truth = trial.truth
        np.testing.assert_allclose(kin.ra, truth[["phi1", "phi2"]].to_numpy(), atol=1e-6)
        heading_offset = np.angle(np.exp(1j * (kin.heading - truth.theta.to_numpy())))
        assert np.ptp(heading_offset) < 1e-6  # world frame rotated by the tilt, nothing else
        vb = body_velocity(kin.xy, kin.heading, 0.01, window_frames(0.11, 100, 3, len(kin.xy)), 3)
        err = vb - truth[["vx", "vy", "wz"]].to_numpy()
        rms_vx = np.sqrt(np.mean(truth.vx**2))
        assert np.sqrt(np.mean(err[5:-5] ** 2, axis=0)).max() < 0.01 * rms_vx


def test_noisy_capture_gives_ra_within_a_hundredth_of_a_radian():
    trials = synthetic_trials(n_cycles=6, noise_mm=0.2, n_jumps=5, n_dropouts=5, seed=10)
    from suds_exp.preprocess.clean import clean_tracks

    measured = [measure(clean_tracks(t.xyz).xyz) for t in trials]
    joints = SwimmerModel().fit_joints(measured)
    errors = []
    for trial, m in zip(trials, measured, strict=True):
        ra = smooth(kinematics(m, joints).ra, 21, 5)
        errors.append(ra - trial.truth[["phi1", "phi2"]].to_numpy())
    assert np.sqrt(np.mean(np.concatenate(errors) ** 2)) < 0.01


def test_passive_state_and_pca(clean_trials):
    trials, measured = clean_trials
    joints = SwimmerModel().fit_joints(measured)
    passive = np.concatenate([kinematics(m, joints).passive for m in measured])
    # head spoke in the head frame: fixed at (55, 8) mm
    np.testing.assert_allclose(passive[:, :2], np.tile([55.0, 8.0], (len(passive), 1)), atol=1e-5)
    # flipper_1 marker: hinge (80, 20) + 30 mm at the opening angle
    a = np.concatenate([t.truth.flipper_1.to_numpy() for t in trials])
    np.testing.assert_allclose(passive[:, 4], 80 - 30 * np.cos(a), atol=1e-5)
    np.testing.assert_allclose(passive[:, 5], 20 + 30 * np.sin(a), atol=1e-5)
    pca = PassivePCA(4).fit(passive)
    assert pca.explained_variance_ratio_.sum() == pytest.approx(1.0)
    assert np.all(np.diff(pca.explained_variance_) <= 1e-9)
    rp = pca.transform(passive)
    assert rp.shape == (len(passive), 4)
    np.testing.assert_allclose(rp.var(axis=0, ddof=1), pca.explained_variance_[:4], rtol=1e-9)
    # four flipper angles drive 8 coordinates: 4 components hold all the variance
    assert pca.explained_variance_ratio_[:4].sum() > 0.98
    again = PassivePCA.from_dict(pca.to_dict())
    np.testing.assert_allclose(again.transform(passive[:10]), rp[:10])


def test_savitzky_golay_derivative_is_exact_for_cubics():
    t = np.arange(200) * 0.01
    x = 3 * t**3 - 2 * t + 1
    np.testing.assert_allclose(derivative(x, 0.01, 21, 3), 9 * t**2 - 2, atol=1e-8)
    assert window_frames(0.21, 100, 3, 1000) == 21
    assert window_frames(0.2, 100, 3, 1000) == 21  # odd
    assert window_frames(1.0, 100, 3, 51) == 51  # no longer than the record
    assert window_frames(0.0, 100, 3, 51) == 1  # off


def test_rigid_tail_fit_keeps_the_frame_and_averages_the_noise_down():
    from suds_exp.preprocess.body_frame import rigid_fit

    clean = synthetic_trial("D+", 1.0, n_cycles=4, noise_mm=0.0, seed=3)
    noisy = synthetic_trial("D+", 1.0, n_cycles=4, noise_mm=0.2, seed=3)
    exact, top = measure(clean.xyz, "rigid"), measure(noisy.xyz, "top")
    fitted, hinged = measure(noisy.xyz, "rigid"), measure(noisy.xyz, "rigid+flippers")
    # noise-free: the rigid fit reproduces the two-marker frame
    ref = measure(clean.xyz, "top").frames
    np.testing.assert_allclose(exact.frames.tail_origin, ref.tail_origin, atol=1e-6)
    np.testing.assert_allclose(exact.frames.tail_angle, ref.tail_angle, atol=1e-9)
    np.testing.assert_array_equal(fitted.frames.head_angle, top.frames.head_angle)
    # noisy: three markers give a less noisy tail angle than two
    err_top = np.std(top.frames.tail_angle - ref.tail_angle)
    err_fit = np.std(fitted.frames.tail_angle - ref.tail_angle)
    assert err_fit < 0.8 * err_top
    # the flippers' circles about their hinges constrain the frame further
    np.testing.assert_allclose(measure(clean.xyz).frames.tail_angle, ref.tail_angle, atol=1e-9)
    err_hinged = np.std(hinged.frames.tail_angle - ref.tail_angle)
    assert err_hinged < 0.9 * err_fit
    # a hinged marker that does not move (a flipper on its stop) defines no circle: left out
    from suds_exp.preprocess.body_frame import hinged_fit

    rigid = np.tile([[0.0, 0.0], [10.0, 0.0]], (50, 1, 1))
    still = np.tile([[[5.0, 5.0]]], (50, 1, 1))
    o, a = hinged_fit(rigid, still, np.zeros((50, 2)), np.zeros(50))
    np.testing.assert_array_equal(o, 0.0)
    np.testing.assert_array_equal(a, 0.0)
    # a single frame: origin and angle of a rotated, shifted template are recovered
    pts = np.array([[[0.0, 0.0], [10.0, 0.0], [0.0, 5.0]]])
    o, a = rigid_fit(pts, np.zeros((1, 2)), np.zeros(1))
    np.testing.assert_allclose(o, [[0.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(a, [0.0], atol=1e-12)
    with pytest.raises(ValueError, match="tail_fit"):
        measure(clean.xyz, "spokes")


def test_differentiator_window_grows_as_a_power_of_the_gait_period():
    from suds_exp.preprocess.params import DEFAULTS, resolve_params
    from suds_exp.preprocess.rates import differentiator_window

    # the defaults: 27, 21 and 13 frames at 1/3, 1/2 and 1 Hz
    assert [differentiator_window(DEFAULTS, 100, f, 4000) for f in (1 / 3, 0.5, 1.0)] == [
        27,
        21,
        13,
    ]
    # exponent 1: a fixed number of cycles (and the rule of versions made without it)
    fixed = resolve_params({"sg_window_cycles": 0.1, "sg_window_exponent": 1})
    old = {k: v for k, v in fixed.items() if k != "sg_window_exponent"}
    for params in (fixed, old):
        assert [differentiator_window(params, 100, f, 4000) for f in (1 / 3, 0.5, 1.0)] == [
            31,
            21,
            11,
        ]
    # no frequency: seconds
    assert differentiator_window(DEFAULTS, 100, None, 4000) == 21
    with pytest.raises(Exception, match="sg_window_exponent"):
        resolve_params({"sg_window_exponent": -1})
