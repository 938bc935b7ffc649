"""Reader for C3D files, through the pure-Python ``c3d`` package.

A point whose residual is negative is invalid in C3D; it is read as missing, as is a
point at exactly (0, 0, 0). Positions are converted to mm from POINT:UNITS.
"""

from __future__ import annotations

import io
import warnings
from pathlib import Path

import c3d
import numpy as np

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture

_TO_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0}


def read_c3d(path: Path, data: bytes) -> Capture:
    """Parse the bytes of a C3D file into a `Capture` (positions in mm)."""
    if len(data) < 512 or data[1] != 0x50:
        raise IngestError(f"{path}: not a C3D file (expected a 512-byte header with key 0x50)")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reader = c3d.Reader(io.BytesIO(data))
            names = [str(n).strip() for n in reader.point_labels]
            rate = float(reader.point_rate)
            units = reader.get("POINT:UNITS")
            unit = units.string_value.strip().lower() if units is not None else "mm"
            n_expected = int(reader.last_frame) - int(reader.first_frame) + 1
            frames, points = [], []
            for number, pts, _analog in reader.read_frames(copy=False):
                frames.append(number)
                points.append(np.array(pts[:, :4], dtype=float))
    except IngestError:
        raise
    except Exception as exc:  # the library's own errors: corrupt or truncated file
        reason = str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__
        raise IngestError(f"{path}: not a readable C3D file ({reason})") from None
    if unit not in _TO_MM:
        raise IngestError(f"{path}: POINT:UNITS is {unit!r}; expected mm, cm or m")
    if len(frames) != n_expected:
        raise IngestError(
            f"{path}: header says {n_expected} frames but the file holds {len(frames)} (truncated?)"
        )
    if not frames:
        raise IngestError(f"{path}: the file holds no frames")
    pts = np.stack(points)
    if pts.shape[1] != len(names):
        raise IngestError(
            f"{path}: POINT:LABELS lists {len(names)} markers but frames hold {pts.shape[1]}"
        )
    xyz = pts[:, :, :3] * _TO_MM[unit]
    invalid = (
        (pts[:, :, 3] < 0)
        | np.all(pts[:, :, :3] == 0.0, axis=2)
        | ~np.all(np.isfinite(xyz), axis=2)
    )
    xyz[invalid] = np.nan
    frame = np.asarray(frames, dtype=np.int64)
    return Capture(
        path=path,
        format="c3d",
        sample_rate_hz=rate,
        marker_names=names,
        frame=frame,
        t=(frame - frame[0]) / rate if rate > 0 else frame.astype(float),
        xyz=xyz,
    )
