"""Samples straight from simulator truth, for streams that need no motion capture.

`simulate_stream_samples` runs the simulator (with scheduled changes) and turns each
trial's truth table into a samples frame: r_a = (phi1, phi2), r_p = the four flipper
angles (rad; the physical passive shape instead of marker PCA), rates by central
differences, v_b the true body velocity, phase the commanded phase, cycle its whole
turns. Tests and benchmarks use it to study learners without the marker and
preprocessing error; `suds-exp stream` runs on stored samples.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from suds_exp.sim.config import SimConfig
from suds_exp.sim.dataset import plan_trials, simulate_trials
from suds_exp.sim.schedule import Change


def samples_from_truth(truth: dict, trial_id: int) -> pd.DataFrame:
    """A samples frame (columns of the `samples` table, k = 4) from one truth dict."""
    t = np.asarray(truth["t"], float)
    phase = np.asarray(truth["phase_cmd"], float)
    d = {
        "trial_id": trial_id,
        "frame": np.arange(len(t)),
        "t": t,
        "phase": phase,
        "cycle": np.floor((phase - phase[0]) / (2 * np.pi)).astype(int),
    }
    for i, c in enumerate(("phi1", "phi2"), 1):
        d[f"ra_{i}"] = np.asarray(truth[c], float)
        d[f"dra_{i}"] = np.gradient(d[f"ra_{i}"], t)
    for i in range(1, 5):
        d[f"rp_{i}"] = np.asarray(truth[f"flipper_{i}"], float)
    for i in range(1, 5):
        d[f"drp_{i}"] = np.gradient(d[f"rp_{i}"], t)
    for c in ("vx", "vy", "wz"):
        d[c] = np.asarray(truth[c], float)
    return pd.DataFrame(d)


def simulate_stream_samples(
    gait: str = "O",
    frequency_hz: float = 1.0,
    n_cycles: int = 60,
    changes: Sequence[Change] = (),
    seeds: Sequence[int] = (0,),
    config: SimConfig | None = None,
) -> pd.DataFrame:
    """One trial per seed (trial_id = seed + 1) of `n_cycles` cycles with `changes`.

    Returns the samples frames concatenated, plus `gait` and `frequency_hz` columns.
    """
    cfg = config or SimConfig()
    specs = [
        plan_trials([gait], [frequency_hz], 1, (n_cycles, n_cycles), seed=int(s))[0] for s in seeds
    ]
    truths = simulate_trials(specs, cfg, changes)
    frames = [samples_from_truth(tr, int(s) + 1) for tr, s in zip(truths, seeds, strict=True)]
    out = pd.concat(frames, ignore_index=True)
    out["gait"] = gait
    out["frequency_hz"] = float(frequency_hz)
    return out
