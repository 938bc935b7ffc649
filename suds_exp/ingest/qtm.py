"""Reader for Qualisys Track Manager (QTM) 3D TSV exports.

Layout: ``KEY<TAB>value...`` header lines (NO_OF_FRAMES, NO_OF_MARKERS, FREQUENCY,
MARKER_NAMES, TRAJECTORY_TYPES, ...), then a column line
``Frame Time <name> X <name> Y <name> Z ...`` and one line per frame. QTM writes a
marker it did not see as ``0 0 0`` (or leaves the cells empty when gap filling is off);
both are read as missing. Line ends may be CRLF; a trailing tab is allowed.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture, parse_numeric_block

_REQUIRED = ("NO_OF_FRAMES", "NO_OF_MARKERS", "FREQUENCY", "MARKER_NAMES")


def _header_int(path: Path, header: dict, key: str, line: int) -> int:
    try:
        value = int(header[key][0])
    except (ValueError, IndexError):
        raise IngestError(f"{path}: line {line}, {key}: expected a whole number") from None
    if value < 0:
        raise IngestError(f"{path}: line {line}, {key}: expected a non-negative number")
    return value


def read_qtm_tsv(path: Path, text: str) -> Capture:
    """Parse the text of a QTM 3D TSV export into a `Capture` (positions in mm)."""
    lines = text.splitlines()
    header: dict[str, list[str]] = {}
    header_line: dict[str, int] = {}
    table_at = None
    for i, line in enumerate(lines):
        cells = line.rstrip("\t").split("\t")
        if cells[0] == "Frame" and len(cells) > 1 and cells[1] == "Time":
            table_at = i
            break
        if not line.strip():
            continue
        if not cells[0].replace("_", "").isalnum() or not cells[0].isupper():
            raise IngestError(
                f"{path}: line {i + 1}: expected a header line such as 'NO_OF_FRAMES<TAB>n' "
                f"or the 'Frame<TAB>Time...' column line"
            )
        header[cells[0]] = cells[1:]
        header_line[cells[0]] = i + 1
    missing = [k for k in _REQUIRED if k not in header]
    if missing:
        raise IngestError(f"{path}: not a QTM TSV export: header lacks {', '.join(missing)}")
    if table_at is None:
        raise IngestError(f"{path}: no 'Frame<TAB>Time' column line: the file is truncated")

    n_frames = _header_int(path, header, "NO_OF_FRAMES", header_line["NO_OF_FRAMES"])
    n_markers = _header_int(path, header, "NO_OF_MARKERS", header_line["NO_OF_MARKERS"])
    try:
        rate = float(header["FREQUENCY"][0])
    except (ValueError, IndexError):
        rate = float("nan")
    if not np.isfinite(rate) or rate <= 0:
        raise IngestError(
            f"{path}: line {header_line['FREQUENCY']}, FREQUENCY: expected a positive number of Hz"
        )
    names = [n.strip() for n in header["MARKER_NAMES"]]
    if len(names) != n_markers:
        raise IngestError(
            f"{path}: line {header_line['MARKER_NAMES']}: NO_OF_MARKERS says {n_markers} "
            f"but MARKER_NAMES lists {len(names)}"
        )
    columns = lines[table_at].rstrip("\t").split("\t")
    expected = ["Frame", "Time"] + [f"{n} {a}" for n in names for a in "XYZ"]
    if [c.strip() for c in columns] != expected:
        raise IngestError(
            f"{path}: line {table_at + 1}: expected columns 'Frame Time' then "
            f"'<name> X/Y/Z' for the {n_markers} markers of MARKER_NAMES"
        )
    body = lines[table_at + 1 :]
    while body and not body[-1].strip():
        body.pop()
    if len(body) != n_frames:
        raise IngestError(
            f"{path}: NO_OF_FRAMES says {n_frames} but the file has {len(body)} data lines"
            + (" (truncated?)" if len(body) < n_frames else "")
        )
    n_cols = len(expected)
    # A well-formed line has n_cols cells, plus an empty one after a trailing tab.
    tabs = np.fromiter((line.count("\t") for line in body), dtype=np.int64, count=len(body))
    trailing = np.fromiter((line.endswith("\t") for line in body), dtype=bool, count=len(body))
    wrong = (tabs < n_cols - 1) | (tabs > n_cols) | ((tabs == n_cols) & ~trailing)
    if wrong.any():
        row = int(np.flatnonzero(wrong)[0])
        raise IngestError(
            f"{path}: line {table_at + 2 + row}: expected {n_cols} tab-separated values, "
            f"got {tabs[row] + 1 - int(trailing[row])}"
        )
    values = _parse_floats(path, body, n_cols, table_at + 2, expected)
    xyz = values[:, 2:].reshape(len(body), n_markers, 3)
    # QTM exports an unseen marker as exactly 0 0 0.
    unseen = np.all(xyz == 0.0, axis=2)
    xyz[unseen] = np.nan
    frame = values[:, 0]
    if np.any(np.isnan(frame)) or np.any(frame != np.round(frame)):
        row = int(np.flatnonzero(np.isnan(frame) | (frame != np.round(frame)))[0])
        raise IngestError(
            f"{path}: line {table_at + 2 + row}, column 'Frame': expected a whole number"
        )
    return Capture(
        path=path,
        format="qtm-tsv",
        sample_rate_hz=rate,
        marker_names=names,
        frame=frame.astype(np.int64),
        t=values[:, 1],
        xyz=xyz,
        meta={"trajectory_types": header.get("TRAJECTORY_TYPES", [])},
        first_line=table_at + 2,
    )


def _parse_floats(
    path: Path, body: list[str], n_cols: int, first_line: int, columns: list[str]
) -> np.ndarray:
    """The data lines as floats, shape (n_lines, n_cols); empty cells become NaN."""
    text = "\n".join(line[:-1] if line.endswith("\t") else line for line in body)
    options = dict(sep="\t", header=None, names=range(n_cols), engine="c")
    try:
        # Fast path: the C parser converts straight to float.
        return pd.read_csv(
            io.StringIO(text), dtype=float, na_values=[""], keep_default_na=False, **options
        ).to_numpy()
    except (ValueError, pd.errors.ParserError):
        pass  # some cell is not a number: find and name it below
    cells = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False, **options)
    return parse_numeric_block(path, cells.fillna(""), first_line, columns)
