"""Terminal output shared by the CLI commands: tables, JSON, messages.

pandas and the store's JSON writer are imported where a table is printed: `suds-exp
--version` and `--help` print none and start without them.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from rich.console import Console
from rich.table import Table
from rich.text import Text

if TYPE_CHECKING:
    import pandas as pd

out = Console(highlight=False, soft_wrap=True)
err = Console(stderr=True, highlight=False, soft_wrap=True)


def print_frame(frame: pd.DataFrame, title: str | None = None, max_rows: int = 200) -> None:
    """Print a DataFrame as a rich table (first ``max_rows`` rows)."""
    import pandas as pd

    table = Table(title=title, show_lines=False)
    # cells are data: Text, so a label such as "learner[kNN]" is not read as rich markup
    for column in frame.columns:
        table.add_column(Text(str(column)), overflow="fold")
    for row in frame.head(max_rows).itertuples(index=False):
        table.add_row(*(Text("" if pd.isna(v) is True else _fmt(v)) for v in row))
    out.print(table)
    if len(frame) > max_rows:
        out.print(f"... {len(frame) - max_rows} more rows")


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def output_lines(enabled: bool = True) -> Callable[[str], None]:
    """``say(line)`` for a function whose output is a narration (the demo): each line on
    stdout as plain text when enabled, else nothing (``--json`` prints one document
    instead). Progress goes to stderr (`suds_exp.progress`); this is the result."""
    if not enabled:
        return lambda _line: None
    return lambda line: out.print(line, markup=False, highlight=False)


def print_json(document: Any) -> None:
    """Print one JSON document on stdout (a DataFrame becomes a list of row objects)."""
    import pandas as pd

    from suds_exp.store.sql import frame_to_json

    if isinstance(document, pd.DataFrame):
        text = frame_to_json(document)
    else:
        text = json.dumps(document, default=str, indent=None)
    sys.stdout.write(text + "\n")
    sys.stdout.flush()
