"""`suds-exp stream`: run a stream from the command's strings, summarise it, print it."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from suds_exp import console
from suds_exp.robot import parse_ids
from suds_exp.store.files import check_writable
from suds_exp.stream import StreamSettings, plot_error, run_stream, stream_rows, summarise


def stream_command(
    store,
    name: str,
    models: str = "GMR,OnlineGMR",
    trials: str | None = None,
    prep: str | None = None,
    warmup_cycles: int = 10,
    change_at: str | None = None,
    plot: Path | None = None,
    progress: bool = False,
) -> dict:
    """Create or continue stream ``name`` (`run_stream`), then summarise all its rows
    (`summarise`, with the call's ``run`` and, given ``plot``, the figure's path).
    ``trials`` as ids text (``1,2,5-8``); the plot's folder is checked before any row is
    stored. ``models`` is a comma list of learner names."""
    if plot is not None:
        check_writable(plot.parent, "plot: folder", param="plot")
    run = run_stream(
        store,
        name,
        [m.strip() for m in models.split(",") if m.strip()],
        parse_ids(trials),
        prep,
        StreamSettings(warmup_cycles=warmup_cycles),
        change_at,
        progress=progress,
    )
    rows = stream_rows(store, name)
    summary = summarise(rows)
    summary["run"] = run.to_dict()
    if plot is not None:
        summary["plot"] = str(plot_error(rows, plot))
    return summary


def print_stream(summary: dict) -> None:
    """The per-learner table of `stream_command`'s summary and the figure written."""
    table = pd.DataFrame(summary["models"]).map(
        lambda v: "-" if pd.isna(v) else (f"{v:.3g}" if isinstance(v, float) else v)
    )
    run = summary["run"]
    console.print_frame(
        table.reset_index(names="per learner"),
        title=f"stream {run['stream']}: {run['done_now']} new runs",
    )
    if "plot" in summary:
        console.out.print(f"wrote {summary['plot']}")
