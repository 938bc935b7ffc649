"""Phaser on synthetic oscillators with a known phase: several channels, non-uniform
protophase speed, drifting frequency, phase diffusion and measurement noise."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.errors import PreprocessError
from suds_exp.preprocess.phaser import Phaser, cycles


def oscillator(n: int, seed: int, noise: float = 0.03):
    """Channels (n, 3) and their true phase (n,) rad; 100 Hz, about 0.7 Hz."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 100
    theta = (
        2 * np.pi * 0.7 * t
        + 0.4 * np.sin(2 * np.pi * 0.03 * t + seed)  # slowly drifting frequency
        + np.cumsum(rng.normal(0, 0.003, n))  # phase diffusion
        + rng.uniform(0, 2 * np.pi)
    )
    channels = np.stack(
        [
            np.cos(theta + 0.5 * np.sin(theta)),  # non-uniform protophase speed
            np.sin(theta) + 0.3 * np.cos(2 * theta),
            2 * np.cos(theta - 1) + 0.5 * np.sin(3 * theta),
        ],
        axis=1,
    )
    return channels + rng.normal(0, noise, channels.shape), theta


def phase_rms(estimate, truth):
    """RMS error after removing one constant offset, rad."""
    d = np.angle(np.exp(1j * (estimate - truth)))
    d = np.angle(np.exp(1j * (d - np.angle(np.mean(np.exp(1j * d))))))
    return float(np.sqrt(np.mean(d**2)))


@pytest.fixture(scope="module")
def trained():
    return Phaser(order=10, pad_cycles=2).fit([oscillator(3000 + 400 * i, i)[0] for i in range(4)])


@pytest.mark.parametrize("seed", [50, 51, 52])
def test_phase_of_unseen_records_within_005_rad(trained, seed):
    channels, theta = oscillator(2500, seed)
    phase = trained.transform(channels)
    assert phase_rms(phase, theta) < 0.05
    # unwrapped: it counts the same cycles as the truth (no 2 pi slips; ends are noisier)
    assert (phase[-1] - phase[0]) == pytest.approx(theta[-1] - theta[0], abs=1.0)
    assert 0 <= phase[0] < 2 * np.pi


def test_uncorrected_protophase_is_worse_than_the_corrected_phase(trained):
    from scipy.signal import hilbert

    channels, theta = oscillator(2500, 60)
    proto = np.angle(hilbert(channels[:, 0] - channels[:, 0].mean()))
    assert phase_rms(proto, theta) > 0.1  # what the correction has to remove
    assert phase_rms(trained.transform(channels), theta) < 0.05


def test_phase_zero_is_the_first_channel_crossing_its_mean_upwards(trained):
    channels, _ = oscillator(3000, 70, noise=0.0)
    phase = trained.transform(channels)
    z = channels[:, 0] - trained.mean_[0]
    up = np.flatnonzero((z[:-1] < 0) & (z[1:] >= 0))
    at = np.angle(np.exp(1j * phase[up]))
    assert np.abs(at).max() < 0.1
    # a cycle starts at each section crossing
    c = cycles(phase)
    starts = np.flatnonzero(np.diff(c) == 1) + 1
    assert np.abs(starts - up[: len(starts)] - 0.5).max() <= 1.5


def test_stored_state_reproduces_the_phase(trained):
    channels, _ = oscillator(1500, 80)
    again = Phaser.from_dict(trained.to_dict())
    np.testing.assert_allclose(again.transform(channels), trained.transform(channels), atol=1e-12)


def test_constant_channel_is_refused():
    with pytest.raises(PreprocessError, match="constant"):
        Phaser().fit([np.column_stack([np.sin(np.arange(500) / 10), np.ones(500)])])


def test_a_channel_going_round_twice_per_cycle_is_left_out():
    def with_double(n, seed):
        channels, theta = oscillator(n, seed)
        return np.column_stack([channels, np.cos(2 * theta)]), theta

    phaser = Phaser().fit([with_double(3000, i)[0] for i in range(3)])
    assert phaser.channel_ok_.tolist() == [True, True, True, False]
    assert phaser.weights_[3] == 0
    channels, theta = with_double(2500, 90)
    assert phase_rms(phaser.transform(channels), theta) < 0.05


def unequal_noise(n: int, seed: int):
    """The oscillator's channels, the first nearly clean, the others 25 times noisier."""
    channels, theta = oscillator(n, seed, noise=0.0)
    rng = np.random.default_rng(seed + 1000)
    return channels + rng.normal(0, 1, channels.shape) * np.array([0.02, 0.5, 0.5]), theta


def test_channels_count_by_their_signal_to_noise():
    """Noisy channels must not drag the phase away from what the clean one gives alone
    (with equal weights the three-channel phase was about 6 times worse: 0.16 rad)."""
    train = [unequal_noise(3000, i)[0] for i in range(3)]
    combined = Phaser().fit(train)
    alone = Phaser().fit([x[:, :1] for x in train])
    assert combined.weights_[0] > 0.9
    for seed in (40, 41):
        channels, theta = unequal_noise(2500, seed)
        clean_only = phase_rms(alone.transform(channels[:, :1]), theta)
        assert phase_rms(combined.transform(channels), theta) < 1.1 * clean_only


def test_independent_errors_get_inverse_variance_weights():
    from suds_exp.preprocess.phaser import min_variance_weights

    w = min_variance_weights(np.diag([1.0, 4.0, 0.5, 9.0]), np.array([True, True, True, False]))
    np.testing.assert_allclose(w, np.array([1.0, 0.25, 2.0, 0.0]) / 3.25, rtol=1e-5)
    # a channel that only adds correlated error is left out rather than weighed negatively
    cov = np.array([[1.0, 1.2], [1.2, 2.0]])
    assert min_variance_weights(cov, np.array([True, True])).tolist() == [1.0, 0.0]
