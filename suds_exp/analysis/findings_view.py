"""The findings table as it is shown: per-finding verdicts (`findings_summary`), the
display table, the one-line headline and the JSON document.

`suds_exp.analysis.findings` measures the table (one row per statistic, with ``value``,
``low``, ``high``, ``verdict`` and ``reason``); this module only reads it.
"""

from __future__ import annotations

import pandas as pd

from suds_exp.analysis.formatting import interval_text

#: A statistic's verdicts, from best to worst.
VERDICTS = ("holds", "unclear", "fails", "not measurable")


def findings_summary(table: pd.DataFrame) -> pd.DataFrame:
    """One row per finding (F1 ... F10): ``finding``, ``verdict`` (holds when every part
    holds, not measurable when any part is, else fails when any part fails, else unclear),
    ``parts`` (ids of its statistics)."""
    rows = []
    for finding, g in table.groupby("finding", sort=False):
        verdicts = set(g["verdict"])
        for v in ("not measurable", "fails", "unclear"):
            if v in verdicts:
                verdict = v
                break
        else:
            verdict = "holds"
        rows.append({"finding": finding, "verdict": verdict, "parts": ", ".join(g["id"])})
    # columns named even when nothing was measured (a design where no statistic applies)
    return pd.DataFrame(rows, columns=["finding", "verdict", "parts"])


def findings_display(table: pd.DataFrame, digits: int = 2) -> pd.DataFrame:
    """The table as it is shown: ``id``, ``paper``, ``threshold``, ``value [low, high]``
    (text) and ``verdict`` (with the reason when not measurable)."""

    def interval(r) -> str:
        return interval_text(r["value"], r["low"], r["high"], digits)

    return pd.DataFrame(
        {
            "id": table["id"],
            "paper finds": table["paper"],
            "holds if": table["threshold"],
            "value [95% interval]": table.apply(interval, axis=1),
            "verdict": [
                f"{v}: {why}" if v == "not measurable" else v
                for v, why in zip(table["verdict"], table["reason"], strict=True)
            ],
        }
    )


def findings_headline(table: pd.DataFrame) -> str:
    """One line: how many of the paper's ten findings hold, and on how many results."""
    summary = findings_summary(table)
    counts = summary["verdict"].value_counts()
    parts = [f"{int(counts.get(v, 0))} {v}" for v in VERDICTS if counts.get(v, 0)]
    a = table.attrs
    return (
        f"{int(counts.get('holds', 0))} of {len(summary)} findings hold ({', '.join(parts)}); "
        f"{a.get('n_results', '?')} results, main size {a.get('main_cycles', '?')} cycles, "
        f"{a.get('n_boot', '?')} bootstrap replicates"
    )


def findings_json(table: pd.DataFrame, campaign: str) -> dict:
    """A JSON-safe document: ``campaign``, ``attrs``, ``findings`` (per-finding verdicts)
    and ``statistics`` (the table's rows; NaN -> null)."""
    rows = table.astype(object).where(table.notna(), None).to_dict(orient="records")
    return {
        "campaign": campaign,
        **{k: v for k, v in table.attrs.items()},
        "headline": findings_headline(table),
        "findings": findings_summary(table).to_dict(orient="records"),
        "statistics": rows,
    }


DESIGN_CAVEAT = (
    "F1-F10 assume the paper's design (its gaits S+ < S- < O < D- < D+ and frequencies); "
    "{source} is another, so only the statistics its results can measure are shown"
)


def for_design(table: pd.DataFrame, source: str) -> pd.DataFrame:
    """The findings ``table`` on a design other than the paper's (named ``source``):
    only the statistics that could be measured, with ``attrs`` ``design`` (``source``),
    ``caveat`` (`DESIGN_CAVEAT`) and ``left_out`` (``"<id>: <why>"`` for each other)."""
    measured = table["verdict"] != "not measurable"
    out = table[measured].reset_index(drop=True)
    out.attrs = {
        **table.attrs,
        "design": source,
        "caveat": DESIGN_CAVEAT.format(source=source),
        "left_out": [f"{r.id}: {r.reason}" for r in table[~measured].itertuples()],
    }
    return out
