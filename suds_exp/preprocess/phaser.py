"""Step 4, phase: the Phaser algorithm (Revzen & Guckenheimer 2008, Phys. Rev. E 78, 051907).

Implemented from the published description:

1. each channel is centred and scaled, and its protophase is the angle of its analytic
   signal (Hilbert transform). The finite record is extended at both ends by its own
   periodic continuation (shifted by whole periods, estimated from the protophase's
   mean rate) so the transform has no edge transient inside the data;
2. each channel's protophase is corrected by a Fourier series that makes it advance
   uniformly: theta = phi + sum_{n=1..N} (2/n) Im(S_n e^{i n phi}), with
   S_n = <e^{-i n phi}> over the training data (the protophase-to-phase transform of
   Kralemann et al. 2008, the density form of Phaser's series correction);
3. the corrected channel phases are aligned by their mean circular offsets and combined
   with the weights of least error variance (`min_variance_weights`), the errors' covariance
   estimated from what each channel's phase does faster than the cycle
   (`channel_error_covariance`): each channel counts by its signal to noise, as in the
   reference implementation. Channels whose protophase does not advance at channel 0's
   rate, within a factor `MAX_RATE_RATIO`, are left out;
4. the combined phase gets a final Fourier-series correction of the same kind;
5. phase zero is a Poincare section: the mean phase at which the first channel crosses
   its mean upwards.

`Phaser` follows the scikit-learn estimator contract: hyper-parameters in ``__init__``,
`fit` on a list of trials (arrays of shape (n_frames, n_channels)), fitted state in
attributes ending in ``_``, `transform` of one trial -> unwrapped phase (rad).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.ndimage import uniform_filter1d
from scipy.signal import hilbert

from suds_exp.errors import PreprocessError

TWO_PI = 2 * np.pi
#: Channels whose protophase advances faster or slower than channel 0's by more than this
#: factor are left out of the combination.
MAX_RATE_RATIO = 1.25


def _wrap(angle):
    return (np.asarray(angle) + np.pi) % TWO_PI - np.pi


def _circmean(angle: np.ndarray) -> float:
    return float(np.angle(np.mean(np.exp(1j * angle))))


def _period_frames(z: np.ndarray) -> float:
    """Mean period of a centred signal, frames, from its unpadded protophase's rate."""
    phase = np.unwrap(np.angle(hilbert(z)))
    n = len(z)
    mid = slice(n // 4, n - n // 4) if n >= 8 else slice(0, n)
    frames = np.arange(n)[mid]
    slope = np.polyfit(frames, phase[mid], 1)[0] if len(frames) >= 2 else 0.0
    return TWO_PI / slope if slope > 0 else np.inf


def _pad_periodic(z: np.ndarray, pad_cycles: float) -> tuple[np.ndarray, int]:
    """``z`` extended at both ends by whole-period shifted copies of itself."""
    n = len(z)
    period = _period_frames(z)
    if not np.isfinite(period) or pad_cycles <= 0:
        return z, 0
    pad = int(round(pad_cycles * period))
    shift = int(round(np.ceil(pad / period) * period))
    if pad < 1 or shift > n:
        pad = min(pad, int(n // period) * int(period))
        shift = int(round(np.ceil(pad / period) * period)) if pad else 0
        if pad < 1 or shift > n:
            return z, 0
    left = z[shift - pad : shift]
    right = z[n - shift : n - shift + pad]
    return np.concatenate([left, z, right]), pad


def protophases(z: np.ndarray, pad_cycles: float) -> np.ndarray:
    """Hilbert protophase of each channel, (n_frames, n_channels) -> same shape, rad wrapped."""
    out = np.empty_like(z)
    for k in range(z.shape[1]):
        padded, pad = _pad_periodic(z[:, k], pad_cycles)
        out[:, k] = np.angle(hilbert(padded))[pad : pad + len(z)]
    return out


def _series_coefficients(phi: np.ndarray, order: int) -> np.ndarray:
    """S_n = <e^{-i n phi}>, n = 1..order, for phi of shape (n,) -> (order,) complex."""
    n = np.arange(1, order + 1)
    return np.exp(-1j * np.outer(phi, n)).mean(axis=0)


def _apply_series(phi: np.ndarray, coef: np.ndarray) -> np.ndarray:
    """theta = phi + sum_n (2/n) Im(S_n e^{i n phi}); phi of any shape, rad."""
    n = np.arange(1, len(coef) + 1)
    terms = np.exp(1j * phi[..., None] * n) * coef
    return phi + (2.0 * terms.imag / n).sum(axis=-1)


def channel_error_covariance(thetas: Sequence[np.ndarray], offsets: np.ndarray) -> np.ndarray:
    """Covariance of the channels' phase errors, estimated from their own records.

    The true phase of an oscillator advances smoothly, so what a channel's corrected phase
    does faster than the cycle (measurement noise, cycle-to-cycle changes of its waveform,
    wobble the series correction left) is error: the part of each aligned, unwrapped
    channel phase that a moving mean over one period removes.

    Parameters
    ----------
    thetas : list of arrays of shape (n_frames, n_channels), rad
        Corrected channel phases of each training record.
    offsets : array of shape (n_channels,), rad
        Circular offset of each channel from channel 0.

    Returns
    -------
    array of shape (n_channels, n_channels), rad^2
    """
    n_ch = len(offsets)
    acc, count = np.zeros((n_ch, n_ch)), 0
    for th in thetas:
        aligned = np.unwrap(th[:, 0])[:, None] + _wrap(th - offsets - th[:, :1])
        advance = aligned[-1, 0] - aligned[0, 0]
        if advance <= 0:
            continue
        half = int(TWO_PI / advance * (len(th) - 1)) // 2
        if len(th) <= 4 * half + 1:
            continue
        # an odd window, so a steady ramp passes unchanged; ends (biased by the filter's
        # edge handling) left out
        mean = uniform_filter1d(aligned, 2 * half + 1, axis=0, mode="nearest")
        resid = (aligned - mean)[half + 1 : len(th) - half - 1]
        acc += resid.T @ resid
        count += len(resid)
    if count == 0:
        return np.eye(n_ch)
    return acc / count


def min_variance_weights(cov: np.ndarray, keep: np.ndarray, ridge: float = 1e-6) -> np.ndarray:
    """Weights (sum 1, >= 0) of the combination of channel phases with the least error variance.

    Minimises w' C w subject to sum(w) = 1 over the kept channels: w = C^-1 1 / 1' C^-1 1,
    the inverse-variance weights when the errors are independent, so each channel counts
    by its signal to noise (Revzen & Guckenheimer 2008 weigh channels by their z-scored
    amplitude for the same reason). Channels whose weight would be negative are dropped one
    at a time (a negative weight bets on a correlation that new data need not repeat).

    Parameters
    ----------
    cov : array of shape (n_channels, n_channels), rad^2
    keep : bool array of shape (n_channels,)
    ridge : float
        Added to the diagonal as a fraction of its mean, so duplicated channels stay
        solvable.

    Returns
    -------
    array of shape (n_channels,), 0 for the channels left out
    """
    active = np.flatnonzero(keep)
    while True:
        c = cov[np.ix_(active, active)]
        c = c + ridge * max(float(np.trace(c)) / len(active), 1e-300) * np.eye(len(active))
        w = np.linalg.solve(c, np.ones(len(active)))
        if np.all(w >= 0) or len(active) == 1:
            break
        active = np.delete(active, int(np.argmin(w)))
    out = np.zeros(len(keep))
    out[active] = np.abs(w) / np.abs(w).sum()
    return out


class Phaser:
    """Phase estimator of a noisy oscillator from several channels.

    Parameters
    ----------
    order : int
        Order N of the Fourier-series corrections.
    pad_cycles : float
        Periodic extension at each end of a record before the Hilbert transform, cycles.

    Attributes (after `fit`)
    ------------------------
    mean_, scale_ : arrays of shape (n_channels,)
        Centring and scaling of the channels.
    channel_series_ : complex array of shape (n_channels, order)
        Per-channel correction coefficients S_n.
    offsets_ : array of shape (n_channels,), rad
        Circular offset of each corrected channel phase from channel 0.
    weights_ : array of shape (n_channels,)
        Combination weights (sum 1); 0 for a channel left out.
    channel_ok_ : bool array of shape (n_channels,)
        Channels whose protophase goes round once per cycle of channel 0 (kept).
    final_series_ : complex array of shape (order,)
    zero_ : float, rad
        Phase of the Poincare section, subtracted so it becomes phase 0.
    """

    def __init__(self, order: int = 10, pad_cycles: float = 2.0):
        self.order = order
        self.pad_cycles = pad_cycles

    # -- the steps, shared by fit and transform ------------------------------------
    def _channel_phases(self, x: np.ndarray) -> np.ndarray:
        z = (np.asarray(x, dtype=float) - self.mean_) / self.scale_
        phi = protophases(z, self.pad_cycles)
        return np.stack(
            [_apply_series(phi[:, k], self.channel_series_[k]) for k in range(phi.shape[1])], axis=1
        )

    def _combine(self, theta: np.ndarray) -> np.ndarray:
        dev = _wrap(theta - self.offsets_ - theta[:, :1])
        return theta[:, 0] + dev @ self.weights_

    def fit(self, trials: Sequence[np.ndarray]) -> Phaser:
        """Train on records, each array of shape (n_frames, n_channels)."""
        if int(self.order) < 1:
            raise PreprocessError(f"Phaser: order must be >= 1, got {self.order}")
        trials = [np.asarray(x, dtype=float) for x in trials]
        if not trials or any(x.ndim != 2 or len(x) < 8 for x in trials):
            raise PreprocessError("Phaser: need records of shape (n_frames >= 8, n_channels)")
        pooled = np.concatenate(trials)
        self.mean_ = pooled.mean(axis=0)
        self.scale_ = pooled.std(axis=0)
        if np.any(self.scale_ <= 0):
            raise PreprocessError("Phaser: a channel is constant; it carries no phase")
        order = int(self.order)
        proto = [protophases((x - self.mean_) / self.scale_, self.pad_cycles) for x in trials]
        allphi = np.concatenate(proto)
        self.channel_series_ = np.stack(
            [_series_coefficients(allphi[:, k], order) for k in range(allphi.shape[1])]
        )
        thetas = [
            np.stack(
                [_apply_series(p[:, k], self.channel_series_[k]) for k in range(p.shape[1])], 1
            )
            for p in proto
        ]
        alltheta = np.concatenate(thetas)
        self.offsets_ = np.array(
            [_circmean(alltheta[:, k] - alltheta[:, 0]) for k in range(alltheta.shape[1])]
        )
        # a channel that does not go round once per cycle of channel 0 (a flipper opening
        # twice per cycle, a channel with no oscillation) carries no usable phase
        rate = np.array(
            [
                np.mean([np.unwrap(p[:, k])[-1] - np.unwrap(p[:, k])[0] for p in proto])
                for k in range(allphi.shape[1])
            ]
        )
        ratio = rate / rate[0] if rate[0] > 0 else np.ones_like(rate)
        self.channel_ok_ = (ratio > 1 / MAX_RATE_RATIO) & (ratio < MAX_RATE_RATIO)
        self.weights_ = min_variance_weights(
            channel_error_covariance(thetas, self.offsets_), self.channel_ok_
        )
        combined = [self._combine(th) for th in thetas]
        self.final_series_ = _series_coefficients(_wrap(np.concatenate(combined)), order)
        # Poincare section: channel 0 crossing its mean upwards
        at_section = []
        for x, c in zip(trials, combined, strict=True):
            psi = _apply_series(_wrap(c), self.final_series_)
            z0 = x[:, 0] - self.mean_[0]
            i = np.flatnonzero((z0[:-1] < 0) & (z0[1:] >= 0))
            frac = -z0[i] / (z0[i + 1] - z0[i])
            step = _wrap(psi[i + 1] - psi[i])
            at_section.append(psi[i] + frac * step)
        events = np.concatenate(at_section)
        if events.size == 0:
            raise PreprocessError("Phaser: the first channel never crosses its mean; no cycles")
        self.zero_ = _circmean(events)
        return self

    def transform(self, x: np.ndarray) -> np.ndarray:
        """Phase of one record (n_frames, n_channels) -> (n_frames,), rad, unwrapped,
        starting in [0, 2 pi) at the first frame."""
        x = np.asarray(x, dtype=float)
        psi = _apply_series(_wrap(self._combine(self._channel_phases(x))), self.final_series_)
        wrapped = np.mod(psi - self.zero_, TWO_PI)
        return np.unwrap(wrapped)

    # -- storage ---------------------------------------------------------------------
    def to_dict(self) -> dict:
        """The fitted state as plain JSON-ready values."""
        return {
            "order": int(self.order),
            "pad_cycles": float(self.pad_cycles),
            "mean": self.mean_.tolist(),
            "scale": self.scale_.tolist(),
            "channel_series": [[c.real, c.imag] for row in self.channel_series_ for c in row],
            "n_channels": int(len(self.mean_)),
            "offsets": self.offsets_.tolist(),
            "weights": self.weights_.tolist(),
            "channel_ok": self.channel_ok_.tolist(),
            "final_series": [[c.real, c.imag] for c in self.final_series_],
            "zero": self.zero_,
        }

    @classmethod
    def from_dict(cls, state: dict) -> Phaser:
        p = cls(state["order"], state["pad_cycles"])
        p.mean_ = np.asarray(state["mean"])
        p.scale_ = np.asarray(state["scale"])
        cs = np.asarray(state["channel_series"])
        p.channel_series_ = (cs[:, 0] + 1j * cs[:, 1]).reshape(state["n_channels"], -1)
        p.offsets_ = np.asarray(state["offsets"])
        p.weights_ = np.asarray(state["weights"])
        p.channel_ok_ = np.asarray(state["channel_ok"], dtype=bool)
        fs = np.asarray(state["final_series"])
        p.final_series_ = fs[:, 0] + 1j * fs[:, 1]
        p.zero_ = float(state["zero"])
        return p


def cycles(phase: np.ndarray) -> np.ndarray:
    """Cycle number of each frame: how many Poincare sections the phase has passed (int)."""
    return np.floor(np.asarray(phase) / TWO_PI).astype(np.int64)
