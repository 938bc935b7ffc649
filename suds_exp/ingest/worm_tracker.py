"""Reader for Worm Tracker 2 features files (`.mat`; Schafer lab, Open Worm Movement
Database; Yemini et al. 2013).

The skeleton (``worm.posture.skeleton.x``, ``.y``: 49 points x frames, head first, in
microns in lab coordinates) becomes 49 markers ``p01`` (head) .. ``p49`` (tail), 2-D (no
Z), in mm. Only frames annotated 1 (segmented) carry data: a stage movement (2), a
segmentation failure (102) or a dropped frame (0) is a gap, never data, whatever the
file holds there. Frames before the first and after the last skeleton are left out (a
recording that ends in failures ends at its last skeleton). The frame rate is
``info.video.resolution.fps``.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture

#: Annotation code of a segmented frame (the only frames with data), and the names of the
#: others for the capture's notes.
SEGMENTED = 1
ANNOTATIONS = {0: "dropped", 2: "stage movement", 102: "segmentation failure"}
N_POINTS = 49


def skeleton_names(n: int = N_POINTS) -> list[str]:
    """Marker names of the skeleton's points, head to tail: p01 .. p49."""
    return [f"p{i:02d}" for i in range(1, n + 1)]


def _field(path: Path, obj, dotted: str):
    for part in dotted.split("."):
        if not hasattr(obj, part):
            raise IngestError(
                f"{path}: not a Worm Tracker 2 features file (no {dotted}); expected the "
                "struct worm with posture.skeleton.x/y and info.video"
            )
        obj = getattr(obj, part)
    return obj


def read_wt2_features(path: Path, data: bytes) -> Capture:
    """Parse a WT2 features file into a `Capture` (mm, 2-D, gaps where not segmented)."""
    from scipy.io import loadmat

    try:
        mat = loadmat(io.BytesIO(data), squeeze_me=True, struct_as_record=False)
    except (ValueError, TypeError, OSError, NotImplementedError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise IngestError(f"{path}: not a readable MATLAB file ({reason})") from None
    if "worm" not in mat or "info" not in mat:
        raise IngestError(
            f"{path}: not a Worm Tracker 2 features file (no 'worm' and 'info' structs)"
        )
    x = np.asarray(_field(path, mat["worm"], "posture.skeleton.x"), dtype=float)
    y = np.asarray(_field(path, mat["worm"], "posture.skeleton.y"), dtype=float)
    fps = float(_field(path, mat["info"], "video.resolution.fps"))
    codes = np.atleast_1d(np.asarray(_field(path, mat["info"], "video.annotations.frames")))
    if x.ndim != 2 or x.shape != y.shape or x.shape[1] != codes.size:
        raise IngestError(
            f"{path}: worm.posture.skeleton.x/y: expected two (points, frames) arrays of "
            f"{codes.size} frames (info.video.annotations.frames), got {x.shape}, {y.shape}"
        )
    segmented = codes == SEGMENTED
    xyz = np.full((codes.size, x.shape[0], 3), np.nan)
    xyz[..., 0], xyz[..., 1] = x.T / 1000.0, y.T / 1000.0  # microns -> mm
    xyz[~segmented] = np.nan
    seen = np.flatnonzero(np.isfinite(xyz[..., :2]).all(axis=2).any(axis=1))
    if seen.size == 0:
        raise IngestError(f"{path}: no frame has a skeleton")
    first, last = int(seen[0]), int(seen[-1])
    notes = [
        f"{int(np.sum(codes == c))} {name} frames are gaps"
        for c, name in ANNOTATIONS.items()
        if np.any(codes == c)
    ]
    if first > 0 or last < codes.size - 1:
        notes.append(
            f"frames 0-{first - 1} and {last + 1}-{codes.size - 1} hold no skeleton: left out"
            if first > 0 and last < codes.size - 1
            else f"frames {last + 1}-{codes.size - 1} hold no skeleton: left out"
            if first == 0
            else f"frames 0-{first - 1} hold no skeleton: left out"
        )
    frame = np.arange(first, last + 1)
    return Capture(
        path,
        "wt2-features",
        fps,
        skeleton_names(x.shape[0]),
        frame,
        frame / fps,
        xyz[first : last + 1],
        {"notes": notes, "dims": 2},
    )
