"""Markerless keypoint files (DeepLabCut, SLEAP, Lightning Pose, Anipose) through
`movement` (neuroinformatics-unit), the ecosystem's one loader for all of them.

A keypoint becomes a marker of the capture (``individual/keypoint`` when the file tracks
more than one individual). A point whose confidence is below the threshold is missing,
as is a point the tracker did not place. 2-D tracks (pixels) are scaled to mm by
``mm_per_px`` and stored with no Z (NULL; preprocessing reads them in the plane z = 0);
3-D tracks (Anipose, in its calibration's unit) are scaled by ``mm_per_px`` if given.
The frame rate comes from the file when it holds one, else from ``fps``.

`movement` is an optional dependency (``pip install suds-exp[pose]``); it is imported
only when a keypoint file is read.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from suds_exp.errors import IngestError
from suds_exp.ingest.capture import Capture

#: Confidence below which a keypoint is missing when none is given: DeepLabCut's default
#: ``pcutoff`` and `movement`'s ``filter_by_confidence`` default.
DEFAULT_CONFIDENCE = 0.6

#: Our name of each tracker -> `movement`'s ``source_software``.
SOFTWARE = {
    "deeplabcut": "DeepLabCut",
    "sleap": "SLEAP",
    "lightning-pose": "LightningPose",
    "anipose": "Anipose",
}


@dataclass(frozen=True)
class PoseOptions:
    """How to read keypoint files.

    Parameters
    ----------
    software : str, optional
        One of `SOFTWARE` (``deeplabcut``, ``sleap``, ``lightning-pose``, ``anipose``);
        None: told by the file (a DeepLabCut-style CSV or H5, a SLEAP analysis H5 or
        ``.slp``, an Anipose CSV).
    fps : float, optional
        Frames per second, when the file does not hold it (DeepLabCut, SLEAP analysis
        files and Lightning Pose do not).
    mm_per_px : float, optional
        Scale of 2-D keypoints, mm per pixel (required for them); of 3-D keypoints, mm
        per calibration unit (default 1: Anipose calibrated in mm).
    confidence_threshold : float, optional
        A point with a lower confidence is missing. None: `DEFAULT_CONFIDENCE` when the
        file has confidences, none when it has not; a value given for a file without
        confidences is refused.
    """

    software: str | None = None
    fps: float | None = None
    mm_per_px: float | None = None
    confidence_threshold: float | None = None

    def check(self) -> PoseOptions:
        """Raise `IngestError` naming the parameter for an impossible value."""
        if self.software is not None and self.software not in SOFTWARE:
            raise IngestError(
                f"software {self.software!r}: expected one of {', '.join(SOFTWARE)}",
                param="software",
            )
        for name in ("fps", "mm_per_px"):
            value = getattr(self, name)
            if value is not None and not (np.isfinite(value) and value > 0):
                raise IngestError(f"{name}={value}: must be a positive number", param=name)
        c = self.confidence_threshold
        if c is not None and not 0 <= c <= 1:
            raise IngestError(
                f"confidence_threshold={c}: must be between 0 and 1", param="confidence_threshold"
            )
        return self


def pose_software(path: Path, data: bytes) -> str | None:
    """The tracker that wrote a keypoint file, told by its content (None: not one)."""
    suffix = path.suffix.lower()
    if suffix == ".slp":
        return "sleap"
    if suffix == ".h5":
        if not data.startswith(b"\x89HDF"):
            return None
        try:
            import h5py
        except ImportError:
            raise IngestError(
                f"{path}: reading HDF5 keypoint files needs the optional packages of "
                "suds-exp's 'pose' extra (pip install 'suds-exp[pose]')",
                param="paths",
            ) from None
        with h5py.File(path, "r") as f:
            if "tracks" in f and "node_names" in f:
                return "sleap"
            return "deeplabcut"
    if suffix == ".csv":
        head = data[:4000].decode("utf-8", errors="replace").lstrip("\ufeff")
        first = head.splitlines()[0] if head else ""
        if first.split(",")[0].strip() == "scorer":
            return "deeplabcut"
        cols = {c.strip() for c in first.split(",")}
        if any(c.endswith("_score") for c in cols) and any(c.endswith("_error") for c in cols):
            return "anipose"
    return None


@contextmanager
def _quiet_movement():
    """`movement` logs its warnings and errors to stderr; ours are one line, so mute it."""
    try:
        from loguru import logger
    except ImportError:  # pragma: no cover - movement depends on loguru
        yield
        return
    logger.disable("movement")
    try:
        yield
    finally:
        logger.enable("movement")


def _load(path: Path, software: str, fps: float | None):
    try:
        from movement.io import load_dataset
    except ImportError:
        raise IngestError(
            f"{path}: reading {SOFTWARE[software]} files needs the optional package "
            "'movement' (pip install 'suds-exp[pose]')"
        ) from None
    with _quiet_movement():
        try:
            return load_dataset(path, SOFTWARE[software], fps=fps)
        except (ValueError, KeyError, OSError, TypeError, AttributeError) as exc:
            reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise IngestError(
                f"{path}: not a readable {SOFTWARE[software]} file ({reason})"
            ) from None


def read_pose(path: Path, data: bytes, options: PoseOptions | None = None) -> Capture:
    """Read a keypoint file into a `Capture` (mm; 2-D tracks with Z missing).

    ``data``: the file's bytes (to tell the tracker). Raises `IngestError` naming the
    file: no frame rate (give ``fps``), 2-D keypoints without ``mm_per_px``, a
    ``confidence_threshold`` for a file without confidences, a file `movement` cannot read.
    """
    options = (options or PoseOptions()).check()
    software = options.software or pose_software(path, data)
    if software is None:
        raise IngestError(
            f"{path}: not a keypoint file of {', '.join(SOFTWARE)}; name the software"
        )
    ds = _load(path, software, options.fps)
    fps = ds.attrs.get("fps") or options.fps
    if not fps:
        raise IngestError(
            f"{path}: the file holds no frame rate; give fps (frames per second)", param="fps"
        )
    position = ds["position"].transpose("time", "individuals", "keypoints", "space").values
    n_frames, n_ind, n_kp, n_space = position.shape
    if n_space == 2 and options.mm_per_px is None:
        raise IngestError(
            f"{path}: 2-D keypoints are in pixels; give mm_per_px (the pixel size in mm)",
            param="mm_per_px",
        )
    scale = options.mm_per_px if options.mm_per_px is not None else 1.0
    xyz = np.full((n_frames, n_ind * n_kp, 3), np.nan)
    xyz[..., :n_space] = position.reshape(n_frames, n_ind * n_kp, n_space) * scale
    notes = []
    low = np.zeros((n_frames, n_ind * n_kp), dtype=bool)
    if "confidence" in ds:
        confidence = ds["confidence"].transpose("time", "individuals", "keypoints").values
        confidence = confidence.reshape(n_frames, n_ind * n_kp)
    else:
        confidence = np.full((n_frames, n_ind * n_kp), np.nan)
    has_confidence = bool(np.isfinite(confidence).any())
    threshold = options.confidence_threshold
    if threshold is not None and not has_confidence:
        raise IngestError(
            f"{path}: the file has no confidence values, so confidence_threshold="
            f"{threshold:g} cannot be applied; leave it unset",
            param="confidence_threshold",
        )
    if threshold is None and has_confidence:
        threshold = DEFAULT_CONFIDENCE
    if threshold is not None:
        placed = np.isfinite(xyz[..., :n_space]).all(axis=2)
        low = placed & (confidence < threshold)
        xyz[low] = np.nan
        notes.append(f"{int(low.sum())} points below confidence {threshold:g} set missing")
    if n_space == 2:
        notes.append(f"2-D keypoints at {scale:g} mm/px, no Z")
    individuals = [str(i) for i in ds["individuals"].values]
    keypoints = [str(k) for k in ds["keypoints"].values]
    names = keypoints if n_ind == 1 else [f"{ind}/{kp}" for ind in individuals for kp in keypoints]
    time = ds["time"].values
    frame = np.round(time * fps).astype(int) if ds.attrs.get("fps") else time.astype(int)
    meta = {"notes": notes, "dims": int(n_space), "software": software}
    return Capture(path, software, float(fps), names, frame, frame / float(fps), xyz, meta)
