"""A samples frame with a known map, for the campaign and learner tests.

Smaller and faster than `synthetic_swimmer` (no physics): the body velocity is a
quadratic function of the actuated shape and its rate, so a learner's error is known.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from suds_exp.robot import GAIT_K


def synthetic_samples(
    conditions=(("O", 0.5), ("O", 1.0), ("D+", 0.5), ("D+", 1.0)),
    trials_per_condition: int = 4,
    cycles=(8, 14),
    rate_hz: float = 20.0,
    seed: int = 0,
) -> pd.DataFrame:
    """A samples frame like `load_samples` returns: several trials per condition.

    ``conditions`` are (gait, frequency Hz) pairs, each with ``trials_per_condition``
    trials of a uniform draw from ``cycles`` gait cycles, captured at ``rate_hz``. r_a
    follows the gait with a per-trial amplitude and phase offset; r_p lags r_a; the body
    velocity (vx, vy in mm/s, wz in rad/s) is a known quadratic map of (r_a, dr_a/dt) plus
    Gaussian noise (sd 1.0, 1.0, 0.02). Trial ids count from 1; ``seed`` fixes every draw.
    """
    rng = np.random.default_rng(seed)
    frames, tid = [], 1
    for gait, f in conditions:
        k = GAIT_K[gait]
        s = 0.0 if np.isinf(k) else 1.0 / k
        for _ in range(trials_per_condition):
            n_cyc = rng.uniform(*cycles)
            t = np.arange(int(n_cyc * rate_hz / f)) / rate_hz
            th0 = rng.uniform(0, 2 * np.pi)
            th = 2 * np.pi * f * t + th0
            w = 2 * np.pi * f
            amp = 1 + 0.1 * rng.standard_normal()
            ra = amp * np.stack(
                [np.cos(th) + s * np.cos(3 * th), np.sin(th) - s * np.sin(3 * th)], 1
            )
            dra = (
                amp
                * w
                * np.stack(
                    [-np.sin(th) - 3 * s * np.sin(3 * th), np.cos(th) - 3 * s * np.cos(3 * th)], 1
                )
            )
            rp = 0.5 * np.stack([np.cos(th - 0.4), np.sin(th - 0.4)], 1)
            drp = 0.5 * w * np.stack([-np.sin(th - 0.4), np.cos(th - 0.4)], 1)
            vx = 12 * (ra[:, 0] * dra[:, 1] - ra[:, 1] * dra[:, 0]) + 3 * rp[:, 0] * dra[:, 0]
            vy = 5 * dra[:, 0] - 2 * dra[:, 1]
            wz = 0.3 * dra[:, 0] * ra[:, 1]
            n = len(t)
            phase = th - th0 + th0 % (2 * np.pi)
            frames.append(
                pd.DataFrame(
                    {
                        "trial_id": tid,
                        "frame": np.arange(n),
                        "t": t,
                        "phase": phase,
                        "cycle": np.floor(phase / (2 * np.pi)).astype(int),
                        "ra_1": ra[:, 0],
                        "ra_2": ra[:, 1],
                        "dra_1": dra[:, 0],
                        "dra_2": dra[:, 1],
                        "rp_1": rp[:, 0],
                        "rp_2": rp[:, 1],
                        "drp_1": drp[:, 0],
                        "drp_2": drp[:, 1],
                        "vx": vx + rng.normal(0, 1.0, n),
                        "vy": vy + rng.normal(0, 1.0, n),
                        "wz": wz + rng.normal(0, 0.02, n),
                        "gait": gait,
                        "frequency_hz": f,
                    }
                )
            )
            tid += 1
    return pd.concat(frames, ignore_index=True)
