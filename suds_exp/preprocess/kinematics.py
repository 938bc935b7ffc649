"""Steps 2-3 for one trial: cleaned marker tracks -> motion plane, segment frames, then
(given the segment origins) body pose, r_a and the passive state."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from suds_exp.ingest.layout import ROLES
from suds_exp.preprocess.body_frame import (
    Joints,
    Plane,
    SegmentFrames,
    body_pose,
    fit_plane,
    segment_frames,
)
from suds_exp.preprocess.shape import PASSIVE_ROLES, actuated_shape, passive_state

_ROLE = {role: i for i, role in enumerate(ROLES)}
TOP = ("head_top_1", "head_top_2", "tail_top_1", "tail_top_2")
#: Markers fixed on a segment; they define the motion plane.
RIGID = (*TOP, "head_spoke", "tail_spoke", "tail_back")


@dataclass(frozen=True)
class Measured:
    """A trial's markers in its motion plane: ``local`` (n_frames, 11, 2) mm in `ROLES`
    order, the `Plane` and the per-frame head/tail `SegmentFrames`."""

    plane: Plane
    local: np.ndarray
    frames: SegmentFrames


def measure(xyz: np.ndarray) -> Measured:
    """Plane and segment frames from cleaned tracks (n_frames, 11, 3) mm in `ROLES` order."""
    xyz = np.asarray(xyz, dtype=float)
    top = xyz[:, [_ROLE[r] for r in TOP]]
    plane = fit_plane(xyz[:, [_ROLE[r] for r in RIGID]], top)
    local = plane.project(xyz)[..., :2]
    frames = segment_frames(
        local[:, [_ROLE["head_top_1"], _ROLE["head_top_2"]]],
        local[:, [_ROLE["tail_top_1"], _ROLE["tail_top_2"]]],
    )
    return Measured(plane, local, frames)


@dataclass(frozen=True)
class Kinematics:
    """Body pose and shape of one trial.

    Attributes
    ----------
    xy : array of shape (n_frames, 2), mm
        Body origin in the motion plane.
    heading : array of shape (n_frames,), rad
        Body +X in the motion plane, unwrapped.
    ra : array of shape (n_frames, 2), rad
        Actuated shape (phi1, phi2).
    passive : array of shape (n_frames, 12), mm
        Passive state (order `suds_exp.preprocess.shape.PASSIVE_NAMES`).
    """

    xy: np.ndarray
    heading: np.ndarray
    ra: np.ndarray
    passive: np.ndarray


def kinematics(measured: Measured, joints: Joints) -> Kinematics:
    """Body pose, r_a and passive state of a measured trial given its segment origins."""
    pose = body_pose(measured.frames, joints)
    ra = actuated_shape(measured.frames, pose)
    points = {r: measured.local[:, _ROLE[r]] for r, _ in PASSIVE_ROLES}
    passive = passive_state(measured.frames, pose, points)
    return Kinematics(pose.xy, pose.heading, ra, passive)
