"""What a stream shows: error against time, recovery after the change, drift alarms.

Per (learner, trial) with a change at time c (s):
- ``pre_error``: median RMSE of vx (mm/s) over the scored cycles that end before c;
- ``recovery_s``: time from c to the end of the first post-change cycle at which the median
  error of the last `RECOVERY_WINDOW` post-change cycles is at most `RECOVERY_FACTOR` x
  pre_error (NaN: not within the trial);
- ``alarm_delay_s``: time from c to the end of the first cycle whose Page-Hinkley alarm
  fires at or after c (NaN: no alarm);
- ``false_alarm``: an alarm before c (or anywhere, on a trial without change).
The learner summary gives medians over trials, how many recovered / alarmed, and the
false-alarm rate (fraction of trials with a false alarm).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

RECOVERY_FACTOR = 1.25
RECOVERY_WINDOW = 3


def trial_outcomes(rows: pd.DataFrame) -> pd.DataFrame:
    """One row per (model, trial_id): change_s, pre_error, post_error, recovery_s,
    alarm_delay_s, false_alarm, n_cycles. `rows`: stored `stream_cycles` rows."""
    out = []
    for (model, tid), g in rows.groupby(["model", "trial_id"], sort=True):
        g = g.sort_values("cycle")
        c = g["change_s"].iloc[0]
        c = None if c is None or pd.isna(c) else float(c)
        err = g["rmse_vx"].to_numpy()
        alarms = g["alarm"].to_numpy(bool)
        t_end = g["t_end"].to_numpy()
        rec = {
            "model": model,
            "trial_id": int(tid),
            "change_s": c,
            "n_cycles": len(g),
            "pre_error": np.nan,
            "post_error": np.nan,
            "recovery_s": np.nan,
            "alarm_delay_s": np.nan,
            "false_alarm": bool(alarms.any()) if c is None else bool(alarms[t_end < c].any()),
        }
        if c is not None:
            pre = t_end < c
            post = g["t_start"].to_numpy() >= c
            if pre.any():
                rec["pre_error"] = float(np.median(err[pre]))
            if post.any():
                rec["post_error"] = float(np.median(err[post][-RECOVERY_WINDOW * 3 :]))
            idx = np.flatnonzero(post)
            for j in range(RECOVERY_WINDOW - 1, len(idx)):
                window = err[idx[j - RECOVERY_WINDOW + 1 : j + 1]]
                if np.median(window) <= RECOVERY_FACTOR * rec["pre_error"]:
                    rec["recovery_s"] = float(t_end[idx[j]] - c)
                    break
            after = np.flatnonzero(alarms & (t_end >= c))
            if len(after):
                rec["alarm_delay_s"] = float(t_end[after[0]] - c)
        out.append(rec)
    return pd.DataFrame(out)


def summarise(rows: pd.DataFrame) -> dict:
    """JSON-ready summary per learner (see the module docstring) plus the trial outcomes."""
    outcomes = trial_outcomes(rows)
    models = {}
    for model, g in outcomes.groupby("model", sort=True):
        changed = g[g["change_s"].notna()]
        m = rows[rows["model"] == model]
        models[model] = {
            "trials": len(g),
            "trials_with_change": len(changed),
            "pre_error_median": _median(changed["pre_error"]),
            "post_error_median": _median(changed["post_error"]),
            "recovered": int(changed["recovery_s"].notna().sum()),
            "recovery_s_median": _median(changed["recovery_s"]),
            "alarmed": int(changed["alarm_delay_s"].notna().sum()),
            "alarm_delay_s_median": _median(changed["alarm_delay_s"]),
            "false_alarm_rate": float(g["false_alarm"].mean()) if len(g) else None,
            "learn_seconds_median": float(m["learn_seconds"].median()),
            "cycle_seconds_median": float((m["t_end"] - m["t_start"]).median()),
        }
    return {
        "recovery_factor": RECOVERY_FACTOR,
        "recovery_window_cycles": RECOVERY_WINDOW,
        "models": models,
        "trials": outcomes.replace({np.nan: None}).to_dict(orient="records"),
    }


def _median(x: pd.Series) -> float | None:
    x = x.dropna()
    return float(x.median()) if len(x) else None


def plot_error(rows: pd.DataFrame, path: str | Path) -> Path:
    """Error against time, one line per learner (median over trials per cycle), the
    change time marked; written to `path` (PNG)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 3.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for model, g in rows.groupby("model", sort=True):
        per = g.groupby("cycle").agg(t=("t_end", "median"), e=("rmse_vx", "median"))
        ax.plot(per["t"], per["e"], label=model)
    changes = rows["change_s"].dropna().unique()
    for c in changes:
        ax.axvline(c, color="k", ls="--", lw=1)
    ax.set_xlabel("time in trial (s)")
    ax.set_ylabel("RMSE of vx per cycle (mm/s)")
    ax.set_yscale("log")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path
