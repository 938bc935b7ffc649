"""Dispatch from a file's extension to its reader."""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from pathlib import Path

from suds_exp.errors import IngestError
from suds_exp.ingest.c3d_reader import read_c3d
from suds_exp.ingest.capture import Capture
from suds_exp.ingest.csv_reader import read_marker_csv
from suds_exp.ingest.motive import is_motive_csv, read_motive_csv
from suds_exp.ingest.pose import PoseOptions, pose_software, read_pose
from suds_exp.ingest.qtm import read_qtm_tsv
from suds_exp.ingest.trc import read_trc
from suds_exp.ingest.vicon import is_vicon_csv, read_vicon_csv
from suds_exp.ingest.worm_tracker import read_wt2_features


def _text(data: bytes) -> str:
    """Text of a capture file: UTF-8 (with or without BOM), else Latin-1 (QTM on Windows)."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def _read_any_csv(path: Path, data: bytes) -> Capture:
    """A ``.csv`` is a Vicon Nexus or Motive export by its first line, else our layout."""
    text = _text(data)
    if is_vicon_csv(text):
        return read_vicon_csv(path, text)
    if is_motive_csv(text):
        return read_motive_csv(path, text)
    return read_marker_csv(path, text)


#: extension -> (format name, reader of the file's bytes)
READERS: dict[str, tuple[str, Callable[[Path, bytes], Capture]]] = {
    ".tsv": ("qtm-tsv", lambda p, b: read_qtm_tsv(p, _text(b))),
    ".c3d": ("c3d", read_c3d),
    ".csv": ("csv, vicon-csv or motive-csv", _read_any_csv),
    ".trc": ("trc", lambda p, b: read_trc(p, _text(b))),
    # keypoint files (suds_exp.ingest.pose); a keypoint .csv is told by its content
    ".h5": ("deeplabcut or sleap", read_pose),
    ".slp": ("sleap", read_pose),
    ".mat": ("wt2-features", read_wt2_features),
}


def capture_formats() -> list[str]:
    """The file extensions ingest understands."""
    return sorted(READERS)


def read_capture(path: Path, pose: PoseOptions | None = None) -> tuple[Capture, str]:
    """Read and validate one capture file; return it with the SHA-256 of its bytes.

    ``pose``: how to read keypoint files (`PoseOptions`; ignored for marker files)."""
    path = Path(path)
    if not path.exists():
        raise IngestError(f"{path}: no such file")
    if not path.is_file():
        raise IngestError(f"{path}: not a file")
    suffix = path.suffix.lower()
    if suffix not in READERS:
        raise IngestError(
            f"{path}: unknown format {suffix or '(no extension)'!r}; expected one of "
            + ", ".join(capture_formats())
        )
    data = path.read_bytes()
    if not data.strip():
        raise IngestError(f"{path}: the file is empty")
    if pose_software(path, data) is not None or (pose is not None and pose.software):
        capture = read_pose(path, data, pose).validate()
    else:
        capture = READERS[suffix][1](path, data).validate()
    return capture, hashlib.sha256(data).hexdigest()
