"""Step 5, rates: local-polynomial differentiation and the body velocity in the body frame.

The differentiator fits a polynomial of order ``polyorder`` over a sliding window of
``window`` frames (odd) and takes its analytic derivative at the centre; the first and
last half-windows use the fit over the first / last window. With ``kernel="box"`` every
frame of the window weighs the same: the Savitzky-Golay filter
(`scipy.signal.savgol_filter` with ``deriv=1``). With ``kernel="triweight"`` frame j of
the window weighs (1 - (j / (h + 1))^2)^3, h the half-width: a weighted local polynomial.
At the same window its response follows the ideal differentiator further into the band
(it blurs sharp changes of velocity less) and has almost none of the box's side lobes
above it (the marker noise there is cut), at the cost of somewhat more noise within the
band. On the simulator's default dataset, with each kernel at its best windows, it leaves
a body-velocity error about 0.15 % (vx) and 0.2 % (vy) of RMS vx lower than the box.
Body velocity: the derivatives of the body origin's plane position and of the unwrapped
heading, with the linear velocity rotated into the body frame at each frame.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.ndimage import convolve1d
from scipy.signal import savgol_filter

#: Weightings of the differentiator's window (see the module docstring).
KERNELS = ("triweight", "box")


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


@dataclass(frozen=True)
class Differentiator:
    """A preprocessing version's differentiator (its ``sg_*`` parameters), the one both
    preprocessing and the discrepancy replay apply, so their rates compare like with like.

    When ``window_cycles`` > 0 and the trial's frequency (Hz) is known, the window is
    ``window_cycles * T**window_exponent`` seconds, T = 1 / frequency the gait period in s:
    ``window_cycles`` cycles at a 1 s period, growing as the period to the power
    ``window_exponent`` (1 = a fixed number of cycles, 0 = fixed seconds; in between, a
    slower gait, whose features are slower, gets a longer window but fewer cycles, since
    the marker noise the window averages is the same at every frequency). Otherwise
    ``window_s`` seconds. ``polyorder`` and ``kernel`` as in `derivative`.
    Build one with `from_params`; `suds_exp.preprocess.get_version` gives a version's.
    """

    window_s: float
    window_cycles: float
    window_exponent: float
    polyorder: int
    kernel: str

    @classmethod
    def from_params(cls, params: Mapping[str, Any]) -> Differentiator:
        """The differentiator of a version's parameters (`suds_exp.preprocess.DEFAULTS`
        keys). A version stored before ``sg_window_exponent`` / ``sg_kernel`` existed
        used a fixed number of cycles and the box kernel."""
        return cls(
            window_s=float(params["sg_window_s"]),
            window_cycles=float(params["sg_window_cycles"]),
            window_exponent=float(params.get("sg_window_exponent", 1.0)),
            polyorder=int(params["sg_polyorder"]),
            kernel=str(params.get("sg_kernel", "box")),
        )

    def window(self, rate_hz: float, frequency_hz: float | None, n_frames: int) -> int:
        """Odd window length in frames for a trial captured at ``rate_hz`` (Hz) with gait
        frequency ``frequency_hz`` (Hz, None = unknown), ``n_frames`` long."""
        if self.window_cycles > 0 and frequency_hz:
            window_s = self.window_cycles * (1.0 / frequency_hz) ** self.window_exponent
        else:
            window_s = self.window_s
        return window_frames(window_s, rate_hz, self.polyorder, n_frames)

    def __call__(self, x: np.ndarray, dt: float, window: int) -> np.ndarray:
        """Time derivative of ``x`` (n_frames, ...) along axis 0 over ``window`` frames
        (from `window`); units of x per second, ``dt`` the frame interval in s."""
        return derivative(x, dt, window, self.polyorder, self.kernel)

    def body_velocity(
        self, xy: np.ndarray, heading: np.ndarray, dt: float, window: int
    ) -> np.ndarray:
        """`body_velocity` with this differentiator: (n_frames, 3) mm/s, mm/s, rad/s."""
        return body_velocity(xy, heading, dt, window, self.polyorder, self.kernel)


def differentiator_window(
    params: dict, rate_hz: float, frequency_hz: float | None, n_frames: int
) -> int:
    """A version's differentiator window, frames (`Differentiator.window`)."""
    return Differentiator.from_params(params).window(rate_hz, frequency_hz, n_frames)


@functools.lru_cache(maxsize=64)
def _fit_matrix(window: int, polyorder: int, kernel: str) -> np.ndarray:
    """(polyorder + 1, window): window samples -> coefficients of the weighted polynomial
    in u = (frames from the window's centre) / (half-width + 1), which keeps the normal
    equations well conditioned for long windows and high orders."""
    half = window // 2
    u = np.arange(-half, half + 1, dtype=float) / (half + 1)
    if kernel == "triweight":
        weights = (1.0 - u**2) ** 3
    elif kernel == "box":
        weights = np.ones(window)
    else:
        raise ValueError(f"kernel={kernel!r}: expected one of {', '.join(KERNELS)}")
    basis = np.vander(u, polyorder + 1, increasing=True)
    return np.linalg.solve(basis.T @ (weights[:, None] * basis), (basis * weights[:, None]).T)


def local_polynomial(
    x: np.ndarray, window: int, polyorder: int, kernel: str = "box", deriv: int = 0
) -> np.ndarray:
    """Local polynomial fit of ``x`` (n_frames, ...) along axis 0, evaluated at each frame:
    the value (``deriv=0``, units of x) or the first derivative (``deriv=1``, units of x per
    frame). ``window`` odd, polyorder < window <= n_frames; ``kernel`` one of `KERNELS`.
    The first and last half-windows use the fit over the first / last window."""
    x = np.asarray(x, dtype=float)
    fit = _fit_matrix(window, polyorder, kernel)
    half, n = window // 2, len(x)
    scale = 1.0 / (half + 1) ** deriv  # d/dframe = d/du / (half + 1)
    # interior: a fixed weighted sum of the window centred on each frame
    out = convolve1d(x, fit[deriv][::-1] * scale, axis=0, mode="nearest")
    powers = np.arange(polyorder + 1)
    for start, positions in ((0, np.arange(half)), (n - window, np.arange(n - half, n))):
        coef = np.tensordot(fit, x[start : start + window], axes=(1, 0))
        u = (positions - (start + half)) / (half + 1)
        if deriv:
            basis = powers[1:] * u[:, None] ** (powers[1:] - 1)
            out[positions] = np.tensordot(basis, coef[1:], axes=(1, 0)) * scale
        else:
            out[positions] = np.tensordot(u[:, None] ** powers, coef, axes=(1, 0))
    return out


def derivative(
    x: np.ndarray, dt: float, window: int, polyorder: int, kernel: str = "box"
) -> np.ndarray:
    """Time derivative of ``x`` (n_frames, ...) along axis 0; units of x per second.

    ``dt`` frame interval, s; ``window`` odd number of frames (at most n_frames);
    ``kernel`` one of `KERNELS` (``box`` is the Savitzky-Golay filter).
    """
    x = np.asarray(x, dtype=float)
    if window <= polyorder:
        # too short to fit the polynomial: fall back to central differences
        return np.gradient(x, dt, axis=0)
    if kernel == "box":
        return savgol_filter(x, window, polyorder, deriv=1, delta=dt, axis=0, mode="interp")
    return local_polynomial(x, window, polyorder, kernel, deriv=1) / dt


def smooth(x: np.ndarray, window: int, polyorder: int) -> np.ndarray:
    """Savitzky-Golay smoothing of ``x`` (n_frames, ...) along axis 0 (same units);
    ``window`` <= ``polyorder`` leaves it as it is."""
    if window <= polyorder:
        return np.asarray(x, dtype=float).copy()
    return savgol_filter(x, window, polyorder, axis=0, mode="interp")


def body_velocity(
    xy: np.ndarray,
    heading: np.ndarray,
    dt: float,
    window: int,
    polyorder: int,
    kernel: str = "box",
) -> np.ndarray:
    """Body velocity v_b = (vx, vy, wz): (n_frames, 3) in mm/s, mm/s, rad/s, body frame.

    ``xy`` (n_frames, 2) mm: body origin in the plane; ``heading`` (n_frames,) rad,
    unwrapped: body +X in the plane; ``window``, ``polyorder``, ``kernel`` as in
    `derivative`.
    """
    rates = derivative(np.column_stack([xy, heading]), dt, window, polyorder, kernel)
    c, s = np.cos(heading), np.sin(heading)
    vx = c * rates[:, 0] + s * rates[:, 1]
    vy = -s * rates[:, 0] + c * rates[:, 1]
    return np.column_stack([vx, vy, rates[:, 2]])
