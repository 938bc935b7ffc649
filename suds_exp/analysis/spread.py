"""Spread and sample efficiency: RMS error against the number of training cycles.

Both tables group results by test frequency, learner and ``n_cycles`` - the paper's
spread table and sample-efficiency figure, one per frequency - over the train/test pairs
named by ``pairs``: ``same-condition`` (same gait and frequency; the campaign's
sample-efficiency sweep runs these, so every training size has the same mix of pairs) or
``same-frequency`` (every gait pairing at one frequency).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import t as student_t

from suds_exp.analysis.categories import learner_order
from suds_exp.errors import AnalysisError

#: Which train/test pairs the spread and efficiency tables pool.
PAIRS = {
    "same-condition": lambda r: (r["freq_sim"] == "same") & (r["gait_sim"] == "same"),
    "same-frequency": lambda r: r["freq_sim"] == "same",
}


def _pooled(results: pd.DataFrame, pairs: str) -> pd.DataFrame:
    if pairs not in PAIRS:
        raise AnalysisError(f"pairs {pairs!r}: expected one of {', '.join(PAIRS)}")
    rows = results[PAIRS[pairs](results).fillna(False).astype(bool)]
    if rows.empty:
        raise AnalysisError(
            f"no {pairs} results (trained and tested on the same "
            f"{'condition' if pairs == 'same-condition' else 'frequency'}); the spread table "
            "and sample-efficiency figure need them"
        )
    return rows.assign(frequency_hz=rows["test_frequency_hz"].round(6))


def _ordered(table: pd.DataFrame) -> pd.DataFrame:
    order = {m: i for i, m in enumerate(learner_order(table["model"]))}
    return table.sort_values(
        ["frequency_hz", "model", "n_cycles"] if "n_cycles" in table else ["frequency_hz", "model"],
        key=lambda s: s.map(order) if s.name == "model" else s,
    ).reset_index(drop=True)


def iqr_table(results: pd.DataFrame, pairs: str = "same-condition") -> pd.DataFrame:
    """Quartiles of the RMS error of vx by frequency, learner and training size.

    Parameters
    ----------
    results : DataFrame
        Rows of ``results_labelled`` (see `load_results`).
    pairs : {"same-condition", "same-frequency"}
        Train/test pairs pooled (see the module docstring).

    Returns
    -------
    DataFrame with columns ``frequency_hz``, ``model``, ``n_cycles``, ``n``, ``q1``,
    ``median``, ``q3``, ``iqr`` (mm/s; linear-interpolated quartiles, as DuckDB's
    ``quantile_cont`` in the view ``results_iqr``).
    """
    rows = _pooled(results, pairs)
    grouped = rows.groupby(["frequency_hz", "model", "n_cycles"])["rmse_vx"]
    table = grouped.quantile([0.25, 0.5, 0.75]).unstack()
    table.columns = ["q1", "median", "q3"]
    table["iqr"] = table["q3"] - table["q1"]
    table.insert(0, "n", grouped.size())
    return _ordered(table.reset_index())


def slope_table(
    results: pd.DataFrame, upper_from: int | None = None, pairs: str = "same-condition"
) -> pd.DataFrame:
    """Each learner's log-log slope of RMS error against training cycles, per frequency.

    The slope is the least-squares fit of ``ln(rmse_vx)`` on ``ln(n_cycles)`` over every
    result with ``n_cycles >= upper_from`` (so it is the rate at which the geometric-mean
    error falls; -0.5 is the rate of averaging out white noise). ``upper_from`` defaults
    to the median of the distinct training sizes: the upper half of the sweep, past the
    first fast drop the paper describes. ``pairs`` as in `iqr_table`.

    Returns
    -------
    DataFrame with columns ``frequency_hz``, ``model``, ``slope``, ``ci_low``, ``ci_high``
    (95 %), ``cycles_from``, ``cycles_to``, ``n`` (results used); ``slope`` is NaN where
    fewer than two training sizes are in the range.
    """
    rows = _pooled(results, pairs)
    return _ordered(fit_slopes(rows, ["frequency_hz", "model"], upper_from, pairs))


def fit_slopes(
    rows: pd.DataFrame,
    keys: list[str],
    upper_from: int | None = None,
    pairs: str = "same-condition",
) -> pd.DataFrame:
    """The log-log slopes of `slope_table` on ``rows`` (labelled results of the ``pairs``
    named in errors), one per group of ``keys``; columns ``keys``, then as `slope_table`'s."""
    sizes = np.sort(rows["n_cycles"].unique())
    start = int(np.median(sizes)) if upper_from is None else int(upper_from)
    rows = rows[rows["n_cycles"] >= start]
    out = []
    for group, g in rows.groupby(keys):
        x = np.log(g["n_cycles"].to_numpy(dtype=float))
        y = g["ln_rmse_vx"].to_numpy(dtype=float)
        slope = lo = hi = np.nan
        if np.unique(x).size >= 2:
            xc = x - x.mean()
            sxx = xc @ xc
            slope = (xc @ (y - y.mean())) / sxx
            resid = y - y.mean() - slope * xc
            dof = len(y) - 2
            if dof > 0:
                half = student_t.ppf(0.975, dof) * np.sqrt(resid @ resid / dof / sxx)
                lo, hi = slope - half, slope + half
        out.append(
            {
                **dict(zip(keys, group, strict=True)),
                "slope": slope,
                "ci_low": lo,
                "ci_high": hi,
                "cycles_from": int(g["n_cycles"].min()),
                "cycles_to": int(g["n_cycles"].max()),
                "n": len(g),
            }
        )
    if not out:
        raise AnalysisError(f"no {pairs} results with n_cycles >= {start}")
    return pd.DataFrame(out)
