"""Shape of a marker chain (snake, fish): chord angles, eigen-shapes, body frame.

The markers, head to tail, are projected on the plane normal to the lab's ``up`` axis.
Successive markers give chords; the shape is the angles between successive chords
(n_markers - 2 angles, rad, positive = the body turning left going from tail to head),
reduced to a few shape modes by PCA, the "eigen-shape" description of undulators
(Stephens et al. 2008 for worms; used for snakes and fish alike). The body frame has its
origin at the markers' centroid and its +X along the mean chord direction, tail to head
(chord-length weighted circular mean), so it follows the body's average heading, not the
head's swing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_PLANE = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}


@dataclass(frozen=True)
class ChainGeometry:
    """Per-frame geometry of a chain.

    Attributes
    ----------
    angles : (n_frames, n_markers - 2), rad
        Angles between successive chords, head to tail.
    origin : (n_frames, 2), mm
        Centroid of the markers in the plane.
    heading : (n_frames,), rad, unwrapped
        Body +X in the plane (mean chord direction, pointing to the head).
    length : (n_frames,), mm
        Summed chord length, head to tail.
    """

    angles: np.ndarray
    origin: np.ndarray
    heading: np.ndarray
    length: np.ndarray


def chain_geometry(xyz: np.ndarray, up: str = "z") -> ChainGeometry:
    """Geometry of ``xyz`` (n_frames, n_markers, 3) mm, markers head to tail, gap-free."""
    a, b = _PLANE[up]
    xy = np.stack([xyz[:, :, a], xyz[:, :, b]], axis=2)
    # chords point from each marker towards the head
    chords = xy[:, :-1] - xy[:, 1:]
    lengths = np.hypot(chords[..., 0], chords[..., 1])
    direction = np.arctan2(chords[..., 1], chords[..., 0])
    turn = np.angle(np.exp(1j * (direction[:, :-1] - direction[:, 1:])))
    mean = (lengths * np.exp(1j * direction)).sum(axis=1)
    return ChainGeometry(
        angles=turn,
        origin=xy.mean(axis=1),
        heading=np.unwrap(np.angle(mean)),
        length=lengths.sum(axis=1),
    )
