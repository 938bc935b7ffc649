"""`Capture`: what every reader returns, and the checks every capture must pass."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.errors import IngestError


@dataclass
class Capture:
    """One motion-capture recording, in the same form whatever file it came from.

    Attributes
    ----------
    path : Path
        The file it was read from.
    format : str
        ``"qtm-tsv"``, ``"c3d"``, ``"csv"``, ``"vicon-csv"``, ``"motive-csv"``, ``"trc"``,
        or a keypoint tracker's name (``"deeplabcut"``, ``"sleap"``, ...).
    sample_rate_hz : float
        Capture rate, Hz.
    marker_names : list of str
        The capture's own marker names, in file order.
    frame : array of shape (n_frames,), int
        Frame numbers as in the file.
    t : array of shape (n_frames,), s
        Sample times.
    xyz : array of shape (n_frames, n_markers, 3), mm
        Marker positions; NaN where the marker was not seen.
    """

    path: Path
    format: str
    sample_rate_hz: float
    marker_names: list[str]
    frame: np.ndarray
    t: np.ndarray
    xyz: np.ndarray
    meta: dict = field(default_factory=dict)
    #: 1-based file line of the first frame, for error messages (None: not a text file)
    first_line: int | None = None

    @property
    def n_frames(self) -> int:
        return len(self.frame)

    def validate(self) -> Capture:
        """Raise `IngestError` unless the capture is complete and ordered in time."""
        name = self.path
        if self.n_frames == 0:
            raise IngestError(f"{name}: the file holds no frames")
        if len(set(self.marker_names)) != len(self.marker_names):
            dup = pd.Series(self.marker_names)
            raise IngestError(
                f"{name}: marker name {dup[dup.duplicated()].iloc[0]!r} appears twice"
            )
        for label, values in (("frame", self.frame), ("time", self.t)):
            if not np.all(np.isfinite(values)):
                raise IngestError(f"{name}: {label} column has a missing value")
            steps = np.diff(values)
            bad = np.flatnonzero(steps <= 0)
            if bad.size:
                i = int(bad[0]) + 1
                where = f"line {self.first_line + i}" if self.first_line else f"frame index {i}"
                raise IngestError(
                    f"{name}: {where}: {label} values must increase strictly; "
                    f"{values[i]:g} does not follow {values[i - 1]:g}"
                )
        if not np.isfinite(self.sample_rate_hz) or self.sample_rate_hz <= 0:
            raise IngestError(f"{name}: sample rate must be a positive number of Hz")
        if self.xyz.shape != (self.n_frames, len(self.marker_names), 3):
            raise IngestError(
                f"{name}: expected {len(self.marker_names)} markers x 3 coordinates per frame"
            )
        return self

    def long_frame(self, trial_id: int) -> pd.DataFrame:
        """The capture as rows of the ``markers`` table (trial, frame, t, marker, x, y, z);
        a 2-D capture (``meta["dims"] == 2``, keypoints) has z NULL and is missing where x
        or y is."""
        n_f, n_m = self.n_frames, len(self.marker_names)
        xyz = self.xyz.reshape(n_f * n_m, 3)
        dims = int(self.meta.get("dims", 3))
        missing = ~np.all(np.isfinite(xyz[:, :dims]), axis=1)
        xyz = np.where(missing[:, None], np.nan, xyz)
        return pd.DataFrame(
            {
                "trial_id": np.full(n_f * n_m, trial_id, dtype=np.int32),
                "frame": np.repeat(self.frame.astype(np.int32), n_m),
                "t": np.repeat(self.t.astype(float), n_m),
                "marker": np.tile(np.asarray(self.marker_names, dtype=object), n_f),
                "x": xyz[:, 0],
                "y": xyz[:, 1],
                "z": xyz[:, 2],
                "missing": missing,
            }
        )
