"""Gait commands and the actuator model (command -> realised joint angles).

Gaits (DESIGN.md), with theta = 2 pi f t + phase0:
O: phi1 = cos th, phi2 = sin th; D-/D+: phi1 = cos th + cos(3 th)/k,
phi2 = sin th - sin(3 th)/k (k = 9 / 4); S-/S+: phi1 = cos th - cos(3 th)/k,
phi2 = sin th + sin(3 th)/k (k = 9 / 4).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

from suds_exp.errors import ConfigError
from suds_exp.sim.config import Actuator

GAITS = ("S+", "S-", "O", "D-", "D+")
FREQUENCIES_HZ = (1 / 3, 1 / 2, 1.0)

# (sign of the cos(3 th) term in phi1, k); phi2's sin(3 th) term has the opposite sign
_GAIT_TERMS = {
    "S+": (-1.0, 4.0),
    "S-": (-1.0, 9.0),
    "O": (0.0, 1.0),
    "D-": (1.0, 9.0),
    "D+": (1.0, 4.0),
}


def gait_shape(gait: str, theta: np.ndarray) -> np.ndarray:
    """Commanded (phi1, phi2) of `gait` at phases theta (rad): array (..., 2), rad."""
    try:
        sign, k = _GAIT_TERMS[gait]
    except KeyError:
        raise ConfigError(f"gait {gait!r}: expected one of {', '.join(GAITS)}") from None
    theta = np.asarray(theta, dtype=float)
    phi1 = np.cos(theta) + sign * np.cos(3 * theta) / k
    phi2 = np.sin(theta) - sign * np.sin(3 * theta) / k
    return np.stack([phi1, phi2], axis=-1)


def actuate(phi_cmd: np.ndarray, dt: float, actuator: Actuator, rng: np.random.Generator):
    """Realised joint angles from commanded ones: OU tracking noise, then first-order lag.

    phi_cmd: array (n, 2), rad, every dt s. Returns array (n, 2), rad; starts at the
    command (the robot is placed in its initial shape before the trial).
    """
    phi_cmd = np.asarray(phi_cmd, dtype=float)
    target = phi_cmd.copy()
    if actuator.noise_rad > 0:
        # tracking error: white noise through two first-order filters of time constant
        # noise_corr_s (a smooth process, stationary sd noise_rad), on the target
        b = np.exp(-dt / max(actuator.noise_corr_s, dt))
        drive = rng.normal(size=phi_cmd.shape) * np.sqrt(1 - b * b)
        x0 = rng.normal(size=2)
        x = lfilter([1.0], [1.0, -b], drive, axis=0, zi=(b * x0)[None, :])[0]
        y = lfilter([1 - b], [1.0, -b], x, axis=0, zi=(b * x0)[None, :])[0]
        target = target + y * actuator.noise_rad * (1 + b) / np.sqrt(1 + b * b)
    out = target
    if actuator.lag_s > 0:
        a = np.exp(-dt / actuator.lag_s)
        zi = (a * target[0])[None, :]
        out = lfilter([1 - a], [1, -a], target, axis=0, zi=zi)[0]
    return out
