"""Reader for the plain CSV marker layout.

Layout (one header row, comma-separated, one row per frame)::

    frame,t,<name>_x,<name>_y,<name>_z,<name>_x,...

``frame`` is a whole number, ``t`` seconds, positions in mm; an empty cell is a missing
value (a marker missing in a frame has all three cells empty). The sample rate is
1 / (median time step) and the time steps must agree with it within 1 %.
"""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture, parse_numeric_block

_COORD = re.compile(r"^(.+)_([xyz])$")


def read_marker_csv(path: Path, text: str) -> Capture:
    """Parse the text of a marker CSV into a `Capture` (positions in mm)."""
    try:
        cells = pd.read_csv(
            io.StringIO(text), dtype=str, keep_default_na=False, on_bad_lines="error"
        )
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        line = re.search(r"line (\d+)", str(exc))
        where = f"line {line.group(1)}: " if line else ""
        raise IngestError(
            f"{path}: {where}not a marker CSV (expected frame,t,<name>_x,...)"
        ) from None
    columns = [c.strip() for c in cells.columns]
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
    if cells.empty:
        raise IngestError(f"{path}: the file holds no frames")
    values = parse_numeric_block(path, cells, 2, columns)
    frame, t = values[:, 0], values[:, 1]
    if np.any(np.isnan(frame)) or np.any(np.isnan(t)):
        row = int(np.flatnonzero(np.isnan(frame) | np.isnan(t))[0])
        raise IngestError(f"{path}: line {row + 2}: frame and t must not be empty")
    if np.any(frame != np.round(frame)):
        row = int(np.flatnonzero(frame != np.round(frame))[0])
        raise IngestError(f"{path}: line {row + 2}, column 'frame': expected a whole number")
    steps = np.diff(t)
    if steps.size == 0:
        raise IngestError(f"{path}: at least two frames are needed to know the sample rate")
    dt = float(np.median(steps))
    capture = Capture(
        path=path,
        format="csv",
        sample_rate_hz=round(1.0 / dt, 6) if dt > 0 else float("nan"),
        marker_names=names,
        frame=frame.astype(np.int64),
        t=t,
        xyz=values[:, 2:].reshape(len(t), len(names), 3),
        first_line=2,
    )
    capture.validate()
    if np.any(np.abs(steps - dt) > 0.01 * dt):
        row = int(np.flatnonzero(np.abs(steps - dt) > 0.01 * dt)[0]) + 1
        raise IngestError(
            f"{path}: line {row + 2}: time step {steps[row - 1]:g} s differs from the median "
            f"{dt:g} s; expected a constant sample rate"
        )
    return capture


def write_marker_csv(path: Path, capture: Capture) -> None:
    """Write ``capture`` in the CSV layout this module reads (missing -> empty cells)."""
    data = {"frame": capture.frame, "t": capture.t}
    for j, name in enumerate(capture.marker_names):
        for k, axis in enumerate("xyz"):
            data[f"{name}_{axis}"] = capture.xyz[:, j, k]
    pd.DataFrame(data).to_csv(path, index=False, float_format="%.3f", na_rep="")
