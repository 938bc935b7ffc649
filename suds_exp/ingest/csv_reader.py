"""Reader for the plain CSV marker layout.

Layout (one header row, comma-separated, one row per frame)::

    frame,t,<name>_x,<name>_y,<name>_z,<name>_x,...

``frame`` is a whole number, ``t`` seconds, positions in mm; an empty cell (or ``NA``,
``NaN``) is a missing value (a marker missing in a frame has all three cells empty). The
sample rate is 1 / (median time step) and the time steps must agree with it within 1 %.
"""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture
from suds_exp.ingest.marker_table import MarkerTable, read_marker_table

_COORD = re.compile(r"^(.+)_([xyz])$")


def read_marker_csv(path: Path, text: str) -> Capture:
    """Parse the text of a marker CSV into a `Capture` (positions in mm)."""
    lines = text.splitlines()
    columns = [c.strip() for c in lines[0].split(",")] if lines else []
    if columns[:2] != ["frame", "t"] or (len(columns) - 2) % 3 or len(columns) < 5:
        raise IngestError(
            f"{path}: line 1: expected columns frame,t then <name>_x,<name>_y,<name>_z per marker"
        )
    names = []
    for i in range(2, len(columns), 3):
        found = [_COORD.match(c) for c in columns[i : i + 3]]
        if (
            not all(found)
            or {m.group(1) for m in found} != {found[0].group(1)}
            or [m.group(2) for m in found] != ["x", "y", "z"]
        ):
            raise IngestError(
                f"{path}: line 1, column {i + 1}: expected <name>_x,<name>_y,<name>_z, "
                f"got {','.join(columns[i : i + 3])}"
            )
        names.append(found[0].group(1))
    table = MarkerTable(
        format="csv",
        lines=lines,
        start=1,
        stop=len(lines),
        sep=",",
        columns=columns,
        names=names,
        xyz_columns=list(range(2, len(columns), 3)),
    )
    return read_marker_table(path, table)


def write_marker_csv(path: Path, capture: Capture) -> None:
    """Write ``capture`` in the CSV layout this module reads (missing -> empty cells)."""
    data = {"frame": capture.frame, "t": capture.t}
    for j, name in enumerate(capture.marker_names):
        for k, axis in enumerate("xyz"):
            data[f"{name}_{axis}"] = capture.xyz[:, j, k]
    pd.DataFrame(data).to_csv(path, index=False, float_format="%.3f", na_rep="")
