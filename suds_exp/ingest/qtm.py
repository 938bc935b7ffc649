"""Reader for Qualisys Track Manager (QTM) 3D TSV exports.

Layout: ``KEY<TAB>value...`` header lines (NO_OF_FRAMES, NO_OF_MARKERS, FREQUENCY,
MARKER_NAMES, TRAJECTORY_TYPES, TIME_STAMP, EVENT, ...; any upper-case key is accepted),
then a column line ``Frame Time <name> X <name> Y <name> Z ...`` and one line per frame,
numbered from any first frame. QTM writes a marker it did not see as ``0 0 0``, as
``NA`` or ``NaN``, or leaves the cells empty; all are read as missing. Line ends may be
CRLF; a trailing tab is allowed.
"""

from __future__ import annotations

from pathlib import Path

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture
from suds_exp.ingest.marker_table import MarkerTable, parse_rate, read_marker_table

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
    rate = parse_rate(
        path, (header["FREQUENCY"] or [""])[0], f"line {header_line['FREQUENCY']}, FREQUENCY"
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
    table = MarkerTable(
        format="qtm-tsv",
        lines=lines,
        start=table_at + 1,
        stop=len(lines),
        sep="\t",
        columns=expected,
        names=names,
        xyz_columns=list(range(2, len(expected), 3)),
        rate_hz=rate,
        # QTM exports an unseen marker as exactly 0 0 0 (or NA, or empty cells).
        zero_is_missing=True,
        declared_frames=(n_frames, "NO_OF_FRAMES"),
        meta={"trajectory_types": header.get("TRAJECTORY_TYPES", [])},
    )
    return read_marker_table(path, table)
