"""Comparing ways of finding a gait by the robot cycles they need.

A run (of `plan loop --goal gait`, or of a black-box optimiser evaluating one trial at
a time) leaves a curve: the best gait found (mm per cycle, scored on the robot or its
simulator) against the cycles recorded so far. Runs are compared by the cycles they
need to reach 80 % and 90 % of a ceiling, over several runs a dataset seed: a run that
never reached a level counts as beyond any budget, so a median exists only while fewer
than half of the runs missed. The plan loop's medians over a peer's give the ratio the
issue's bar reads (<= 1/3); where the peer's median run missed within its budget the
ratio is an upper bound. Seeds of repeated runs come from the job's key.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.gait.predict import derive_seed

#: The black-box peers of the gait goal: each evaluation one trial, no map.
PEERS = ("bo", "tpe")


def job_seed(arm: str, seed: int, repeat: int) -> int:
    """The seed of run ``repeat`` of ``arm`` on dataset seed ``seed``: the dataset seed
    itself for repeat 0 (the run `plan loop --seed S` makes), else derived from the job's
    key. It drives all of the run's randomness: its trials' noise draws and the arm's own
    (BO's random starts and GP, TPE's sampler, the loop's bootstrap refits)."""
    return seed if repeat == 0 else derive_seed("adaptive", arm, seed, repeat) % 2**31


def run_stats(values: list[int | None]) -> dict:
    """Median, least and most cycles over runs to reach a level; a run that never reached
    it counts as more than any budget (so the median is None when half or more missed)."""
    reached = sorted(v for v in values if v is not None)
    ranked = reached + [np.inf] * (len(values) - len(reached))
    median = float(np.median(ranked)) if ranked else np.inf
    return {
        "median": None if not np.isfinite(median) else median,
        "min": reached[0] if reached else None,
        "max": None if len(reached) < len(values) else reached[-1],
        "missed": len(values) - len(reached),
        "runs": values,
    }


def over_runs(runs: list[dict]) -> dict:
    """A dataset seed's entry for one arm: the runs and their cycles to 80 % and 90 %."""
    out = {
        "repeats": len(runs),
        "cycles_to_80": run_stats([r["cycles_to_80"] for r in runs]),
        "cycles_to_90": run_stats([r["cycles_to_90"] for r in runs]),
        "median_share_of_ceiling": float(np.median([r["share_of_ceiling"] for r in runs])),
        "runs": runs,
    }
    # a run with no count within the budget (the designer: the full grid first) has none
    if all(r.get("share_at_budget") is not None for r in runs):
        out["median_share_at_budget"] = float(np.median([r["share_at_budget"] for r in runs]))
    return out


def run_entry(rows: list[dict], ceiling: float, budget: int) -> dict:
    """One run's figures from its curve rows (in order of cycles): its last count and best
    gait (mm per cycle), that as a share of ``ceiling``, the share of the best gait it had
    within ``budget`` cycles (the learning arms' budget, so peers are read at it too) and
    the cycles at which it first reached 80 % and 90 % of ``ceiling`` (None: never)."""
    last = rows[-1]
    within = [r["best_forward_mm"] for r in rows if r["cycles"] <= budget]
    return {
        "cycles": int(last["cycles"]),
        "best_forward_mm": round(float(last["best_forward_mm"]), 2),
        "share_of_ceiling": round(float(last["best_forward_mm"]) / ceiling, 3),
        "share_at_budget": round(max(within) / ceiling, 3) if within else None,
        "cycles_to_80": first_reaching(rows, 0.8 * ceiling),
        "cycles_to_90": first_reaching(rows, 0.9 * ceiling),
    }


def summary_from_curves(
    frame: pd.DataFrame, ceiling: float, budget: int, peer_budget: int
) -> dict:  # fmt: skip
    """The gait goal's summary (as a run writes it, without timings and job seeds)
    recomputed from stored curves (curves.csv rows: goal, arm, seed, repeat, cycles,
    best_forward_mm) against ``ceiling`` mm per cycle: no arm is run again."""
    gait = frame[frame["goal"] == "gait"]
    if "repeat" not in gait:
        gait = gait.assign(repeat=0)
    arms: dict = {}
    for (arm, seed), part in gait.groupby(["arm", "seed"], sort=False):
        runs = [
            {"repeat": int(repeat)}
            | run_entry(rows.sort_values("cycles").to_dict("records"), ceiling, budget)
            for repeat, rows in part.groupby("repeat")
        ]
        arms.setdefault(arm, {})[str(seed)] = over_runs(runs)
    summary = {"ceiling_mm": ceiling, "budget": budget, "peer_budget": peer_budget}
    return summary | {"arms": arms, "ratios": ratios(arms, budget, peer_budget)}


def read_curves(paths: list[Path]) -> pd.DataFrame:
    """Stored curves.csv files as one frame; where two files hold the same arm on the same
    dataset seed the later file's runs are taken (a longer rerun of a peer, say)."""
    frames: list[pd.DataFrame] = []
    for path in paths:
        frame = pd.read_csv(path)
        keys = set(zip(frame["goal"], frame["arm"], frame["seed"], strict=True))
        frames = [
            f[[k not in keys for k in zip(f["goal"], f["arm"], f["seed"], strict=True)]]
            for f in frames
        ]
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def ratios(arms: dict, budget: int, peer_budget: int) -> dict:
    """Per peer and dataset seed, the plan loop's median cycles to 80 % / 90 % over the
    peer's (the bar: <= 1/3). Where the peer's median run missed the level within its
    budget the ratio is an upper bound (``peer_missed``: the peer needs > peer_budget);
    where the loop's did, None."""
    out = {}
    for peer in PEERS:
        if "plan" not in arms or peer not in arms:
            continue
        for seed, plan in arms["plan"].items():
            if seed not in arms[peer]:
                continue
            for level in ("80", "90"):
                p = plan[f"cycles_to_{level}"]["median"]
                q = arms[peer][seed][f"cycles_to_{level}"]["median"]
                out.setdefault(peer, {}).setdefault(seed, {})[level] = {
                    "ratio": None if p is None else round(p / (q or peer_budget), 3),
                    "peer_missed": q is None,
                }
    return out


def first_reaching(rows: list[dict], level: float) -> int | None:
    """Cycles recorded when the best gait first reaches ``level`` mm per cycle."""
    for r in rows:
        if r["best_forward_mm"] >= level:
            return int(r["cycles"])
    return None
