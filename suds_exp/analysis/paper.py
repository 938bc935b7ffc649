"""The paper's GLM and IQR tables, and our tables set beside them.

The paper's tables are read from ``glm_table.csv`` and ``iqr_table.csv`` in the paper
folder: ``$SUDS_PAPER_DIR`` if set, else ``../shared/paper`` beside the repository.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import kendalltau

from suds_exp.errors import AnalysisError

PAPER_FILES = {"glm": "glm_table.csv", "iqr": "iqr_table.csv"}


def default_paper_dir() -> Path:
    """``$SUDS_PAPER_DIR``, or ``shared/paper`` beside the repository."""
    env = os.environ.get("SUDS_PAPER_DIR")
    return Path(env) if env else Path(__file__).resolve().parents[3] / "shared" / "paper"


def paper_table(kind: str, paper_dir: Path | None = None) -> pd.DataFrame:
    """The paper's ``glm`` table (model, term, coef, ci_low, ci_high) or ``iqr`` table
    (frequency_hz, model, n_cycles, iqr), as published."""
    if kind not in PAPER_FILES:
        raise AnalysisError(f"paper table {kind!r}: expected one of {', '.join(PAPER_FILES)}")
    path = Path(paper_dir or default_paper_dir()) / PAPER_FILES[kind]
    if not path.is_file():
        raise AnalysisError(
            f"{path}: the paper's {kind} table is not there; pass paper_dir DIR", param="paper_dir"
        )
    return pd.read_csv(path)


def _magnitude_rank(table: pd.DataFrame, group: list[str], value: str) -> pd.Series:
    """1 = largest |value| within each group, intercepts excluded (NaN)."""
    mag = (
        table[value].abs().where(table.get("term", pd.Series("", index=table.index)) != "Intercept")
    )
    return mag.groupby([table[g] for g in group]).rank(ascending=False, method="min")


def compare_glm(ours: pd.DataFrame, paper: pd.DataFrame) -> pd.DataFrame:
    """Our GLM coefficients beside the paper's, on the paper's rows.

    Parameters
    ----------
    ours : DataFrame
        `glm_table` output (model, term, coef, ci_low, ci_high, ...).
    paper : DataFrame
        ``paper_table("glm")``.

    Returns
    -------
    DataFrame with ``model``, ``term``, the paper's ``paper_coef``, ``paper_ci_low``,
    ``paper_ci_high``, our ``coef``, ``ci_low``, ``ci_high``, ``sign_agree``, and
    ``paper_rank`` / ``rank``: the term's place by magnitude within its model (1 =
    largest, intercept not ranked, ours ranked among the paper's terms we also have),
    with ``rank_agree``. Terms we could not estimate have NaN numbers and NA agreements.
    """
    left = paper.rename(columns={c: f"paper_{c}" for c in ("coef", "ci_low", "ci_high")})
    right = ours[["model", "term", "coef", "ci_low", "ci_high"]]
    table = left.merge(right, on=["model", "term"], how="left")
    table["sign_agree"] = (np.sign(table["coef"]) == np.sign(table["paper_coef"])).astype("boolean")
    table.loc[table["coef"].isna(), "sign_agree"] = pd.NA
    both = table["coef"].notna()
    table["paper_rank"] = _magnitude_rank(table.where(both), ["model"], "paper_coef")
    table["rank"] = _magnitude_rank(table.where(both), ["model"], "coef")
    table["rank_agree"] = (table["paper_rank"] == table["rank"]).astype("boolean")
    table.loc[table["rank"].isna(), "rank_agree"] = pd.NA
    for col in ("paper_rank", "rank"):
        table[col] = table[col].astype("Int64")
    return table


def compare_iqr(ours: pd.DataFrame, paper: pd.DataFrame) -> pd.DataFrame:
    """Our IQRs beside the paper's, on the paper's rows (frequency, learner, n_cycles).

    Frequencies are matched to 3 decimals (the paper writes 1/3 Hz as 0.3333). ``rank`` and
    ``paper_rank`` place each learner by IQR among the learners at the same frequency and
    training size (1 = smallest spread), over the learners both tables have there;
    ``rank_agree`` says whether the two places are equal.
    """
    left = paper.rename(columns={"iqr": "paper_iqr"}).assign(
        _f=lambda d: d["frequency_hz"].round(3)
    )
    right = ours.assign(_f=ours["frequency_hz"].round(3))[["_f", "model", "n_cycles", "iqr"]]
    table = left.merge(right, on=["_f", "model", "n_cycles"], how="left")
    both = table["iqr"].notna()
    keys = [table["_f"], table["n_cycles"]]
    table["paper_rank"] = table["paper_iqr"].where(both).groupby(keys).rank(method="min")
    table["rank"] = table["iqr"].groupby(keys).rank(method="min")
    table["rank_agree"] = (table["paper_rank"] == table["rank"]).astype("boolean")
    table.loc[~both, "rank_agree"] = pd.NA
    for col in ("paper_rank", "rank"):
        table[col] = table[col].astype("Int64")
    return table.drop(columns="_f")


def agreement_summary(glm_compare: pd.DataFrame, iqr_compare: pd.DataFrame) -> pd.DataFrame:
    """One line per compared table part: rows compared, sign and rank agreement counts, and
    Kendall's tau between our ordering and the paper's: by |coef| within a GLM, and for a
    spread table the mean over training sizes of the tau of the learners' IQRs."""
    lines = []
    for model, g in glm_compare.groupby("model", sort=False):
        g = g[(g["term"] != "Intercept") & g["coef"].notna()]
        tau = kendalltau(g["coef"].abs(), g["paper_coef"].abs()).statistic if len(g) > 1 else np.nan
        lines.append(
            {
                "table": f"GLM {model}",
                "rows_compared": len(g),
                "sign_agree": int(g["sign_agree"].sum()),
                "rank_agree": int(g["rank_agree"].sum()),
                "kendall_tau": tau,
            }
        )
    for freq, g in iqr_compare.groupby(iqr_compare["frequency_hz"].round(3), sort=True):
        g = g[g["iqr"].notna()]
        taus = [
            kendalltau(h["iqr"], h["paper_iqr"]).statistic
            for _, h in g.groupby("n_cycles")
            if len(h) > 1
        ]
        lines.append(
            {
                "table": f"IQR {freq:g} Hz",
                "rows_compared": len(g),
                "sign_agree": pd.NA,
                "rank_agree": int(g["rank_agree"].sum()),
                "kendall_tau": float(np.nanmean(taus)) if taus else np.nan,
            }
        )
    table = pd.DataFrame(lines)
    table["sign_agree"] = table["sign_agree"].astype("Int64")
    return table
