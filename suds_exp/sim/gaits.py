"""The actuator model (command -> realised joint angles); the gaits live in `suds_exp.robot`
(imported here, where the simulator's callers have always found them)."""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

from suds_exp.robot import FREQUENCIES_HZ, GAITS, gait_shape
from suds_exp.sim.config import Actuator

__all__ = ["FREQUENCIES_HZ", "GAITS", "actuate", "gait_shape"]


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
