"""Writing tables as CSV, Markdown and HTML fragments, and saying which could not be
computed (`ReportTables`, `write_missing`)."""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.errors import AnalysisError


def interval_text(value: float, low: float, high: float, digits: int = 2) -> str:
    """``value [low, high]`` to ``digits`` decimals as tables show an estimate and its
    interval; the value alone when the interval is not finite, "" when the value is not."""
    if not np.isfinite(value):
        return ""
    text = f"{value:.{digits}f}"
    if np.isfinite(low) and np.isfinite(high):
        text += f" [{low:.{digits}f}, {high:.{digits}f}]"
    return text


def interval_column(table: pd.DataFrame, name: str, digits: int = 2) -> list[str]:
    """`interval_text` of every row's ``name`` and its interval (columns ``name_low`` and
    ``name_high``): one table column of text."""
    return [
        interval_text(v, lo, hi, digits)
        for v, lo, hi in zip(table[name], table[f"{name}_low"], table[f"{name}_high"], strict=True)
    ]


def not_measured(columns, reason: str) -> pd.DataFrame:
    """An empty table of ``columns`` that says why it is empty (``attrs["reason"]``), as
    the diagnostics return one when the data cannot give them."""
    table = pd.DataFrame(columns=list(columns))
    table.attrs["reason"] = reason
    return table


def _cell(value, digits: int) -> str:
    if value is None or value is pd.NA or (isinstance(value, float) and np.isnan(value)):
        return ""
    if isinstance(value, bool | np.bool_):
        return "yes" if value else "no"
    if isinstance(value, float | np.floating):
        return f"{value:.{digits}f}"
    return str(value)


def formatted(frame: pd.DataFrame, digits: int = 2) -> list[list[str]]:
    """The frame's cells as strings: floats to ``digits`` decimals, booleans yes/no, NA blank."""
    return [[_cell(v, digits) for v in row] for row in frame.itertuples(index=False)]


def to_markdown(frame: pd.DataFrame, digits: int = 2) -> str:
    """A GitHub-flavoured Markdown table of ``frame`` (numbers right-aligned)."""
    header = [str(c) for c in frame.columns]
    align = [
        "---:" if pd.api.types.is_numeric_dtype(frame[c]) and frame[c].dtype != bool else "---"
        for c in frame.columns
    ]
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(align) + "|"]
    lines += [
        "| " + " | ".join(c.replace("|", "\\|") for c in row) + " |"
        for row in formatted(frame, digits)
    ]
    return "\n".join(lines) + "\n"


def to_html(frame: pd.DataFrame, digits: int = 2) -> str:
    """An HTML ``<table>`` of ``frame`` (escaped; numbers right-aligned)."""
    numeric = [
        pd.api.types.is_numeric_dtype(frame[c]) and frame[c].dtype != bool for c in frame.columns
    ]
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in frame.columns)
    body = []
    for row in formatted(frame, digits):
        cells = "".join(
            f'<td class="num">{html.escape(v)}</td>' if num else f"<td>{html.escape(v)}</td>"
            for v, num in zip(row, numeric, strict=True)
        )
        body.append(f"<tr>{cells}</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def write_table(
    frame: pd.DataFrame, out_dir: Path, name: str, digits: int = 2, markdown: str | None = None
) -> dict[str, Path]:
    """Write ``name.csv`` (full precision) and ``name.md`` (``markdown`` if given, else
    ``frame`` rounded to ``digits``); return kind -> path."""
    csv = out_dir / f"{name}.csv"
    md = out_dir / f"{name}.md"
    frame.to_csv(csv, index=False)
    md.write_text(
        markdown if markdown is not None else to_markdown(frame, digits), encoding="utf-8"
    )
    return {"csv": csv, "md": md}


class ReportTables(dict):
    """The report's tables by name (a dict of DataFrames), and ``missing``: the name of
    each table that could not be computed -> why (one line), for the page to say."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.missing: dict[str, str] = {}

    def attempt(self, names: str | tuple[str, ...], compute) -> bool:
        """Store ``compute()`` (a DataFrame, or a tuple of them for several ``names``);
        when the results cannot support it (`AnalysisError`), record why under each name
        instead. Returns whether it was computed."""
        names = (names,) if isinstance(names, str) else names
        try:
            got = compute()
        except AnalysisError as exc:
            for name in names:
                self.missing[name] = str(exc)
            return False
        self.update(zip(names, got if len(names) > 1 else (got,), strict=True))
        return True


def write_missing(missing: dict[str, str], out: Path) -> dict[str, dict[str, Path]]:
    """For each table that could not be computed, ``<name>.md`` saying why (and no CSV,
    so no stale one is read as current); returns each one's files by name."""
    files = {}
    for name, reason in missing.items():
        md = out / f"{name}.md"
        md.write_text(f"Not computed: {reason}\n", encoding="utf-8")
        (out / f"{name}.csv").unlink(missing_ok=True)
        files[name] = {"md": md}
    return files


def not_computed_html(reason: str, files: dict[str, Path]) -> str:
    """The paragraph a report section shows in place of what could not be computed."""
    links = " ".join(
        f'<a href="{html.escape(p.name)}">{html.escape(p.name)}</a>' for p in files.values()
    )
    return f"<p><b>Not computed:</b> {html.escape(reason)}. Files: {links}</p>"
