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


#: widest a cell is shown in a terminal table before it wraps within its column
MAX_CELL = 40


def print_frame(frame: pd.DataFrame, title: str | None = None, max_rows: int = 200) -> None:
    """Print a DataFrame as `print_rows` does (first ``max_rows`` rows)."""
    import pandas as pd

    from suds_exp.store.rows import Rows

    cells = [
        tuple(None if pd.isna(v) is True else v for v in row)
        for row in frame.head(max_rows).itertuples(index=False)
    ]
    print_rows(Rows(tuple(str(c) for c in frame.columns), cells), title, max_rows, len(frame))


def print_rows(rows, title: str | None = None, max_rows: int = 200, total: int | None = None):
    """Print `suds_exp.store.rows.Rows` (first ``max_rows``) so that they fit the output.

    In a terminal: a table, its columns split into blocks as wide as the terminal (the
    first column, the row's key, repeated in each), so nothing is squeezed into slivers.
    Piped: plain aligned text, a row a line and no title, for `grep`, `cut` and `less`."""
    columns = [str(c) for c in rows.columns]
    cells = [["" if v is None else _fmt(v) for v in row] for row in rows.rows[:max_rows]]
    # columns without a value in any row shown are named once, not drawn
    empty = [j for j in range(len(columns)) if cells and not any(row[j] for row in cells)]
    if empty and len(empty) < len(columns):
        kept = [j for j in range(len(columns)) if j not in empty]
        note = "empty columns: " + ", ".join(columns[j] for j in empty)
        columns = [columns[j] for j in kept]
        cells = [[row[j] for j in kept] for row in cells]
    else:
        note = None
    if not out.is_terminal:
        for line in plain_lines(columns, cells):
            out.print(line, markup=False, highlight=False, soft_wrap=True)
    else:
        for i, block in enumerate(column_blocks(columns, cells, out.width)):
            table = Table(title=title if i == 0 else None, show_lines=False)
            # cells are data: Text, so a label such as "learner[kNN]" is not read as markup
            for j in block:
                table.add_column(Text(columns[j]), overflow="fold", max_width=MAX_CELL)
            for row in cells:
                table.add_row(*(Text(row[j]) for j in block))
            out.print(table)
    if note:
        out.print(note, markup=False, highlight=False)
    total = len(rows) if total is None else total
    if total > max_rows:
        out.print(f"... {total - max_rows} more rows", highlight=False)


def plain_lines(columns: list[str], cells: list[list[str]]) -> list[str]:
    """Rows as lines of columns padded to their widest cell, two spaces apart."""
    widths = [max([len(c), *(len(row[j]) for row in cells)]) for j, c in enumerate(columns)]
    return [
        "  ".join(v.ljust(w) for v, w in zip(line, widths, strict=True)).rstrip()
        for line in [columns, *cells]
    ]


def column_blocks(columns: list[str], cells: list[list[str]], width: int) -> list[list[int]]:
    """The column indices of each block of a table ``width`` characters wide: as many
    columns as fit at their natural width (at most `MAX_CELL`), the first in every block."""
    natural = [
        min(MAX_CELL, max([len(c), *(len(row[j]) for row in cells)])) for j, c in enumerate(columns)
    ]
    # a rich table's borders and padding: 3 characters a column, 1 at the end
    blocks: list[list[int]] = []
    block = [0]
    used = 1 + natural[0] + 3
    for j in range(1, len(columns)):
        if len(block) > 1 and used + natural[j] + 3 > width:
            blocks.append(block)
            block, used = [0], 1 + natural[0] + 3
        block.append(j)
        used += natural[j] + 3
    blocks.append(block)
    return blocks


def print_csv(rows) -> None:
    """`Rows` or a DataFrame as CSV on stdout, a header line first."""
    import csv

    from suds_exp.store.rows import plain

    if type(rows).__name__ == "DataFrame":
        rows.to_csv(sys.stdout, index=False)
        return
    writer = csv.writer(sys.stdout, lineterminator="\n")
    writer.writerow(rows.columns)
    writer.writerows([[plain(v) for v in row] for row in rows.rows])
    sys.stdout.flush()


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
    """Print one JSON document on stdout (a DataFrame or `Rows` becomes a list of row
    objects)."""
    if hasattr(document, "records"):  # suds_exp.store.rows.Rows
        text = json.dumps(document.records(), default=str)
    elif type(document).__name__ == "DataFrame":  # pandas is loaded when one exists
        from suds_exp.store.sql import frame_to_json

        text = frame_to_json(document)
    else:
        text = json.dumps(document, default=str, indent=None)
    sys.stdout.write(text + "\n")
    sys.stdout.flush()
