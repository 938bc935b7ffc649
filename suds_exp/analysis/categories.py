"""Similarity categories and learner order: the vocabulary of the paper's results section.

The labels themselves are computed by the SQL view ``results_labelled`` (migration 004),
the one definition both SQL users and this package read. This module holds the orders
in which categories and learners are shown, and the numbers behind the box plots.
"""

from __future__ import annotations

import pandas as pd

from suds_exp.errors import AnalysisError
from suds_exp.models.registry import LEARNERS
from suds_exp.robot import GAITS

#: The gait axis; gait similarity is the number of steps along it (0 same, 1 near, >1 far).
GAIT_AXIS = GAITS
#: Learners in display order (`LEARNERS`); unknown names are shown after these, sorted.
#: Category orders as the paper's panels run, left to right.
FREQ_SIM = ("different", "same")
GAIT_SIM = ("far", "near", "same")
#: period_rel values: model-period (1 / training frequency) against data-period.
PERIOD_REL = ("<", "=", ">")


def learner_order(models) -> list[str]:
    """The learners in ``models`` in display order (known ones first, then sorted)."""
    present = set(models)
    return [m for m in LEARNERS if m in present] + sorted(present - set(LEARNERS))


def main_cycles(results: pd.DataFrame) -> int:
    """The training size the category analyses use by default: the most common ``n_cycles``.

    A campaign that runs the full condition grid at one size and a sample-efficiency sweep
    on the side has most of its rows at the grid's size; ties go to the larger size.
    """
    if results.empty:
        raise ValueError("no results")
    counts = results["n_cycles"].value_counts()
    top = counts[counts == counts.max()].index
    return int(max(top))


def at_cycles(results: pd.DataFrame, n_cycles: int | None) -> tuple[pd.DataFrame, int]:
    """The rows at ``n_cycles`` training cycles (default `main_cycles`), and that size
    (``results`` itself when every row is at that size: callers do not change it)."""
    size = main_cycles(results) if n_cycles is None else int(n_cycles)
    at = (results["n_cycles"] == size).to_numpy()
    # a campaign without a sweep has every row at one size: the frame itself, not a copy
    # of every loaded column
    rows = results if at.all() else results[at]
    if rows.empty:
        sizes = ", ".join(str(v) for v in sorted(results["n_cycles"].unique()))
        raise AnalysisError(
            f"n_cycles {size}: no results at that size; the campaign has {sizes}", param="n_cycles"
        )
    return rows, size


def category_table(results: pd.DataFrame, n_cycles: int | None = None) -> pd.DataFrame:
    """Numbers behind the box plots: ln RMS error of vx by learner and similarity category.

    Parameters
    ----------
    results : DataFrame
        Rows of ``results_labelled`` (see `load_results`).
    n_cycles : int, optional
        Training size to use; default the campaign's most common one.

    Returns
    -------
    DataFrame with columns ``model``, ``freq_sim``, ``gait_sim`` (``all`` where pooled),
    ``n``, ``q1``, ``median``, ``q3`` (ln of mm/s) and ``median_rmse_vx`` (mm/s); one
    row per learner for each frequency category, each gait category and each combination.
    """
    rows, _ = at_cycles(results, n_cycles)
    parts = []
    for keys in (["freq_sim"], ["gait_sim"], ["freq_sim", "gait_sim"]):
        grouped = rows.groupby(["model", *keys], observed=True)
        part = grouped["ln_rmse_vx"].describe()[["count", "25%", "50%", "75%"]]
        part.columns = ["n", "q1", "median", "q3"]
        part["median_rmse_vx"] = grouped["rmse_vx"].median()
        part = part.reset_index()
        for key in ("freq_sim", "gait_sim"):
            if key not in keys:
                part[key] = "all"
        parts.append(part)
    table = pd.concat(parts, ignore_index=True)
    table["n"] = table["n"].astype(int)
    order = {m: i for i, m in enumerate(learner_order(table["model"]))}
    freq = {v: i for i, v in enumerate(("all", *FREQ_SIM))}
    gait = {v: i for i, v in enumerate(("all", *GAIT_SIM))}
    table = table.sort_values(
        ["freq_sim", "gait_sim", "model"],
        key=lambda s: s.map({"freq_sim": freq, "gait_sim": gait, "model": order}[s.name]),
        kind="stable",
    )
    cols = ["model", "freq_sim", "gait_sim", "n", "q1", "median", "q3", "median_rmse_vx"]
    return table[cols].reset_index(drop=True)
