"""Writers of what a capture session leaves behind: QTM TSV exports, the manifest CSV
and the simulator's ground-truth Parquet files."""

from __future__ import annotations

import csv
import datetime as _dt
import io
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

TRUTH_COLUMNS = (
    "t",
    "x",
    "y",
    "theta",
    "vx",
    "vy",
    "wz",
    "phi1",
    "phi2",
    "flipper_1",
    "flipper_2",
    "flipper_3",
    "flipper_4",
    "phase_cmd",
)
MANIFEST_COLUMNS = ("file", "gait", "frequency_hz", "repeat", "notes")


def _clock_seconds(timestamp: _dt.datetime) -> float:
    """QTM's second stamp is a capture-computer clock; use seconds since New Year
    (time-zone free, so files stay byte-identical across machines)."""
    return (timestamp - _dt.datetime(timestamp.year, 1, 1)).total_seconds()


def write_qtm_tsv(
    path: Path,
    positions: np.ndarray,
    marker_names: list[str] | tuple[str, ...],
    sample_rate_hz: float,
    timestamp: _dt.datetime,
    n_cameras: int = 4,
) -> None:
    """Write a Qualisys QTM 3D TSV export (layout of refdata/qtm_measurement1.tsv, CRLF).

    positions: array (n_frames, n_markers, 3), mm, NaN where a marker was not seen
    (written as 0.000 0.000 0.000, as QTM does).
    """
    n, k, _ = positions.shape
    names = list(marker_names)
    stamp = timestamp.strftime("%Y-%m-%d, %H:%M:%S.") + f"{timestamp.microsecond // 1000:03d}"
    header = [
        f"NO_OF_FRAMES\t{n}",
        f"NO_OF_CAMERAS\t{n_cameras}",
        f"NO_OF_MARKERS\t{k}",
        f"FREQUENCY\t{sample_rate_hz:g}",
        "NO_OF_ANALOG\t0",
        "ANALOG_FREQUENCY\t0",
        "DESCRIPTION\t--",
        f"TIME_STAMP\t{stamp}\t{_clock_seconds(timestamp):.8f}",
        "DATA_INCLUDED\t3D",
        "MARKER_NAMES\t" + "\t".join(names),
        "TRAJECTORY_TYPES\t" + "\t".join(["Measured"] * k),
        "Frame\tTime\t" + "".join(f"{m} X\t{m} Y\t{m} Z\t" for m in names),
    ]
    data = np.nan_to_num(positions.reshape(n, 3 * k), nan=0.0)
    # "-0.000" is what %.3f gives for tiny negatives; QTM writes 0.000
    data = np.where(np.abs(data) < 0.0005, 0.0, data)
    table = np.column_stack([np.arange(1, n + 1), np.arange(n) / sample_rate_hz, data])
    buf = io.StringIO()
    np.savetxt(
        buf,
        table,
        fmt=["%d", "%.5f"] + ["%.3f"] * (3 * k),
        delimiter="\t",
        newline="\r\n",
    )
    with open(path, "w", newline="") as fh:
        fh.write("\r\n".join(header) + "\r\n")
        fh.write(buf.getvalue())


def write_truth(path: Path, columns: dict[str, np.ndarray]) -> None:
    """Write a truth Parquet file with exactly `TRUTH_COLUMNS` (float64)."""
    missing = [c for c in TRUTH_COLUMNS if c not in columns]
    if missing:
        raise ValueError(f"truth columns missing: {missing}")
    table = pa.table({c: pa.array(np.asarray(columns[c], dtype=float)) for c in TRUTH_COLUMNS})
    pq.write_table(table, path, compression="zstd")


def write_manifest(path: Path, rows: list[dict]) -> None:
    """Write the manifest CSV (file relative to the manifest's folder)."""
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=MANIFEST_COLUMNS, lineterminator="\n")
        w.writeheader()
        for row in rows:
            w.writerow({c: row.get(c, "") for c in MANIFEST_COLUMNS})
