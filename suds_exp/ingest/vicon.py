"""Reader for Vicon Nexus CSV exports (the ``Trajectories`` block).

A Nexus CSV holds one or more blocks separated by blank lines; each block is::

    <title>                      e.g. Trajectories, Devices, Model Outputs, Joints
    <rate>                       Hz
    ,,Subject:Marker,,,Subject:Marker2,,,...
    Frame,Sub Frame,X,Y,Z,X,Y,Z,...
    ,,mm,mm,mm,...               units row (mm, cm or m)
    <frame>,<sub frame>,x,y,z,...

Only the ``Trajectories`` block is read; the other blocks' titles are named in
``Capture.meta["notes"]``. A gap is an empty cell. Marker names lose their ``Subject:``
prefix when the short names are still unique in the file (so one body description fits
every subject), else they keep it. Time is (frame - first frame) / rate.
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

BLOCK = "Trajectories"


def is_vicon_csv(text: str) -> bool:
    """True when the text starts like a Nexus export: a lone title line, then a rate."""
    head = text.lstrip("\ufeff").splitlines()[:2]
    if len(head) < 2:
        return False
    title = head[0].strip().rstrip(",")
    return bool(title) and "," not in title and _is_number(head[1].strip().rstrip(","))


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _blocks(lines: list[str]) -> list[tuple[str, int, int]]:
    """(title, first line index, stop index) of each block."""
    out, i = [], 0
    while i < len(lines):
        if not lines[i].strip().strip(","):
            i += 1
            continue
        j = i
        while j < len(lines) and lines[j].strip().strip(","):
            j += 1
        out.append((lines[i].strip().strip(","), i, j))
        i = j
    return out


def short_names(names: list[str]) -> list[str]:
    """Names without their ``Subject:`` prefix when that keeps them unique."""
    short = [n.split(":", 1)[1] if ":" in n else n for n in names]
    return short if len(set(short)) == len(short) else names


def read_vicon_csv(path: Path, text: str) -> Capture:
    """Parse a Vicon Nexus CSV export into a `Capture` of its Trajectories (mm)."""
    lines = text.splitlines()
    blocks = _blocks(lines)
    found = [b for b in blocks if b[0] == BLOCK]
    if not found:
        titles = ", ".join(b[0][:40] for b in blocks) or "none"
        raise IngestError(
            f"{path}: a Vicon Nexus CSV without a '{BLOCK}' block (blocks found: {titles})"
        )
    _, at, stop = found[0]
    if stop - at < 5:
        raise IngestError(
            f"{path}: line {at + 1}: the {BLOCK} block needs a rate, marker-name, column "
            "and units line before its frames"
        )
    rate = parse_rate(path, lines[at + 1].split(",")[0].strip(), f"line {at + 2}, rate")
    name_cells, col_cells = (next(csv.reader([lines[at + k]])) for k in (2, 3))
    col_cells = [c.strip() for c in col_cells]
    while col_cells and not col_cells[-1]:
        col_cells.pop()
    if col_cells[:2] != ["Frame", "Sub Frame"] or (len(col_cells) - 2) % 3 or len(col_cells) < 5:
        raise IngestError(
            f"{path}: line {at + 4}: expected columns 'Frame,Sub Frame' then X,Y,Z per marker"
        )
    names = []
    for i in range(2, len(col_cells), 3):
        name = name_cells[i].strip() if i < len(name_cells) else ""
        if col_cells[i : i + 3] != ["X", "Y", "Z"] or not name:
            raise IngestError(
                f"{path}: line {at + 3}, column {i + 1}: expected a marker name over X,Y,Z"
            )
        names.append(name)
    units_line = at + 4
    units = [u.strip() for u in next(csv.reader([lines[units_line]]))]
    if units[:1] != [""]:
        raise IngestError(f"{path}: line {units_line + 1}: expected the units row (',,mm,mm,...')")
    given = {u for u in units[2 : len(col_cells)] if u}
    if len(given) != 1:
        raise IngestError(
            f"{path}: line {units_line + 1}: expected one length unit for all markers, "
            f"got {', '.join(sorted(given)) or 'none'}"
        )
    to_mm = unit_scale(path, given.pop(), f"line {units_line + 1}")
    skipped = [b[0] for b in blocks if b[0] != BLOCK]
    notes = [f"skipped block(s) {', '.join(skipped)}"] if skipped else []
    table = MarkerTable(
        format="vicon-csv",
        lines=lines,
        start=units_line + 1,
        stop=stop,
        sep=",",
        columns=col_cells[:2] + [f"{n} {a}" for n in names for a in "XYZ"],
        names=short_names(names),
        xyz_columns=list(range(2, len(col_cells), 3)),
        time_column=None,
        rate_hz=rate,
        to_mm=to_mm,
        meta={"notes": notes, "full_names": names},
    )
    return read_marker_table(path, table)
