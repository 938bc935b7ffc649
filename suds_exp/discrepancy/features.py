"""The feature library of the discovered correction: physically meaningful signals.

When no named effect closes the gap, the workflow fits an additive correction to the
replayed channels as a sparse combination of these features (`discover.py`). Each
feature is evaluated at every scored sample of every replay window, from the model's own
replay (body velocity and acceleration: what the model would know when it runs) and
from the measured inputs and states the replay is driven by (actuated shape r_a and its
rates, passive shape r_p as the flippers' state, distance travelled, time in the trial).

Every feature carries a unit and a family; the family is what the discovered term is
said to resemble (`PHYSICS`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.signal import savgol_filter

from suds_exp.discrepancy.replay import WindowSet, window_field

#: Physics a term of each feature family most resembles.
PHYSICS: dict[str, str] = {
    "acceleration": "inertia",
    "distance": "compaction",
    "sign": "asymmetric drag",
    "rate": "damping",
    "velocity": "drag scaling",
    "time": "drift over the trial",
    "shape": "shape-dependent force",
    "product": "shape-dependent force",
    "constant": "offset",
}

#: Units of the replayed channels (vx, vy, wz, then passive-shape coordinates).
CHANNEL_UNITS = {"vx": "mm/s", "vy": "mm/s", "wz": "rad/s"}


def channel_unit(channel: str) -> str:
    """Unit of a compared channel (r_p coordinates are mm)."""
    return CHANNEL_UNITS.get(channel, "mm")


@dataclass(frozen=True)
class Feature:
    """One column of the library: ``name`` (as written in equations), unit, family."""

    name: str
    unit: str
    family: str


#: Window (s) of the local cubic that differentiates the measured body velocity.
ACC_WINDOW_S = 0.21


def _trial_arrays(samples: pd.DataFrame) -> dict[int, pd.DataFrame]:
    out = {}
    for tid, tr in samples.sort_values(["trial_id", "t"]).groupby("trial_id", sort=True):
        tr = tr.reset_index(drop=True)
        t = tr["t"].to_numpy(float)
        dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
        w = max(5, int(round(ACC_WINDOW_S / dt)) | 1)
        for ch in ("vx", "vy", "wz"):
            x = tr[ch].to_numpy(float)
            tr[f"acc_{ch}"] = (
                savgol_filter(x, w, 3, deriv=1, delta=dt) if len(x) > w else np.gradient(x, dt)
            )
        speed = np.hypot(tr["vx"].to_numpy(float), tr["vy"].to_numpy(float))
        # path length from the trial's start (mm -> m), as the replay's compaction adapter
        tr["dist_m"] = (
            np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t))])
            + np.nanmean(speed) * t[0]
        ) / 1000.0
        out[int(tid)] = tr
    return out


def _rate(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """d/dt along axis 1 of (n_windows, n_samples, ...) arrays with per-window times."""
    dt = np.nanmedian(np.diff(t, axis=1), axis=1)
    dt = np.where(np.isfinite(dt) & (dt > 0), dt, 1.0)
    # windows shorter than the longest are NaN padded: extend each linearly by one
    # sample so the gradient at its last sample is one-sided instead of NaN
    valid = np.isfinite(t)
    last = np.maximum(valid.sum(axis=1) - 1, 1)
    held = x.copy()
    for k in range(x.shape[0]):
        if last[k] + 1 < x.shape[1]:
            held[k, last[k] + 1] = 2 * x[k, last[k]] - x[k, last[k] - 1]
    g = np.gradient(held, axis=1)
    g[~valid] = np.nan
    return g / dt.reshape((-1,) + (1,) * (x.ndim - 1))


def feature_library(
    windows: WindowSet, samples: pd.DataFrame, sim: np.ndarray
) -> tuple[np.ndarray, list[Feature]]:
    """Every feature at every scored sample.

    Parameters
    ----------
    windows : WindowSet
        The replay windows (the undecimated ones the gap is measured on).
    samples : DataFrame
        The samples the windows were cut from (`suds_exp.preprocess.load_samples`).
    sim : array of shape (n_windows, n_samples, n_channels)
        The model's replay of those windows (channels as `replay`).

    Returns
    -------
    X : array of shape (n_windows, n_samples, n_features), NaN where a window is padded
    features : list of `Feature`, one per column
    """
    t = window_field(windows, "t")
    ra = window_field(windows, "ra")
    n_win, n_s = t.shape
    per = _trial_arrays(samples)
    rp_cols = [c for c in samples.columns if c.startswith("rp_") and samples[c].notna().any()]
    drp_cols = [f"d{c}" for c in rp_cols if f"d{c}" in samples.columns]
    dra = np.full((n_win, n_s, 2), np.nan)
    rp = np.full((n_win, n_s, len(rp_cols)), np.nan)
    drp = np.full((n_win, n_s, len(drp_cols)), np.nan)
    acc_meas = np.full((n_win, n_s, 3), np.nan)
    dist = np.full((n_win, n_s), np.nan)
    t_trial = np.full((n_win, n_s), np.nan)
    for k, tid in enumerate(windows.trial_id):
        tr = per[int(tid)]
        ok = np.isfinite(t[k])
        tt = tr["t"].to_numpy(float)
        idx = np.clip(np.searchsorted(tt, t[k, ok] - 1e-9), 0, len(tt) - 1)
        dra[k, ok] = tr[["dra_1", "dra_2"]].to_numpy(float)[idx]
        rp[k, ok] = tr[rp_cols].to_numpy(float)[idx]
        drp[k, ok] = tr[drp_cols].to_numpy(float)[idx]
        dist[k, ok] = tr["dist_m"].to_numpy(float)[idx]
        acc_meas[k, ok] = tr[["acc_vx", "acc_vy", "acc_wz"]].to_numpy(float)[idx]
        t_trial[k, ok] = tt[idx] - tt[0]
    v = sim[..., :3]
    acc = _rate(v, t)
    ddra = _rate(dra, t)
    cols: list[tuple[Feature, np.ndarray]] = [
        (Feature("1", "-", "constant"), np.ones((n_win, n_s)))
    ]
    vel = (("v_x", "mm/s"), ("v_y", "mm/s"), ("w_z", "rad/s"))
    for i, (name, unit) in enumerate(vel):
        cols.append((Feature(name, unit, "velocity"), v[..., i]))
    for i, (name, unit) in enumerate(
        zip(("a_x", "a_y", "alpha_z"), ("mm/s^2", "mm/s^2", "rad/s^2"), strict=True)
    ):
        # measured: the inertia's own form, v = v_model - tau dv/dt (equation error)
        cols.append((Feature(name, unit, "acceleration"), acc_meas[..., i]))
        cols.append((Feature(f"{name}^model", unit, "acceleration"), acc[..., i]))
    # sliding forward and backward may meet different drag: the forward part of v_x
    cols.append((Feature("max(v_x,0)", "mm/s", "sign"), np.maximum(v[..., 0], 0.0)))
    cols.append((Feature("|w_z|", "rad/s", "sign"), np.abs(v[..., 2])))
    for i in range(2):
        cols.append((Feature(f"phi{i + 1}", "rad", "shape"), ra[..., i]))
        cols.append((Feature(f"dphi{i + 1}/dt", "rad/s", "rate"), dra[..., i]))
        cols.append((Feature(f"d2phi{i + 1}/dt2", "rad/s^2", "acceleration"), ddra[..., i]))
    for i, c in enumerate(rp_cols):
        cols.append((Feature(c, "mm", "shape"), rp[..., i]))
    for i, c in enumerate(drp_cols):
        cols.append((Feature(f"{c[1:]}'", "mm/s", "rate"), drp[..., i]))
    cols.append((Feature("s", "m", "distance"), dist))
    cols.append((Feature("t", "s", "time"), t_trial))
    for i, (name, unit) in enumerate(vel):
        cols.append((Feature(f"s*{name}", f"m {unit}", "distance"), dist * v[..., i]))
        cols.append((Feature(f"t*{name}", f"s {unit}", "time"), t_trial * v[..., i]))
    cols.append((Feature("phi1*phi2", "rad^2", "product"), ra[..., 0] * ra[..., 1]))
    cols.append((Feature("dphi1/dt*dphi2/dt", "rad^2/s^2", "product"), dra[..., 0] * dra[..., 1]))
    for i in range(2):
        cols.append(
            (Feature(f"phi{i + 1}*dphi{i + 1}/dt", "rad^2/s", "product"), ra[..., i] * dra[..., i])
        )
        cols.append((Feature(f"phi{i + 1}^2", "rad^2", "product"), ra[..., i] ** 2))
    features = [f for f, _ in cols]
    X = np.stack([x for _, x in cols], axis=-1)
    X[~np.isfinite(t)] = np.nan
    return X, features
