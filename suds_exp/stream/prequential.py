"""Prequential ("predict, then learn") evaluation of learners on one trial's cycles.

For one trial, in time order: the first `warmup_cycles` whole cycles train the learner
(`fit`); from then on each cycle is first predicted and scored (RMSE of vx, vy, wz over its
samples), then, for an online learner (one with `partial_fit`), learned. A batch learner
stays as the warm-up left it, the reference a robot without online learning would have.
Every scored cycle feeds the learner's own Page-Hinkley drift alarm.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from suds_exp.models import make_model
from suds_exp.stream.drift import PageHinkley

#: Columns of one scored cycle (table `stream_cycles` without the stream name).
CYCLE_COLUMNS = (
    "model",
    "trial_id",
    "cycle",
    "t_start",
    "t_end",
    "n_samples",
    "rmse_vx",
    "rmse_vy",
    "rmse_wz",
    "rms_vx",
    "ph_stat",
    "alarm",
    "learn_seconds",
    "predict_seconds",
)
TIMING_COLUMNS = ("learn_seconds", "predict_seconds")


@dataclass(frozen=True)
class StreamSettings:
    """Hyper-parameters of a prequential run (stored with the stream).

    warmup_cycles : whole cycles that train every learner before scoring starts.
    min_samples : a cycle with fewer samples (a cut-off first or last one) is skipped.
    ph_delta, ph_threshold, ph_burn_in : the Page-Hinkley test (see `drift`).
    """

    warmup_cycles: int = 10
    min_samples: int = 10
    ph_delta: float = 0.1
    ph_threshold: float = 1.5
    ph_burn_in: int = 5


def trial_cycles(trial: pd.DataFrame, min_samples: int) -> list[pd.DataFrame]:
    """The trial's cycles in time order, each a samples frame of >= min_samples rows."""
    trial = trial.sort_values("t", kind="stable")
    return [c for _, c in trial.groupby("cycle", sort=True) if len(c) >= min_samples]


def run_trial(
    trial: pd.DataFrame, model: str, params: dict, settings: StreamSettings
) -> pd.DataFrame:
    """Score one learner on one trial; one row per scored cycle (columns CYCLE_COLUMNS).

    `trial`: the samples of one trial (columns of the `samples` table). The learner is
    `make_model(model, **params)`; cycles are numbered 0.. in time order over the cycles
    kept, the first scored one being `settings.warmup_cycles`.
    """
    cycles = trial_cycles(trial, settings.min_samples)
    w = settings.warmup_cycles
    learner = make_model(model, **params)
    online = hasattr(learner, "partial_fit")
    trial_id = int(trial["trial_id"].iloc[0])
    rows = []
    if len(cycles) <= w:
        return pd.DataFrame(rows, columns=list(CYCLE_COLUMNS))
    learner.fit(pd.concat(cycles[:w], ignore_index=True))
    ph = PageHinkley(settings.ph_delta, settings.ph_threshold, settings.ph_burn_in)
    for i in range(w, len(cycles)):
        c = cycles[i]
        start = time.perf_counter()
        pred = learner.predict(c)
        predict = time.perf_counter() - start
        err = pred[["vx", "vy", "wz"]].to_numpy() - c[["vx", "vy", "wz"]].to_numpy()
        rmse = np.sqrt(np.mean(err * err, axis=0))
        stat, alarm = ph.update(float(rmse[0]))
        rows.append(
            {
                "model": model,
                "trial_id": trial_id,
                "cycle": i,
                "t_start": float(c["t"].iloc[0]),
                "t_end": float(c["t"].iloc[-1]),
                "n_samples": len(c),
                "rmse_vx": float(rmse[0]),
                "rmse_vy": float(rmse[1]),
                "rmse_wz": float(rmse[2]),
                "rms_vx": float(np.sqrt(np.mean(c["vx"].to_numpy() ** 2))),
                "ph_stat": float(stat),
                "alarm": bool(alarm),
                "learn_seconds": 0.0,
                "predict_seconds": predict,
            }
        )
        if online:
            start = time.perf_counter()
            learner.partial_fit(c)
            rows[-1]["learn_seconds"] = time.perf_counter() - start
    return pd.DataFrame(rows, columns=list(CYCLE_COLUMNS))
