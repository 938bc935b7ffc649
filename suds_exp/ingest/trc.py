"""Reader for TRC files (Motion Analysis "track row column", as OpenSim reads and writes).

Layout (tab-separated)::

    PathFileType  4  (X/Y/Z)  <file name>
    DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  ...
    <values of the keys above>
    Frame#  Time  <name>  (two empty cells)  <name>  ...
    (two empty cells)  X1  Y1  Z1  X2  Y2  Z2 ...
    (an optional blank line)
    <frame>  <time>  x  y  z ...

Units is mm, cm or m; a missing marker is empty cells or NaN.
"""

from __future__ import annotations

from pathlib import Path

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture
from suds_exp.ingest.marker_table import (
    MarkerTable,
    parse_rate,
    read_marker_table,
    unit_scale,
)


def read_trc(path: Path, text: str) -> Capture:
    """Parse the text of a TRC file into a `Capture` (positions in mm)."""
    lines = text.splitlines()
    if len(lines) < 5 or not lines[0].startswith("PathFileType"):
        raise IngestError(f"{path}: line 1: not a TRC file (expected 'PathFileType<TAB>4...')")
    keys = [k.strip() for k in lines[1].split("\t")]
    values = [v.strip() for v in lines[2].split("\t")]
    header = dict(zip(keys, values, strict=False))
    for key in ("DataRate", "NumFrames", "NumMarkers", "Units"):
        if not header.get(key):
            raise IngestError(f"{path}: lines 2-3: the TRC header lacks {key}")
    rate = parse_rate(path, header["DataRate"], "line 3, DataRate")
    try:
        n_frames, n_markers = int(header["NumFrames"]), int(header["NumMarkers"])
    except ValueError:
        raise IngestError(
            f"{path}: line 3: NumFrames and NumMarkers must be whole numbers"
        ) from None
    to_mm = unit_scale(path, header["Units"], "line 3, Units")
    name_cells = lines[3].rstrip("\t").split("\t")
    if [c.strip() for c in name_cells[:2]] != ["Frame#", "Time"]:
        raise IngestError(f"{path}: line 4: expected 'Frame#<TAB>Time' then the marker names")
    names = [c.strip() for c in name_cells[2::3]]
    if len(names) != n_markers or not all(names):
        raise IngestError(
            f"{path}: line 4: NumMarkers says {n_markers} but the line names {len(names)}"
        )
    axes = [c.strip() for c in lines[4].strip("\t").split("\t")]
    expected = [f"{a}{i}" for i in range(1, n_markers + 1) for a in "XYZ"]
    if axes != expected:
        raise IngestError(f"{path}: line 5: expected X1 Y1 Z1 ... Z{n_markers}")
    start = 6 if len(lines) > 5 and not lines[5].strip() else 5
    table = MarkerTable(
        format="trc",
        lines=lines,
        start=start,
        stop=len(lines),
        sep="\t",
        columns=["Frame#", "Time"] + [f"{n} {a}" for n in names for a in "XYZ"],
        names=names,
        xyz_columns=list(range(2, 2 + 3 * n_markers, 3)),
        rate_hz=rate,
        to_mm=to_mm,
        declared_frames=(n_frames, "NumFrames"),
    )
    return read_marker_table(path, table)
