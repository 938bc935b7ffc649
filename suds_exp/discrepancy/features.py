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

from suds_exp.campaign.conditions import format_condition, round_hz
from suds_exp.discrepancy.replay import WindowSet, window_field

#: Physics a term of each feature family most resembles. The mapping is the form each
#: physical effect takes in a first-order correction of a quasi-static model:
#: - acceleration: momentum makes the body lag its quasi-static velocity,
#:   v = v_qs - tau dv/dt (`channel_features`' own-channel rate for the body channels,
#:   or the measured acceleration): inertia;
#: - rate: a viscous torque opposes the hinge rate, so the flippers lag their
#:   quasi-static opening, r_p = r_p,qs - tau dr_p/dt (the own-channel rate of the
#:   passive shape), or the body feels a force in the shape rates: damping;
#: - distance: a resistance that grows with distance travelled s scales the velocity
#:   by (1 - k s), a term in s times the velocity or times a named effect: compaction;
#: - sign: a force that differs sliding forward and backward, max(v_x, 0) or a named
#:   effect gated by the sliding direction: asymmetric drag;
#: - velocity: a term in the model's own velocity rescales every drag: drag scaling;
#: - time: a slow change along the trial not tied to distance: drift;
#: - shape, product: a force that depends on where in the gait the body is, the generic
#:   periodic correction that names no mechanism.
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
    "effect": "the named effect's own scale",
}

#: Units of the replayed channels (vx, vy, wz, then passive-shape coordinates).
CHANNEL_UNITS = {"vx": "mm/s", "vy": "mm/s", "wz": "rad/s"}


def channel_unit(channel: str) -> str:
    """Unit of a compared channel (r_p coordinates are mm)."""
    return CHANNEL_UNITS.get(channel, "mm")


#: Unit suffix of a channel-specific feature that carries its channel's own unit.
IN_CHANNEL_UNIT = "[channel]"


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
    windows: WindowSet, samples: pd.DataFrame, sim: np.ndarray, half_middle_mm: float
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
    half_middle_mm : float
        Half the middle segment's length, mm (the motor axes' offset from the body
        origin), for each segment's sliding velocity (`segment_sliding`).

    Returns
    -------
    X : array of shape (n_windows, n_samples, n_features), NaN where a window is padded
    features : list of `Feature`, one per column
    """
    t = window_field(windows, "t")
    ra = window_field(windows, "ra")
    m = _measured_at_windows(windows, samples, t)
    v = sim[..., :3]
    cols = [
        *_motion_columns(v, _rate(v, t), m["acc"], ra, half_middle_mm),
        *_shape_columns(ra, m["dra"], _rate(m["dra"], t), m),
        *_course_columns(m["dist"], m["t_trial"], v),
        *_product_columns(ra, m["dra"]),
    ]
    features = [f for f, _ in cols]
    X = np.stack([x for _, x in cols], axis=-1)
    X[~np.isfinite(t)] = np.nan
    return X, features


_VELOCITIES = (("v_x", "mm/s"), ("v_y", "mm/s"), ("w_z", "rad/s"))


def _measured_at_windows(windows: WindowSet, samples: pd.DataFrame, t: np.ndarray) -> dict:
    """The measured samples' fields at each window's times, NaN where a window is padded.

    Returns "dra" (n_win, n_s, 2) rad/s, "rp" and "drp" (n_win, n_s, k) with their column
    names "rp_cols" and "drp_cols", "acc" (n_win, n_s, 3) the measured acceleration,
    "dist" (n_win, n_s) m travelled and "t_trial" (n_win, n_s) s since the trial's start.
    """
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
    return {
        "dra": dra,
        "rp": rp,
        "drp": drp,
        "rp_cols": rp_cols,
        "drp_cols": drp_cols,
        "acc": acc_meas,
        "dist": dist,
        "t_trial": t_trial,
    }


def _motion_columns(v, acc, acc_meas, ra, half_middle_mm) -> list[tuple[Feature, np.ndarray]]:
    """The constant, the model's velocities v (mm/s, rad/s), the measured and the model's
    accelerations, and the sign features of each segment's sliding."""
    cols = [(Feature("1", "-", "constant"), np.ones(v.shape[:2]))]
    for i, (name, unit) in enumerate(_VELOCITIES):
        cols.append((Feature(name, unit, "velocity"), v[..., i]))
    for i, (name, unit) in enumerate(
        zip(("a_x", "a_y", "alpha_z"), ("mm/s^2", "mm/s^2", "rad/s^2"), strict=True)
    ):
        # measured: the inertia's own form, v = v_model - tau dv/dt (equation error)
        cols.append((Feature(name, unit, "acceleration"), acc_meas[..., i]))
        cols.append((Feature(f"{name}^model", unit, "acceleration"), acc[..., i]))
    # sliding forward and backward may meet different drag: the forward part of each
    # segment's sliding velocity (the middle one's is v_x); the head and tail often
    # slide against the body, so the body's v_x alone misses most of an asymmetry
    u = segment_sliding(v, ra, half_middle_mm)
    cols.append((Feature("max(v_x,0)", "mm/s", "sign"), np.maximum(u[..., 0], 0.0)))
    for i, seg in ((1, "head"), (2, "tail")):
        cols.append((Feature(f"max(u_{seg},0)", "mm/s", "sign"), np.maximum(u[..., i], 0.0)))
    cols.append((Feature("|w_z|", "rad/s", "sign"), np.abs(v[..., 2])))
    return cols


def _shape_columns(ra, dra, ddra, m: dict) -> list[tuple[Feature, np.ndarray]]:
    """The actuated angles (rad) with their first and second rates, then r_p and dr_p/dt."""
    cols = []
    for i in range(2):
        cols.append((Feature(f"phi{i + 1}", "rad", "shape"), ra[..., i]))
        cols.append((Feature(f"dphi{i + 1}/dt", "rad/s", "rate"), dra[..., i]))
        cols.append((Feature(f"d2phi{i + 1}/dt2", "rad/s^2", "acceleration"), ddra[..., i]))
    for i, c in enumerate(m["rp_cols"]):
        cols.append((Feature(c, "mm", "shape"), m["rp"][..., i]))
    for i, c in enumerate(m["drp_cols"]):
        cols.append((Feature(f"{c[1:]}'", "mm/s", "rate"), m["drp"][..., i]))
    return cols


def _course_columns(dist, t_trial, v) -> list[tuple[Feature, np.ndarray]]:
    """Distance travelled (m) and time into the trial (s), alone and times each velocity."""
    cols = [(Feature("s", "m", "distance"), dist), (Feature("t", "s", "time"), t_trial)]
    for i, (name, unit) in enumerate(_VELOCITIES):
        cols.append((Feature(f"s*{name}", f"m {unit}", "distance"), dist * v[..., i]))
        cols.append((Feature(f"t*{name}", f"s {unit}", "time"), t_trial * v[..., i]))
    return cols


def _product_columns(ra, dra) -> list[tuple[Feature, np.ndarray]]:
    """Products of the actuated angles (rad) and their rates (rad/s)."""
    cols = [
        (Feature("phi1*phi2", "rad^2", "product"), ra[..., 0] * ra[..., 1]),
        (Feature("dphi1/dt*dphi2/dt", "rad^2/s^2", "product"), dra[..., 0] * dra[..., 1]),
    ]
    for i in range(2):
        cols.append(
            (Feature(f"phi{i + 1}*dphi{i + 1}/dt", "rad^2/s", "product"), ra[..., i] * dra[..., i])
        )
        cols.append((Feature(f"phi{i + 1}^2", "rad^2", "product"), ra[..., i] ** 2))
    return cols


#: Time constants (s) of the lagged copies of each channel (`channel_features`): a
#: logarithmic grid over the lags the library's effects span (body inertia 0-0.5 s; a
#: viscous flipper hinge over the medium's resistance, tenths of a second).
LAG_TAUS_S = (0.05, 0.15, 0.45)


def _lagged(x: np.ndarray, t: np.ndarray, tau: float) -> np.ndarray:
    """First-order lag of x along axis 1 with time constant ``tau`` (s): tau dy/dt = x - y,
    starting at rest on each window's first sample (so a window's first ~tau seconds
    carry a start-up transient). Windows are NaN padded at their ends, which the
    recursion leaves NaN."""
    dt = np.nanmedian(np.diff(t, axis=1), axis=1)
    dt = np.where(np.isfinite(dt) & (dt > 0), dt, 1.0)
    a = np.exp(-dt / tau).reshape((-1,) + (1,) * (x.ndim - 2))
    y = np.empty_like(x)
    y[:, 0] = x[:, 0]
    for k in range(1, x.shape[1]):
        y[:, k] = a * y[:, k - 1] + (1 - a) * x[:, k]
    return y


def channel_features(windows: WindowSet, sim: np.ndarray) -> tuple[np.ndarray, list[Feature]]:
    """Features that differ per channel: the lag of the channel itself.

    A channel that lags its quasi-static value with time constant tau reads
    ``x = x_model - tau dx_model/dt`` to first order, and ``x = lag_tau(x_model)`` (the
    first-order low-pass, tau dx/dt = x_model - x) in full. For the body velocity that
    lag is momentum (inertia: the simulator's own form of it); for the passive shape it
    is the flippers lagging their quasi-static opening, which is what a viscous hinge
    does (damping). A lag too large for the first-order form (a stiff hinge damper
    nearly stops the flippers) is still one term, ``lag_tau(x_model) - x_model``, at the
    nearest of `LAG_TAUS_S` (coefficient 1: that lag in full). So the model's own rate
    and its lagged copies of each channel are features per physics, zero on the
    channels they do not apply to.

    Returns
    -------
    Xc : array (n_windows, n_samples, n_channels, 2 + 2 len(LAG_TAUS_S))
    features : the `Feature` s (the rates' coefficients in s, the lags' in 1)
    """
    t = window_field(windows, "t")
    rate = _rate(sim, t)
    n_ch = sim.shape[-1]
    body = np.arange(n_ch) < 3
    n_lag = len(LAG_TAUS_S)
    Xc = np.zeros(sim.shape + (2 + 2 * n_lag,))
    Xc[..., body, 0] = rate[..., body]
    Xc[..., ~body, 1] = rate[..., ~body]
    for j, tau in enumerate(LAG_TAUS_S):
        lag = _lagged(sim, t, tau) - sim
        Xc[..., body, 2 + j] = lag[..., body]
        Xc[..., ~body, 2 + n_lag + j] = lag[..., ~body]
    Xc[~np.isfinite(t)] = np.nan
    unit = f"{IN_CHANNEL_UNIT}/s"
    return Xc, [
        Feature("d/dt(own velocity)^model", unit, "acceleration"),
        Feature("d/dt(own r_p)^model", unit, "rate"),
    ] + [
        Feature(f"lag_{tau:g}s(own velocity)^model", IN_CHANNEL_UNIT, "acceleration")
        for tau in LAG_TAUS_S
    ] + [Feature(f"lag_{tau:g}s(own r_p)^model", IN_CHANNEL_UNIT, "rate") for tau in LAG_TAUS_S]


def effect_features(
    windows: WindowSet,
    samples: pd.DataFrame,
    sim: np.ndarray,
    delta: np.ndarray,
    label: str,
    half_middle_mm: float,
) -> tuple[np.ndarray, list[Feature]]:
    """Does a named effect's strength vary? Its contribution by distance, time, direction,
    condition.

    ``delta`` is what the named effect adds to every channel (the replay with it minus
    the replay without it, same shape as ``sim``). A physical constant has the same
    strength everywhere; an effect that only mimics the real one is too weak in some
    parts of the data and too strong in others. The covariates are the ones a constant
    drag/inertia parameter could physically depend on: distance travelled (a bed that
    compacts), time in the trial (drift: warming, wear) and the direction each segment
    slides along its own axis (drag that differs forward and backward acts per segment,
    and the outer segments often slide against the body: `segment_sliding`) and the
    condition (gait and frequency). The candidate's own physics
    already says how its contribution changes from gait to gait and with the gait's
    speed (a viscous torque grows with the rates, a granular force does not), so a
    real effect needs no rescaling per condition, while a mimic of another form does
    (hinge damping standing in for locked flippers). ``delta`` itself is in the set so
    that a slightly mis-fitted but constant parameter is absorbed there.
    ``half_middle_mm``: half the middle segment's length, mm (the motor axes' offset
    from the body origin).

    Returns
    -------
    Xc : array (n_windows, n_samples, n_channels, 6 + n_conditions - 1)
    features : `Feature` s named after ``label`` (coefficients in 1, 1/m, 1/s, then 1)
    """
    t = window_field(windows, "t")
    dist, t_trial = _distance_and_time(windows, samples)
    fwd = segment_sliding(sim[..., :3], window_field(windows, "ra"), half_middle_mm) > 0
    info = windows.info
    # the campaign's spelling of a condition ("O@0.5"); the first one is D's own column
    pairs = zip(info["gait"], info["frequency_hz"], strict=True)
    cond = np.array([format_condition((g, round_hz(f))) for g, f in pairs])
    levels = sorted(set(cond))[1:]
    Xc = np.stack(
        [delta, dist[..., None] * delta, t_trial[..., None] * delta]
        + [fwd[..., i, None] * delta for i in range(3)]
        + [(cond == c)[:, None, None] * delta for c in levels],
        axis=-1,
    )
    Xc[~np.isfinite(t)] = np.nan
    d = f"D[{label}]"
    return Xc, [
        Feature(d, IN_CHANNEL_UNIT, "effect"),
        Feature(f"s*{d}", f"m {IN_CHANNEL_UNIT}", "distance"),
        Feature(f"t*{d}", f"s {IN_CHANNEL_UNIT}", "time"),
        Feature(f"[v_x>0]*{d}", IN_CHANNEL_UNIT, "sign"),
        Feature(f"[u_head>0]*{d}", IN_CHANNEL_UNIT, "sign"),
        Feature(f"[u_tail>0]*{d}", IN_CHANNEL_UNIT, "sign"),
    ] + [Feature(f"[{c}]*{d}", IN_CHANNEL_UNIT, "condition") for c in levels]


def segment_sliding(v: np.ndarray, ra: np.ndarray, half_middle_mm: float) -> np.ndarray:
    """Each segment's velocity along its own axis, towards the head (mm/s).

    A rigid segment has one tangential velocity along its whole length: turning about its
    joint moves its points normal to the axis only. With the body velocity ``v`` = (vx,
    vy, wz) (mm/s, mm/s, rad/s) and r_a = (phi1, phi2) (rad; the head axis at +phi1 from
    body X, the tail axis at -phi2, joints at +-``half_middle_mm`` on body X):

    - middle: u = vx
    - head: u = vx cos phi1 + vy sin phi1 + wz a sin phi1
    - tail: u = vx cos phi2 - vy sin phi2 + wz a sin phi2

    ``v`` (..., 3), ``ra`` (..., >= 2); returns (..., 3): middle, head, tail.
    """
    vx, vy, wz = v[..., 0], v[..., 1], v[..., 2]
    c1, s1 = np.cos(ra[..., 0]), np.sin(ra[..., 0])
    c2, s2 = np.cos(ra[..., 1]), np.sin(ra[..., 1])
    a = half_middle_mm
    return np.stack([vx, vx * c1 + vy * s1 + wz * a * s1, vx * c2 - vy * s2 + wz * a * s2], axis=-1)


def _distance_and_time(windows: WindowSet, samples: pd.DataFrame):
    """Distance travelled (m) and time in the trial (s) at every window sample."""
    t = window_field(windows, "t")
    per = _trial_arrays(samples)
    dist = np.full(t.shape, np.nan)
    t_trial = np.full(t.shape, np.nan)
    for k, tid in enumerate(windows.trial_id):
        tr = per[int(tid)]
        ok = np.isfinite(t[k])
        tt = tr["t"].to_numpy(float)
        idx = np.clip(np.searchsorted(tt, t[k, ok] - 1e-9), 0, len(tt) - 1)
        dist[k, ok] = tr["dist_m"].to_numpy(float)[idx]
        t_trial[k, ok] = tt[idx] - tt[0]
    return dist, t_trial
