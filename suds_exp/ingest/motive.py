"""Reader for OptiTrack Motive CSV exports (format version 1.2x, as Motive 2 and 3 write).

Layout (comma-separated)::

    Format Version,1.23,Take Name,...,Export Frame Rate,120.0,...,Length Units,Millimeters,...
    (blank)
    ,Type,Marker,Marker,Marker,Rigid Body,...
    ,Name,Subject:m1,Subject:m1,Subject:m1,...
    ,ID,...
    ,,Position,Position,Position,Rotation,...
    Frame,Time (Seconds),X,Y,Z,...
    <frame>,<time>,x,y,z,...

Only columns of type ``Marker`` holding a ``Position`` are read; other types (rigid
bodies, their markers, skeleton bones) are named in ``Capture.meta["notes"]``. Names
lose their ``Subject:`` prefix when that keeps them unique. A gap is an empty cell.
"""

from __future__ import annotations

import csv
from pathlib import Path

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture
from suds_exp.ingest.marker_table import (
    MarkerTable,
    parse_rate,
    read_marker_table,
    unit_scale,
)
from suds_exp.ingest.vicon import short_names

SIGNATURE = "Format Version"


def is_motive_csv(text: str) -> bool:
    return text.lstrip("\ufeff").startswith(SIGNATURE)


def read_motive_csv(path: Path, text: str) -> Capture:
    """Parse a Motive CSV export into a `Capture` of its labelled markers (mm)."""
    lines = text.lstrip("\ufeff").splitlines()
    first = next(csv.reader([lines[0]]))
    info = {first[i].strip(): first[i + 1].strip() for i in range(0, len(first) - 1, 2)}
    rate_text = info.get("Export Frame Rate") or info.get("Capture Frame Rate", "")
    rate = parse_rate(path, rate_text, "line 1, Export Frame Rate")
    to_mm = unit_scale(path, info.get("Length Units", "Meters"), "line 1, Length Units")
    rows: dict[str, tuple[int, list[str]]] = {}
    table_at = None
    for i, line in enumerate(lines[1:40], start=1):
        cells = [c.strip() for c in next(csv.reader([line]))] if line.strip() else []
        if cells[:2] == ["Frame", "Time (Seconds)"]:
            table_at = i
            break
        if len(cells) > 1 and cells[1] in ("Type", "Name", "ID"):
            rows[cells[1]] = (i, cells)
        elif len(cells) > 2 and not cells[0] and not cells[1]:
            rows["Kind"] = (i, cells)
    if table_at is None or not {"Type", "Name", "Kind"} <= set(rows):
        raise IngestError(
            f"{path}: not a Motive CSV: expected Type, Name and Position rows, then "
            "'Frame,Time (Seconds),X,Y,Z,...'"
        )
    columns = [c.strip() for c in lines[table_at].split(",")]
    kinds, types, full = (rows[k][1] for k in ("Kind", "Type", "Name"))

    def cell(row: list[str], j: int) -> str:
        return row[j] if j < len(row) else ""

    names, xyz_columns, others = [], [], set()
    for j in range(2, len(columns)):
        if cell(types, j) != "Marker" or cell(kinds, j) != "Position":
            if cell(types, j):
                others.add(cell(types, j))
            continue
        if columns[j] == "X":
            if columns[j + 1 : j + 3] != ["Y", "Z"] or cell(full, j) != cell(full, j + 2):
                raise IngestError(
                    f"{path}: line {table_at + 1}, column {j + 1}: expected X,Y,Z of "
                    f"marker {cell(full, j)!r}"
                )
            names.append(cell(full, j))
            xyz_columns.append(j)
    if not names:
        raise IngestError(f"{path}: the Motive export holds no marker positions")
    notes = [f"skipped column type(s) {', '.join(sorted(others))}"] if others else []
    table = MarkerTable(
        format="motive-csv",
        lines=lines,
        start=table_at + 1,
        stop=len(lines),
        sep=",",
        columns=columns,
        names=short_names(names),
        xyz_columns=xyz_columns,
        rate_hz=rate,
        to_mm=to_mm,
        meta={"notes": notes, "full_names": names},
    )
    return read_marker_table(path, table)
