"""Writers of what a capture session leaves behind: QTM TSV exports, the manifest CSV
and the simulator's ground-truth Parquet files."""

from __future__ import annotations

import csv
import datetime as _dt
import math
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from suds_exp.sim._jit import njit

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
    decimals = np.array([0, 5] + [3] * (3 * k), dtype=np.int64)
    body = format_table(table, decimals)
    with open(path, "wb") as fh:
        fh.write(("\r\n".join(header) + "\r\n").encode())
        fh.write(body)


@njit(cache=True)
def _format_into(values, decimals, out):
    """Write values (n, m) as tab-separated fixed-point text with CRLF rows into out
    (uint8); returns the number of bytes. Rounds half away from zero."""
    pos = 0
    digits = np.empty(24, dtype=np.uint8)
    for i in range(values.shape[0]):
        for j in range(values.shape[1]):
            d = decimals[j]
            scale = 10.0**d
            q = int(math.floor(abs(values[i, j]) * scale + 0.5))
            if values[i, j] < 0 and q != 0:
                out[pos] = 45  # '-'
                pos += 1
            nd = 0
            while True:
                digits[nd] = 48 + q % 10
                q //= 10
                nd += 1
                if q == 0 and nd > d:
                    break
            for r in range(nd - 1, -1, -1):
                out[pos] = digits[r]
                pos += 1
                if r == d and d > 0:
                    out[pos] = 46  # '.'
                    pos += 1
            if j < values.shape[1] - 1:
                out[pos] = 9
                pos += 1
        out[pos] = 13
        out[pos + 1] = 10
        pos += 2
    return pos


def format_table(values: np.ndarray, decimals: np.ndarray) -> bytes:
    """Tab-separated, CRLF-terminated text of values (n, m), column j with decimals[j]
    digits after the point (like "%.{d}f", rounding half away from zero); compiled,
    because formatting dominates writing a session's TSV files otherwise."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    if not np.all(np.abs(values) < 1e12):
        raise ValueError("format_table: values must be finite and below 1e12")
    buf = np.empty(values.size * 24 + 2 * len(values), dtype=np.uint8)
    return buf[: _format_into(values, np.asarray(decimals, dtype=np.int64), buf)].tobytes()


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
