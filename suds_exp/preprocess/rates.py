"""Step 5, rates: Savitzky-Golay differentiation and the body velocity in the body frame.

The differentiator fits a polynomial of order ``polyorder`` over a sliding window of
``window`` frames (odd) and takes its analytic derivative at the centre
(`scipy.signal.savgol_filter` with ``deriv=1``; the ends use the fit over the first /
last window). Body velocity: the derivatives of the body origin's plane position and of
the unwrapped heading, with the linear velocity rotated into the body frame at each frame.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter


def window_frames(window_s: float, rate_hz: float, polyorder: int, n_frames: int) -> int:
    """Odd window length in frames for ``window_s`` seconds, at least polyorder + 2 and
    at most the (odd) record length; 1 (no filtering) when ``window_s`` is 0."""
    if window_s <= 0:
        return 1
    w = int(round(window_s * rate_hz))
    w = max(w, polyorder + 2)
    w += 1 - w % 2
    limit = n_frames if n_frames % 2 else n_frames - 1
    return min(w, limit)


def differentiator_window(
    params: dict, rate_hz: float, frequency_hz: float | None, n_frames: int
) -> int:
    """A version's differentiator window, frames.

    When ``sg_window_cycles`` is set and the trial's frequency (Hz) is known, the window is
    ``sg_window_cycles * T**sg_window_exponent`` seconds, T = 1 / frequency the gait period
    in s: ``sg_window_cycles`` cycles at a 1 s period, growing as the period to the power
    ``sg_window_exponent`` (1 = a fixed number of cycles, 0 = fixed seconds; in between, a
    slower gait, whose features are slower, gets a longer window but fewer cycles, since
    the marker noise the window averages is the same at every frequency). Otherwise
    ``sg_window_s`` seconds."""
    if params["sg_window_cycles"] > 0 and frequency_hz:
        # versions made before the exponent existed used a fixed number of cycles
        exponent = params.get("sg_window_exponent", 1.0)
        window_s = params["sg_window_cycles"] * (1.0 / frequency_hz) ** exponent
    else:
        window_s = params["sg_window_s"]
    return window_frames(window_s, rate_hz, params["sg_polyorder"], n_frames)


def derivative(x: np.ndarray, dt: float, window: int, polyorder: int) -> np.ndarray:
    """Time derivative of ``x`` (n_frames, ...) along axis 0; units of x per second.

    ``dt`` frame interval, s; ``window`` odd number of frames.
    """
    if window <= polyorder:
        # too short to fit the polynomial: fall back to central differences
        return np.gradient(x, dt, axis=0)
    return savgol_filter(x, window, polyorder, deriv=1, delta=dt, axis=0, mode="interp")


def smooth(x: np.ndarray, window: int, polyorder: int) -> np.ndarray:
    """Savitzky-Golay smoothing of ``x`` (n_frames, ...) along axis 0 (same units);
    ``window`` <= ``polyorder`` leaves it as it is."""
    if window <= polyorder:
        return np.asarray(x, dtype=float).copy()
    return savgol_filter(x, window, polyorder, axis=0, mode="interp")


def body_velocity(
    xy: np.ndarray, heading: np.ndarray, dt: float, window: int, polyorder: int
) -> np.ndarray:
    """Body velocity v_b = (vx, vy, wz): (n_frames, 3) in mm/s, mm/s, rad/s, body frame.

    ``xy`` (n_frames, 2) mm: body origin in the plane; ``heading`` (n_frames,) rad,
    unwrapped: body +X in the plane.
    """
    rates = derivative(np.column_stack([xy, heading]), dt, window, polyorder)
    c, s = np.cos(heading), np.sin(heading)
    vx = c * rates[:, 0] + s * rates[:, 1]
    vy = -s * rates[:, 0] + c * rates[:, 1]
    return np.column_stack([vx, vy, rates[:, 2]])
