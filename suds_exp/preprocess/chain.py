"""Step 2b, body pose from the whole kinematic chain (``body_fit="chain"``).

`body_frame.body_pose` builds the body frame from each outer segment's own frame. The
head carries only two rigid markers, so its frame, and with it the head motor axis and the
body heading, is the noisiest part of that pose; and the body's lateral velocity contains
half the middle segment's length times the heading rate. Two facts about the robot give
more to work with:

- the segments' angles relative to the body (the motor angles, up to a constant) are
  driven by the motors and change smoothly, while the body velocity jumps whenever a
  flipper reaches or leaves a stop; so the relative angles can be smoothed over a fraction
  of a gait cycle without blurring the body's motion;
- given those angles, all five rigid markers (two on the head, three on the tail) and the
  tail flippers' markers (each on a circle about its hinge) are fixed in the body frame,
  so each frame's body pose (3 numbers) is one least-squares fit to all of them.

`chain_pose` alternates: relative angles per frame (a rotation of each segment's markers
about its motor axis, given the body pose), smoothed by a local polynomial of
``polyorder`` over ``window`` frames; then the body pose per frame, given the smoothed
angles (closed-form 2D Procrustes of the rigid markers, refined by Gauss-Newton with the
flipper circles). The pose itself is not smoothed: the differentiator in `rates` is the
only smoothing the body velocity sees. On the simulator's default dataset this brings the
body pose error from 0.14 to 0.10 mm RMS and the heading error from 0.0030 to 0.0016 rad.
"""

from __future__ import annotations

import numpy as np

from suds_exp.preprocess.body_frame import (
    Joints,
    SegmentFrames,
    best_rotation,
    body_pose,
    hinge_circles,
    procrustes,
    refine_with_circles,
    rotate,
    to_frame,
)
from suds_exp.preprocess.rates import local_polynomial, window_frames
from suds_exp.robot import ROLES

_ROLE = {role: i for i, role in enumerate(ROLES)}
#: Rigid markers of each outer segment (also of `kinematics`' rigid tail fit,
#: ``tail_fit="rigid"``; the head has only its two top markers: its spoke rings on its
#: skewer).
HEAD_RIGID = ("head_top_1", "head_top_2")
TAIL_RIGID = ("tail_top_1", "tail_top_2", "tail_back")
#: Markers on the tail's flippers (``tail_fit="rigid+flippers"``): each moves on a circle
#: about its hinge, fixed in the tail frame. The head's flippers open by at most ~0.45 rad
#: on the simulator, too little arc for a well-determined circle.
TAIL_HINGED = ("flipper_3", "flipper_4")


def chain_pose(
    local: np.ndarray,
    frames: SegmentFrames,
    joints: Joints,
    window: int,
    polyorder: int,
    rounds: int = 2,
    newton_steps: int = 2,
) -> tuple[np.ndarray, np.ndarray]:
    """Body pose of one trial from all rigid markers and the tail flipper circles.

    Parameters
    ----------
    local : array of shape (n_frames, 11, 2), mm
        Markers in the motion plane, `ROLES` order.
    frames : SegmentFrames
        The segment frames: the starting point, and the frames in which the markers'
        fixed positions are learned (their means over the trial).
    joints : Joints
        Segment origins (motor axes) in those frames and their distance.
    window, polyorder : int
        Local-polynomial smoothing of the segments' angles relative to the body (odd
        number of frames; ``window <= polyorder`` leaves them unsmoothed).
    rounds : int
        Alternations of (relative angles | pose) and (pose | relative angles).
    newton_steps : int
        Gauss-Newton steps of the pose fit with the flipper circles, per round.

    Returns
    -------
    xy : array of shape (n_frames, 2), mm
        Body origin (midpoint of the motor axes) in the plane.
    heading : array of shape (n_frames,), rad
        Body +X (tail motor axis -> head motor axis), unwrapped.
    """
    pose = body_pose(frames, joints)
    xy, heading = pose.xy, pose.heading
    hinge, marks, template, circles = _segment_markers(local, frames, joints)
    relative = {
        "head": np.unwrap(frames.head_angle - heading),
        "tail": np.unwrap(frames.tail_angle - heading),
    }
    plane = np.concatenate([marks["head"], marks["tail"]], axis=1)
    for round_ in range(rounds):
        if round_:
            for seg in ("head", "tail"):
                measured = to_frame(marks[seg], xy, heading) - hinge[seg]
                relative[seg] = best_rotation(template[seg], measured, relative[seg])
        smooth = {
            seg: local_polynomial(a, window, polyorder) if window > polyorder else a
            for seg, a in relative.items()
        }
        xy, heading = _pose_given_angles(
            smooth, hinge, template, circles, plane, heading, newton_steps
        )
    return xy, heading


def _segment_markers(local: np.ndarray, frames: SegmentFrames, joints: Joints):
    """What the pose is fitted to, per segment ("head", "tail").

    Returns ``hinge`` (each motor axis in the body frame, (2,) mm), ``marks`` (its rigid
    markers in the plane, (n_frames, m, 2) mm), ``template`` (each rigid marker relative
    to its motor axis in its segment's frame, (m, 2) mm) and ``circles`` (per hinged tail
    flipper marker: its track (n_frames, 2), circle centre relative to the tail axis (2,)
    and radius, mm).
    """
    half = joints.length_mm / 2
    hinge = {"head": np.array([half, 0.0]), "tail": np.array([-half, 0.0])}
    marks = {
        "head": local[:, [_ROLE[r] for r in HEAD_RIGID]],
        "tail": local[:, [_ROLE[r] for r in TAIL_RIGID]],
    }
    # each rigid marker relative to its motor axis, in its segment's frame
    template = {
        "head": to_frame(marks["head"], frames.head_origin, frames.head_angle).mean(axis=0)
        - joints.head,
        "tail": to_frame(marks["tail"], frames.tail_origin, frames.tail_angle).mean(axis=0)
        - joints.tail,
    }
    hinged = local[:, [_ROLE[r] for r in TAIL_HINGED]]
    circles = [
        (hinged[:, k], centre - joints.tail, radius)
        for k, centre, radius in hinge_circles(hinged, frames.tail_origin, frames.tail_angle)
    ]
    return hinge, marks, template, circles


def _pose_given_angles(smooth, hinge, template, circles, plane, heading, newton_steps):
    """(xy (n, 2) mm, heading (n,) rad) of the body that best places the rigid markers
    (and the flipper circles) at the segments' relative angles ``smooth`` (rad)."""
    # the rigid markers and the circle centres in the body frame, per frame
    body = np.concatenate(
        [hinge[seg] + rotate(smooth[seg], template[seg][None]) for seg in ("head", "tail")],
        axis=1,
    )
    xy, heading = procrustes(body, plane, heading)
    if circles:
        in_body = [
            (marker, hinge["tail"] + rotate(smooth["tail"], centre[None, None])[:, 0], r)
            for marker, centre, r in circles
        ]
        xy, heading = refine_with_circles(xy, heading, body, plane, in_body, newton_steps)
    return xy, heading


def chain_settings(
    params: dict, rate_hz: float, frequency_hz: float | None, n_frames: int
) -> tuple[int, int] | None:
    """(window frames, polynomial order) of a version's `chain_pose` for one trial, or None
    when the version takes the body pose from the segment frames (``body_fit=segments``,
    and versions made before ``body_fit`` existed)."""
    if params.get("body_fit", "segments") != "chain":
        return None
    order = int(params["chain_polyorder"])
    if params["chain_window_cycles"] > 0 and frequency_hz:
        seconds = params["chain_window_cycles"] / frequency_hz
    else:
        seconds = params["chain_window_s"]
    return window_frames(seconds, rate_hz, order, n_frames), order
