"""Synthetic swimmers with a known motility map, for testing and benchmarking learners.

Not the physics simulator (`suds_exp.sim`): a few lines of closed-form kinematics whose
truth is known exactly, so tests can ask "did the learner recover A(r)?".

Actuated shape (rad): r_a = g(theta) (1 + e_amp(t)) + e_off(t), theta = 2 pi f t + theta_0,
g the contract gaits (O, D-, D+, S-, S+); e_amp, e_off are smooth per-trial wobbles of a
few low frequencies (amplitude `tube`), so the data fill a tube around the gait.

Passive shape r_p (k = 2, dimensionless), SUDS form dr_p/dt = C dr_a/dt + D(r):
- "lag":    dr_p/dt = C dr_a/dt - (r_p - G r_a) / tau          (rate-dependent, tau s)
- "travel": dr_p/dt = C dr_a/dt - (r_p - G r_a) |dr_a/dt| / ell (rate-independent)
- "none":   no passive shape.

Body velocity (body frame; vx, vy mm/s, wz rad/s):
- "linear":  v_b = A(r) dr_a/dt (principally kinematic, linear in dr_a/dt)
- "finsler": v_b = A(r) dr_a/dt + b(r_a) |dr_a/dt| (homogeneous of degree 1, not linear:
  asymmetric, direction-dependent friction)
- "asymmetric": v_b = A(r) ([dr_a/dt]+ + `asymmetry` [dr_a/dt]-), [x]+ = max(x, 0),
  [x]- = min(x, 0): a joint closing moves the body `asymmetry` times as far as opening
  (a Finsler map with a known asymmetry ratio; linear at 1)
with A(r) = A_a(r_a) + A_p(r_p) given by `connection`.

Momentum (`body_tau` s > 0): the body velocity relaxes towards the map above,
dv/dt = (v_map - v) / body_tau, integrated exactly at the substep (a body whose momentum
matters; 0 = the principally kinematic swimmer). Each trial starts at rest on the map.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.signal import lfilter

from suds_exp.errors import ConfigError
from suds_exp.robot import gait_shape, gait_shape_rate

C_PASSIVE = np.array([[0.6, 0.0], [0.0, -0.4]])
G_PASSIVE = np.array([[0.5, 0.2], [-0.2, 0.4]])


def connection(ra: np.ndarray, rp: np.ndarray | None = None) -> np.ndarray:
    """True motility map A(r), shape (n, 3, 2): rows vx (mm/rad), vy (mm/rad), wz (1/1).

    ra: (n, 2) rad; rp: (n, 2) or None (then the passive part is left out).
    """
    p1, p2 = ra[:, 0], ra[:, 1]
    A = np.empty((len(ra), 3, 2))
    A[:, 0, 0] = -12.0 * p2 + 6.0 * np.cos(p1)
    A[:, 0, 1] = 12.0 * p1 - 6.0 * np.cos(p2)
    A[:, 1, 0] = 5.0 + 3.0 * p1 * p2
    A[:, 1, 1] = -5.0 + 3.0 * p1 * p2
    A[:, 2, 0] = 0.3 - 0.15 * p2
    A[:, 2, 1] = 0.3 + 0.15 * p1
    if rp is not None:
        A[:, 0, 0] += 15.0 * rp[:, 0]
        A[:, 0, 1] -= 15.0 * rp[:, 1]
        A[:, 1, 0] += 6.0 * rp[:, 1]
        A[:, 2, 1] += 0.2 * rp[:, 0]
    return A


def _finsler_bias(ra: np.ndarray) -> np.ndarray:
    """b(r_a) of the finsler map, shape (n, 3): velocity per unit |dr_a/dt|."""
    return np.stack([8.0 + 2.0 * ra[:, 0], 1.5 * ra[:, 1], 0.05 * ra[:, 0]], 1)


def _wobble(t: np.ndarray, f: float, tube: float, rng) -> tuple[np.ndarray, np.ndarray]:
    """Smooth per-trial perturbation (n, 4) = (amp1, amp2, off1, off2) and its rate."""
    n_modes = 3
    freqs = f * rng.uniform(0.05, 1.5, size=(n_modes, 4))
    phases = rng.uniform(0, 2 * np.pi, size=(n_modes, 4))
    amps = tube / np.sqrt(n_modes) * rng.uniform(0.5, 1.5, size=(n_modes, 4))
    arg = 2 * np.pi * freqs[None] * t[:, None, None] + phases[None]
    e = (amps[None] * np.sin(arg)).sum(1)
    de = (amps[None] * 2 * np.pi * freqs[None] * np.cos(arg)).sum(1)
    return e, de


def _actuated(n_cycles, gait, f, spc, tube, substeps, rng, direction):
    """The actuated shape at ``substeps`` points a sample: (t (n,) s, theta (n,) rad,
    theta_0 rad, r_a (n, 2) rad, dr_a/dt (n, 2) rad/s)."""
    n = int(round(n_cycles * spc))
    fs = f * spc
    nf = n * substeps
    tf = np.arange(nf) / (fs * substeps)
    theta0 = rng.uniform(0, 2 * np.pi)
    theta = direction * 2 * np.pi * f * tf + theta0
    g, dg = gait_shape(gait, theta), direction * gait_shape_rate(gait, theta)
    e, de = _wobble(tf, f, tube, rng)
    amp = 1.0 + e[:, :2]
    ra = g * amp + e[:, 2:]
    dra = dg * (2 * np.pi * f) * amp + g * de[:, :2] + de[:, 2:]
    return tf, theta, theta0, ra, dra


def _passive_shape(ra, dra, rate, passive, tau, ell, rp_start):
    """(r_p, dr_p/dt), each (n, 2) ((n, 0) for ``passive`` "none"), of the actuated shape
    ``ra``, ``dra`` sampled at ``rate`` Hz."""
    nf = len(ra)
    if passive == "none":
        rp = np.zeros((nf, 0))
        return rp, rp
    speed = np.linalg.norm(dra, axis=1)
    lam = np.full(nf, 1.0 / tau) if passive == "lag" else speed / ell
    forcing = dra @ C_PASSIVE.T + lam[:, None] * (ra @ G_PASSIVE.T)
    h = 1.0 / rate
    rp = np.empty((nf, 2))
    x = ra[0] @ G_PASSIVE.T + rp_start
    denom = 1.0 + h * lam
    for i in range(nf):  # implicit Euler: stable whatever tau, exact as h -> 0
        x = (x + h * forcing[i]) / denom[i]
        rp[i] = x
    return rp, forcing - lam[:, None] * rp


def _body_velocity(ra, dra, rp, rate, velocity, asymmetry, body_tau):
    """Body velocity (n, 3) (vx, vy mm/s, wz rad/s) of shape ``ra``, ``rp`` and shape
    velocity ``dra`` sampled at ``rate`` Hz."""
    A = connection(ra, rp if rp.shape[1] else None)
    if velocity == "asymmetric":
        v = np.einsum("nij,nj->ni", A, np.maximum(dra, 0) + asymmetry * np.minimum(dra, 0))
    else:
        v = np.einsum("nij,nj->ni", A, dra)
    if velocity == "finsler":
        v += _finsler_bias(ra) * np.linalg.norm(dra, axis=1)[:, None]
    if body_tau > 0:
        a = -np.expm1(-1.0 / (rate * body_tau))
        v = lfilter([a], [1.0, a - 1.0], v, axis=0, zi=(1 - a) * v[:1])[0]
    return v


def make_samples(
    n_cycles: float = 30,
    gait: str = "O",
    frequency_hz: float = 0.5,
    n_trials: int = 1,
    samples_per_cycle: int = 100,
    tube: float = 0.15,
    passive: str = "lag",
    velocity: str = "linear",
    tau: float = 0.3,
    ell: float = 0.8,
    noise_v: float = 1.0,
    noise_w: float = 0.02,
    noise_r: float = 0.0,
    noise_dr: float = 0.0,
    substeps: int = 10,
    rp_start: tuple = (0.0, 0.0),
    first_trial_id: int = 1,
    seed: int = 0,
    body_tau: float = 0.0,
    asymmetry: float = 1.0,
    direction: int = 1,
) -> pd.DataFrame:
    """A samples frame (columns of the `samples` table) from the synthetic swimmer.

    Extra columns `vx_true`, `vy_true`, `wz_true` (noise-free body velocity) and
    `rp_true_*` (noise-free r_p) let a test compute the noise floor. r_p starts at
    G r_a(0) + `rp_start` (its equilibrium plus an offset). Measured columns
    get Gaussian noise: v (noise_v mm/s, noise_w rad/s), r_a and r_p (noise_r),
    dr_a/dt and dr_p/dt (noise_dr per s). Trials are `first_trial_id`, ... in order.
    `direction` -1 runs the gait backwards (the phase decreases): the same shapes with
    the opposite shape velocity, where a Finsler map's two halves both show.
    """
    if direction not in (1, -1):
        raise ConfigError(f"synthetic: direction={direction!r}; expected 1 or -1")
    if passive not in ("lag", "travel", "none"):
        raise ConfigError(f"synthetic: passive={passive!r}; expected lag, travel or none")
    if velocity not in ("linear", "finsler", "asymmetric"):
        raise ConfigError(
            f"synthetic: velocity={velocity!r}; expected linear, finsler or asymmetric"
        )
    rng = np.random.default_rng(seed)
    rp_start = np.asarray(rp_start, dtype=float)
    frames = []
    for j in range(n_trials):
        t, theta, theta0, ra, dra = _actuated(
            n_cycles, gait, frequency_hz, samples_per_cycle, tube, substeps, rng, direction
        )
        rate = frequency_hz * samples_per_cycle * substeps
        rp, drp = _passive_shape(ra, dra, rate, passive, tau, ell, rp_start)
        v = _body_velocity(ra, dra, rp, rate, velocity, asymmetry, body_tau)
        sl = slice(None, None, substeps)
        ra, dra, rp, drp, t, v = ra[sl], dra[sl], rp[sl], drp[sl], t[sl], v[sl]
        ph = theta[sl] - theta0 + (theta0 % (2 * np.pi))
        n = len(t)
        d = {
            "trial_id": first_trial_id + j,
            "frame": np.arange(n),
            "t": t,
            "phase": ph,
            "cycle": np.floor(ph / (2 * np.pi)).astype(int),
            "ra_1": ra[:, 0] + noise_r * rng.standard_normal(n),
            "ra_2": ra[:, 1] + noise_r * rng.standard_normal(n),
            "dra_1": dra[:, 0] + noise_dr * rng.standard_normal(n),
            "dra_2": dra[:, 1] + noise_dr * rng.standard_normal(n),
        }
        for i in range(rp.shape[1]):
            d[f"rp_{i + 1}"] = rp[:, i] + noise_r * rng.standard_normal(n)
        for i in range(rp.shape[1]):
            d[f"drp_{i + 1}"] = drp[:, i] + noise_dr * rng.standard_normal(n)
        sig = np.array([noise_v, noise_v, noise_w])
        vm = v + sig * rng.standard_normal((n, 3))
        d.update(vx=vm[:, 0], vy=vm[:, 1], wz=vm[:, 2])
        d.update(vx_true=v[:, 0], vy_true=v[:, 1], wz_true=v[:, 2])
        for i in range(rp.shape[1]):
            d[f"rp_true_{i + 1}"] = rp[:, i]
        frames.append(pd.DataFrame(d))
    out = pd.concat(frames, ignore_index=True)
    out["gait"] = gait
    out["frequency_hz"] = frequency_hz
    return out
