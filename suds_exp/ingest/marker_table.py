"""The parsing core every text capture format shares.

A text export (QTM TSV, Vicon Nexus CSV, OpenSim TRC, OptiTrack Motive CSV, our plain
CSV) is a header, which each format's reader interprets, then a block of delimited lines,
one per frame, holding a frame number, perhaps a time, and X Y Z per marker. The reader
describes that block with a `MarkerTable`; `read_marker_table` parses it, checks it and
returns the `Capture`, so line/column error messages, missing-value tokens, unit
conversion and rate checks are written once.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture

#: Cells read as a missing value (what QTM, Nexus, OpenSim and Motive write for a gap).
MISSING_TOKENS = ("", "NA", "NaN", "nan", "NAN", "-nan", "N/A", "#N/A", "null")

#: Length unit names (lower case) -> factor to mm.
UNIT_TO_MM = {
    "mm": 1.0,
    "millimeters": 1.0,
    "millimetres": 1.0,
    "cm": 10.0,
    "centimeters": 10.0,
    "centimetres": 10.0,
    "m": 1000.0,
    "meters": 1000.0,
    "metres": 1000.0,
}


def unit_scale(path: Path, unit: str, where: str) -> float:
    """Factor from ``unit`` (e.g. ``"mm"``, ``"Meters"``) to mm; `IngestError` if unknown."""
    try:
        return UNIT_TO_MM[unit.strip().lower()]
    except KeyError:
        raise IngestError(
            f"{path}: {where}: length unit {unit.strip()!r}; expected mm, cm or m"
        ) from None


def parse_rate(path: Path, text: str, where: str) -> float:
    """The sample rate in ``text`` (Hz); `IngestError` naming ``where`` unless positive."""
    try:
        rate = float(text)
    except ValueError:
        rate = float("nan")
    if not rate > 0:
        raise IngestError(f"{path}: {where}: expected a positive number of Hz, got {text!r}")
    return rate


@dataclass
class MarkerTable:
    """Where a text export keeps its frames, as its reader found in the header.

    Attributes
    ----------
    format : str
        Format name stored in ``trials.format``.
    lines : list of str
        The file's lines (no line ends).
    start, stop : int
        0-based indices of the first data line and one past the last.
    sep : str
        Cell separator.
    columns : list of str
        A label per cell of a data line, for error messages.
    names : list of str
        Marker names, in the order of ``xyz_columns``.
    xyz_columns : list of int
        Index of each marker's X cell (Y and Z follow it).
    frame_column : int
        Index of the frame-number cell.
    time_column : int or None
        Index of the time cell (s); None: time is (frame - first frame) / rate.
    rate_hz : float or None
        Sample rate; None: 1 / median time step, and steps must agree with it within 1 %.
    to_mm : float
        Factor from the file's length unit to mm.
    zero_is_missing : bool
        Read a marker at exactly (0, 0, 0) as missing (QTM's convention for a gap).
    declared_frames : tuple (int, str) or None
        Frame count the header declares, and the header key that says so.
    """

    format: str
    lines: list[str]
    start: int
    stop: int
    sep: str
    columns: list[str]
    names: list[str]
    xyz_columns: list[int]
    frame_column: int = 0
    time_column: int | None = 1
    rate_hz: float | None = None
    to_mm: float = 1.0
    zero_is_missing: bool = False
    declared_frames: tuple[int, str] | None = None
    meta: dict = field(default_factory=dict)


def read_marker_table(path: Path, table: MarkerTable) -> Capture:
    """Parse the data lines ``table`` describes into a validated `Capture` (mm)."""
    body = table.lines[table.start : table.stop]
    while body and not body[-1].strip():
        body.pop()
    first_line = table.start + 1
    if table.declared_frames is not None:
        n_declared, key = table.declared_frames
        if len(body) != n_declared:
            raise IngestError(
                f"{path}: {key} says {n_declared} but the file has {len(body)} data lines"
                + (" (truncated?)" if len(body) < n_declared else "")
            )
    if not body:
        raise IngestError(f"{path}: the file holds no frames")
    values = _parse_cells(path, body, table.sep, first_line, table.columns)
    frame = values[:, table.frame_column]
    bad = np.isnan(frame) | (frame != np.round(frame))
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise IngestError(
            f"{path}: line {first_line + row}, column "
            f"{table.columns[table.frame_column]!r}: expected a whole number"
        )
    cols = np.asarray(table.xyz_columns, dtype=np.int64)[:, None] + np.arange(3)
    xyz = values[:, cols] * table.to_mm
    if table.zero_is_missing:
        xyz[np.all(xyz == 0.0, axis=2)] = np.nan
    rate = table.rate_hz
    if table.time_column is not None:
        t = values[:, table.time_column]
        if np.any(np.isnan(t)):
            row = int(np.flatnonzero(np.isnan(t))[0])
            raise IngestError(
                f"{path}: line {first_line + row}, column "
                f"{table.columns[table.time_column]!r}: time must not be empty"
            )
    else:
        t = (frame - frame[0]) / rate
    if rate is None:
        rate = _rate_from_times(path, t, first_line)
    capture = Capture(
        path=path,
        format=table.format,
        sample_rate_hz=rate,
        marker_names=list(table.names),
        frame=frame.astype(np.int64),
        t=t,
        xyz=xyz,
        meta=table.meta,
        first_line=first_line,
    )
    capture.validate()
    if table.rate_hz is None:
        _check_constant_rate(path, t, first_line)
    return capture


def _rate_from_times(path: Path, t: np.ndarray, first_line: int) -> float:
    steps = np.diff(t)
    if steps.size == 0:
        raise IngestError(f"{path}: at least two frames are needed to know the sample rate")
    dt = float(np.median(steps))
    return round(1.0 / dt, 6) if dt > 0 else float("nan")


def _check_constant_rate(path: Path, t: np.ndarray, first_line: int) -> None:
    steps = np.diff(t)
    dt = float(np.median(steps))
    off = np.abs(steps - dt) > 0.01 * dt
    if off.any():
        row = int(np.flatnonzero(off)[0]) + 1
        raise IngestError(
            f"{path}: line {first_line + row}: time step {steps[row - 1]:g} s differs from "
            f"the median {dt:g} s; expected a constant sample rate"
        )


def _parse_cells(
    path: Path, body: list[str], sep: str, first_line: int, columns: list[str]
) -> np.ndarray:
    """The data lines as floats, shape (n_lines, n_cols); missing tokens become NaN.

    A well-formed line has exactly ``len(columns)`` cells, plus an empty one after a
    trailing separator.
    """
    n_cols = len(columns)
    seps = np.fromiter((line.count(sep) for line in body), dtype=np.int64, count=len(body))
    trailing = np.fromiter((line.endswith(sep) for line in body), dtype=bool, count=len(body))
    wrong = (seps < n_cols - 1) | (seps > n_cols) | ((seps == n_cols) & ~trailing)
    if wrong.any():
        row = int(np.flatnonzero(wrong)[0])
        what = "tab-separated" if sep == "\t" else "comma-separated"
        raise IngestError(
            f"{path}: line {first_line + row}: expected {n_cols} {what} values, "
            f"got {seps[row] + 1 - int(trailing[row] and seps[row] == n_cols)}"
        )
    text = "\n".join(line[:-1] if seps[i] == n_cols else line for i, line in enumerate(body))
    options = dict(sep=sep, header=None, names=range(n_cols), engine="c", quoting=3)
    try:
        # Fast path: the C parser converts straight to float.
        return pd.read_csv(
            io.StringIO(text),
            dtype=float,
            na_values=list(MISSING_TOKENS),
            keep_default_na=False,
            skip_blank_lines=False,
            **options,
        ).to_numpy()
    except (ValueError, pd.errors.ParserError):
        pass  # some cell is not a number: find and name it below
    cells = pd.read_csv(
        io.StringIO(text), dtype=str, keep_default_na=False, skip_blank_lines=False, **options
    ).fillna("")
    return parse_cell_block(path, cells, first_line, columns)


def parse_cell_block(
    path: Path, cells: pd.DataFrame, first_line: int, columns: list[str]
) -> np.ndarray:
    """Convert a block of text cells to floats; missing tokens become NaN.

    ``first_line`` is the 1-based file line of the block's first row, so an error can
    name the line and column of the first cell that is not a number.
    """
    stripped = cells.apply(lambda c: c.str.strip())
    values = stripped.apply(pd.to_numeric, errors="coerce")
    bad = values.isna() & ~stripped.isin(MISSING_TOKENS)
    if bad.to_numpy().any():
        row, col = np.argwhere(bad.to_numpy())[0]
        raise IngestError(
            f"{path}: line {first_line + row}, column {columns[col]!r}: expected a number, "
            f"got {stripped.iat[row, col]!r}"
        )
    return values.to_numpy(dtype=float)
