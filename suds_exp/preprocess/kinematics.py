"""Steps 2-3 for one trial: cleaned marker tracks -> motion plane, segment frames, then
(given the segment origins) body pose, r_a and the passive state."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from suds_exp.preprocess.body_frame import (
    Joints,
    Plane,
    SegmentFrames,
    body_pose,
    fit_plane,
    hinged_fit,
    rigid_fit,
    segment_frames,
)
from suds_exp.preprocess.chain import TAIL_HINGED, TAIL_RIGID, chain_pose
from suds_exp.preprocess.params import TAIL_FITS
from suds_exp.preprocess.shape import ACTUATED_SHAPES, PASSIVE_ROLES, passive_state
from suds_exp.robot import ROLES, SPOKE_ROLES

_ROLE = {role: i for i, role in enumerate(ROLES)}
TOP = ("head_top_1", "head_top_2", "tail_top_1", "tail_top_2")
#: Markers fixed on a segment; they define the motion plane.
RIGID = (*TOP, *SPOKE_ROLES, "tail_back")


@dataclass(frozen=True)
class Measured:
    """A trial's markers in its motion plane: ``local`` (n_frames, 11, 2) mm in `ROLES`
    order, the `Plane` and the per-frame head/tail `SegmentFrames`."""

    plane: Plane
    local: np.ndarray
    frames: SegmentFrames


def measure(xyz: np.ndarray, tail_fit: str = "rigid+flippers") -> Measured:
    """Plane and segment frames from cleaned tracks (n_frames, 11, 3) mm in `ROLES` order.

    ``tail_fit``: ``"top"`` takes the tail frame from its two top markers, like the head;
    ``"rigid"`` refines it by a per-frame rigid fit of `TAIL_RIGID` (`rigid_fit`);
    ``"rigid+flippers"`` then also uses that each of `TAIL_HINGED` stays on its circle
    about its hinge (`hinged_fit`).
    """
    xyz = np.asarray(xyz, dtype=float)
    top = xyz[:, [_ROLE[r] for r in TOP]]
    plane = fit_plane(xyz[:, [_ROLE[r] for r in RIGID]], top)
    local = plane.project(xyz)[..., :2]
    frames = segment_frames(
        local[:, [_ROLE["head_top_1"], _ROLE["head_top_2"]]],
        local[:, [_ROLE["tail_top_1"], _ROLE["tail_top_2"]]],
    )
    if tail_fit not in TAIL_FITS:
        raise ValueError(f"tail_fit={tail_fit!r}: expected one of {', '.join(TAIL_FITS)}")
    if tail_fit != "top":
        rigid = local[:, [_ROLE[r] for r in TAIL_RIGID]]
        origin, angle = rigid_fit(rigid, frames.tail_origin, frames.tail_angle)
        if tail_fit == "rigid+flippers":
            hinged = local[:, [_ROLE[r] for r in TAIL_HINGED]]
            origin, angle = hinged_fit(rigid, hinged, origin, angle)
        frames = SegmentFrames(frames.head_origin, frames.head_angle, origin, angle)
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
    ra : array of shape (n_frames, m)
        Actuated shape: (phi1, phi2), rad, or with ``ra_repr="cartesian"`` the four
        Cartesian values of `suds_exp.preprocess.shape.cartesian_shape`, mm.
    passive : array of shape (n_frames, 12), mm
        Passive state (order `suds_exp.preprocess.shape.PASSIVE_NAMES`).
    """

    xy: np.ndarray
    heading: np.ndarray
    ra: np.ndarray
    passive: np.ndarray


def kinematics(
    measured: Measured,
    joints: Joints,
    chain: tuple[int, int] | None = None,
    ra_repr: str = "angles",
) -> Kinematics:
    """Body pose, r_a and passive state of a measured trial given its segment origins.

    ``chain``: (window frames, polynomial order) of the relative-angle smoothing of
    `chain_pose`, which then gives the body pose (``xy``, ``heading``); None keeps the pose
    of the segment frames (`body_pose`). r_a and the passive state come from the segment
    frames either way; ``ra_repr`` ("angles" | "cartesian") picks its representation.
    """
    pose = body_pose(measured.frames, joints)
    ra = ACTUATED_SHAPES[ra_repr](measured.frames, pose)
    points = {r: measured.local[:, _ROLE[r]] for r, _ in PASSIVE_ROLES}
    passive = passive_state(measured.frames, pose, points)
    xy, heading = pose.xy, pose.heading
    if chain is not None:
        xy, heading = chain_pose(measured.local, measured.frames, joints, *chain)
    return Kinematics(xy, heading, ra, passive)
