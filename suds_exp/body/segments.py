"""`SegmentModel`: the preprocessing of any body of rigid segments (the `preprocess` hook).

Per trial, from the cleaned markers:

- the motion plane: the least-squares plane of every segment marker (as the swimmer's);
- each segment with markers gets a 2D frame: origin at the midpoint of its first two
  ``frame`` markers, angle the heading from the first to the second, refined by a
  per-frame least-squares rigid fit of all its frame markers when it has more than two.
  A segment's pose comes from the markers the capture saw in that frame whenever at
  least two of its frame markers were seen (their positions in its frame are learned
  from the frames that saw them all); only where fewer were seen does it come from the
  cleaning step's interpolated tracks (counted per segment, ``interpolated_frames``);
- each joint's centre is a point fixed in the frames of both segments it joins (linear
  least squares over every frame of the version's trials); a segment without markers
  (``from_joints``) is the link between its two joints, whose centres are the points of
  its neighbours' frames that keep a constant distance (as the swimmer's motor axes);
- a joint's angle is its **bend**, defined by the joint alone: each of the two segments
  it joins points along the line from its *far point* to the joint (the parent) or from
  the joint to its far point (the child), where a segment's far point is its other
  joint's centre when it has exactly two joints, else its frame origin. The angle is the
  heading of the child's line minus the parent's (rad): zero when the two are in line,
  positive when the child turns counter-clockwise seen from above (the right-hand rule
  about the motion plane's upward normal). It does not depend on which segment is the
  root, which is the body frame, or the order of the joints in the file; swapping a
  joint's parent and child flips its sign;
- each segment's axis (the X of the frame its passive state is measured in, and the
  body frame's): from its parent joint to its child joint when it has exactly one, else
  to its frame origin; a segment that is no joint's child runs from its frame origin to
  its one child joint, or, with several, along its frame's +X (first frame marker to
  the second);
- the body frame is the ``body_frame`` segment's: origin at the midpoint of its joints
  (a ``from_joints`` segment) or at its frame origin, +X along its axis;
- r_a: the actuated joints' angles (rad, in the order the description lists them: the
  one thing that order sets); the passive state (mm, the
  paper's Cartesian choice): each segment's non-frame markers and each passive marker in
  its segment's frame (origin at the segment's joint towards the body frame, X along its
  axis), then, for each passive joint in the order of their names, the far segment's
  origin in the near segment's frame. The pipeline then reduces the passive state by
  PCA, takes the phase from r_a, differentiates and writes samples as for the swimmer.

Written as such a description (`suds_exp/body/swimmer.toml`), the swimmer gives the same
numbers as the built-in pipeline with the segment-frame settings (``tail_fit=rigid``,
``body_fit=segments``) on trials that lose no tail frame marker; the built-in default's
chain fit and flipper circles use facts of that one robot and are not generic.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from suds_exp.body.description import Body, BodyError
from suds_exp.errors import PreprocessError
from suds_exp.ingest.layout import trial_layout
from suds_exp.preprocess.body_frame import (
    Plane,
    SegmentFrames,
    fit_joints,
    fit_plane,
    noise_shift,
    procrustes,
    rotate,
    to_frame,
)
from suds_exp.preprocess.body_model import JOINT_SHIFT_WARN_MM, BodyModel
from suds_exp.preprocess.kinematics import Kinematics
from suds_exp.preprocess.params import params_seed
from suds_exp.robot import MAX_K

#: Most actuated joints a version's samples hold (columns ra_1 .. ra_8, migration 018).
MAX_ACTUATED = 8
#: The parameters whose other values only the built-in swimmer honours.
SWIMMER_ONLY = {"body_fit": "segments", "tail_fit": "rigid", "ra_repr": "angles"}


@dataclass(frozen=True)
class SegMeasured:
    """A trial's markers in its motion plane: ``local`` (n_frames, n_markers, 2) mm (the
    model's label order), the `Plane`, each marker segment's frame: name -> (origin
    (n_frames, 2) mm, angle (n_frames,) rad), and how many frames of each marker segment
    took their pose from interpolated tracks (too few of its frame markers seen)."""

    plane: Plane
    local: np.ndarray
    frames: dict[str, tuple[np.ndarray, np.ndarray]]
    interpolated_frames: dict[str, int] = field(default_factory=dict)


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


def _heading(v: np.ndarray) -> np.ndarray:
    return np.arctan2(v[:, 1], v[:, 0])


class SegmentModel(BodyModel):
    """The `preprocess` hook of a segment `Body` (see the module docstring).

    Parameters
    ----------
    body : Body
        A parsed description of kind ``segments``.

    Raises `BodyError` naming the description's file for a body it cannot preprocess: no
    actuated joint or more than `MAX_ACTUATED`, no passive state, a ``from_joints``
    segment that is not the child of one joint and the parent of one other between
    segments with markers.
    """

    def __init__(self, body: Body):
        if body.chain is not None:
            raise BodyError(f"{body.source}: a [chain] body is not a segment body")
        self.body = body
        self.segments = {s.name: s for s in body.segments}
        self.actuated = [j for j in body.joints if j.kind == "actuated"]
        # by name, so the passive state does not depend on the order joints are listed
        self.passive_joints = sorted(
            (j for j in body.joints if j.kind == "passive"), key=lambda j: j.name
        )
        src = body.source
        if not 1 <= len(self.actuated) <= MAX_ACTUATED:
            raise BodyError(
                f"{src}: joints: {len(self.actuated)} actuated joint(s); a segment body needs "
                f"1 to {MAX_ACTUATED} (their angles are r_a, the phase comes from them)"
            )
        self.parent_joint = {j.child: j for j in body.joints}
        self.child_joints = {
            s.name: [j for j in body.joints if j.parent == s.name] for s in body.segments
        }
        self.joints_of = {
            s.name: [j for j in body.joints if s.name in (j.parent, j.child)] for s in body.segments
        }
        for seg in body.segments:
            if not seg.from_joints:
                continue
            kids = self.child_joints[seg.name]
            parent = self.parent_joint.get(seg.name)
            ends = [parent.parent if parent else None, kids[0].child if len(kids) == 1 else None]
            if parent is None or len(kids) != 1 or any(self.segments[e].from_joints for e in ends):
                raise BodyError(
                    f"{src}: segments.{seg.name}: from_joints = true needs it to be the child "
                    "of one joint and the parent of one other, both to segments with markers"
                )
        self.labels = tuple(body.markers)
        self._col = {m: i for i, m in enumerate(self.labels)}
        marked = [s for s in body.segments if not s.from_joints]
        self.leading = [m for s in marked for m in s.frame_markers[:2]]
        self.plane_markers = self.leading + [
            m for s in marked for m in s.markers if m not in s.frame_markers[:2]
        ]
        #: (marker, segment) measured in their segment's frame as passive state
        self.hanging = [
            (m, s.name) for s in marked for m in s.markers if m not in s.frame_markers
        ] + list(body.passive_markers.items())
        self.n_passive = 2 * (len(self.hanging) + len(self.passive_joints))
        if self.n_passive == 0:
            raise BodyError(
                f"{src}: no passive state (no passive marker, non-frame marker or passive "
                "joint); r_p needs at least one"
            )
        self.towards_body = self._towards_body()

    # -- the tree ------------------------------------------------------------------------
    def _towards_body(self) -> dict[str, tuple[str, str]]:
        """segment -> (joint name, neighbour) on its path to the body frame segment."""
        out: dict[str, tuple[str, str]] = {}
        todo = [self.body.body_frame]
        while todo:
            here = todo.pop()
            for j in self.body.joints:
                for near, far in ((j.parent, j.child), (j.child, j.parent)):
                    if near == here and far not in out and far != self.body.body_frame:
                        out[far] = (j.name, near)
                        todo.append(far)
        return out

    # -- the hook ------------------------------------------------------------------------
    def version_params(self, params: dict[str, Any]) -> dict[str, Any]:
        src = self.body.source
        for key, value in SWIMMER_ONLY.items():
            if params[key] != value:
                raise BodyError(
                    f"{src}: params {key}={params[key]!r} is the built-in swimmer's; a "
                    f"segment body takes {key}={value}"
                )
        if params["reduction"] != "pca":
            raise BodyError(
                f"{src}: params reduction={params['reduction']!r}: a segment body's passive "
                "state is reduced by PCA (reduction=pca)"
            )
        if params["k"] > min(self.n_passive, MAX_K):
            raise BodyError(
                f"{src}: params k={params['k']}: the body's passive state has "
                f"{self.n_passive} numbers; choose k <= {min(self.n_passive, MAX_K)}"
            )
        return {**params, "body": self.body.to_dict()}

    def marker_names(self, layout: str | None) -> list[str]:
        names = trial_layout(layout)
        return [names.get(m, m) for m in self.labels]

    def missing(self, trial_id: int, lacking: Sequence[str]) -> str:
        return f"{self.body.source}: marker(s) {', '.join(lacking)} unknown to trial {trial_id}"

    def measure(
        self, xyz: np.ndarray, params: dict[str, Any], filled: np.ndarray | None = None
    ) -> SegMeasured:
        """The trial's plane and segment frames from cleaned tracks ``xyz`` (n_frames,
        n_markers, 3) mm; ``filled`` (n_frames, n_markers) bool marks the points the
        cleaning step interpolated (none when omitted)."""
        xyz = np.asarray(xyz, dtype=float)
        cols = self._col
        plane = fit_plane(
            xyz[:, [cols[m] for m in self.plane_markers]], xyz[:, [cols[m] for m in self.leading]]
        )
        local = plane.project(xyz)[..., :2]
        frames, interpolated = {}, {}
        for seg in self.body.segments:
            if seg.from_joints:
                continue
            index = [cols[m] for m in seg.frame_markers]
            seen = np.ones((len(xyz), len(index)), bool) if filled is None else ~filled[:, index]
            frames[seg.name], interpolated[seg.name] = _segment_pose(
                seg.name, seg.frame_markers, local[:, index], seen
            )
        return SegMeasured(plane, local, frames, interpolated)

    def interpolated_frames(self, measured: SegMeasured) -> int:
        return sum(measured.interpolated_frames.values())

    def fit_joints(self, measured: Sequence[SegMeasured], params=None) -> dict:
        """Each joint's centre as ``{joint: {segment: [x, y] mm in its frame}}``, each
        ``from_joints`` segment's length (mm, its ``length_mm`` when the description gives
        it) and its RMS deviation over the frames, and, given the version's ``params``,
        how far noise like the trials' own moves its joints (`noise_shift`, mm)."""

        def pooled(seg):
            return tuple(np.concatenate([m.frames[seg][i] for m in measured]) for i in (0, 1))

        centres: dict[str, dict[str, list[float]]] = {j.name: {} for j in self.body.joints}
        links: dict[str, list[float]] = {}
        shifts: dict[str, float] = {}
        for seg in self.body.segments:
            if not seg.from_joints:
                continue
            down, up = self.parent_joint[seg.name], self.child_joints[seg.name][0]
            (to, ta), (ho, ha) = pooled(down.parent), pooled(up.child)
            fitted = fit_joints(SegmentFrames(ho, ha, to, ta), seg.length_mm)
            centres[up.name][up.child] = fitted.head.tolist()
            centres[down.name][down.parent] = fitted.tail.tolist()
            links[seg.name] = [fitted.length_mm, fitted.rms_mm]
            if params is not None:
                trials = [
                    SegmentFrames(*m.frames[up.child], *m.frames[down.parent]) for m in measured
                ]
                seed = params_seed(params)
                shifts[seg.name] = noise_shift(trials, fitted, seg.length_mm, seed)
        for j in self.body.joints:
            if self.segments[j.parent].from_joints or self.segments[j.child].from_joints:
                continue
            a, b = _common_point(*pooled(j.parent), *pooled(j.child))
            centres[j.name] = {j.parent: a.tolist(), j.child: b.tolist()}
        out = {"centres": centres, "links": links}
        if shifts:
            out["noise_shift_mm"] = shifts
        return out

    def joints_warning(self, joints: dict) -> str | None:
        poor = {
            seg: shift
            for seg, shift in joints.get("noise_shift_mm", {}).items()
            if shift > JOINT_SHIFT_WARN_MM
        }
        if not poor:
            return None
        named = ", ".join(
            f"segments.{seg} (joints moved {shift:.1f} mm, fitted "
            f"{joints['links'][seg][0]:.1f} mm apart)"
            for seg, shift in poor.items()
        )
        return (
            f"joints of {named} are poorly determined by these trials: noise like their own "
            "moves them, so joint angles and body velocity may be biased by a few per cent; "
            "give the segment's length_mm in the body description, or preprocess together "
            "with trials of a gait whose shape loop is not a circle"
        )

    def joints_state(self, joints: dict) -> str:
        return json.dumps(joints)

    def joints_from(self, state: str) -> dict:
        return json.loads(state)

    def _joint_points(self, measured: SegMeasured, joints: dict) -> dict[str, np.ndarray]:
        """Each joint's centre per frame (n_frames, 2) mm in the plane: the mean of its
        estimates from the segments that know it."""
        out = {}
        for name, by_seg in joints["centres"].items():
            points = [
                measured.frames[seg][0] + rotate(measured.frames[seg][1], np.asarray(c)[None])
                for seg, c in by_seg.items()
            ]
            out[name] = points[0] if len(points) == 1 else 0.5 * (points[0] + points[1])
        return out

    def _axes(self, measured: SegMeasured, points: dict) -> dict[str, np.ndarray]:
        """Each segment's axis heading (n_frames,) rad (the module docstring's rule, which
        no listing order enters), the body frame's unwrapped."""
        out = {}
        for seg in self.body.segments:
            parent = self.parent_joint.get(seg.name)
            kids = self.child_joints[seg.name]
            origin = None if seg.from_joints else measured.frames[seg.name][0]
            one_kid = points[kids[0].name] if len(kids) == 1 else None
            if parent is not None:
                start, end = points[parent.name], one_kid if one_kid is not None else origin
            elif one_kid is not None:
                start, end = origin, one_kid
            else:
                out[seg.name] = measured.frames[seg.name][1]
                continue
            out[seg.name] = _heading(end - start)
        out[self.body.body_frame] = np.unwrap(out[self.body.body_frame])
        return out

    def _far_point(self, seg: str, joint: str, measured: SegMeasured, points: dict) -> np.ndarray:
        """(n_frames, 2) mm: the point a segment's side of ``joint`` points to: its other
        joint's centre when it has exactly two joints, else its frame origin."""
        joints = self.joints_of[seg]
        if len(joints) == 2:
            return points[next(j.name for j in joints if j.name != joint)]
        return measured.frames[seg][0]

    def _bends(self, measured: SegMeasured, points: dict, joints) -> np.ndarray:
        """The bends (n_frames, len(joints)) rad of ``joints``, each continuous in time."""
        out = []
        for j in joints:
            at = points[j.name]
            before = at - self._far_point(j.parent, j.name, measured, points)
            after = self._far_point(j.child, j.name, measured, points) - at
            out.append(_wrap(_heading(after) - _heading(before)))
        return np.unwrap(np.stack(out, axis=1), axis=0)

    def pose(self, measured: SegMeasured, joints: dict):
        """(joint centres by name, axis headings by segment, body origin (n_frames, 2) mm,
        body heading (n_frames,) rad unwrapped) of one trial."""
        points = self._joint_points(measured, joints)
        axes = self._axes(measured, points)
        frame = self.body.body_frame
        if self.segments[frame].from_joints:
            up = self.child_joints[frame][0].name
            down = self.parent_joint[frame].name
            xy = 0.5 * (points[up] + points[down])
        else:
            xy = measured.frames[frame][0]
        return points, axes, xy, axes[frame]

    def joint_angles(self, measured: SegMeasured, joints: dict) -> dict[str, np.ndarray]:
        """Every joint's bend (n_frames,) rad (the module docstring's definition),
        continuous in time."""
        points = self._joint_points(measured, joints)
        bends = self._bends(measured, points, self.body.joints)
        return {j.name: bends[:, i] for i, j in enumerate(self.body.joints)}

    def _in_segment(self, p, seg, points, axes, xy):
        towards = self.towards_body.get(seg)
        origin = xy if towards is None else points[towards[0]]
        d = p - origin
        c, s = np.cos(axes[seg]), np.sin(axes[seg])
        return [c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]]

    def kinematics(self, measured, joints, params, rate_hz, frequency_hz) -> Kinematics:
        points, axes, xy, heading = self.pose(measured, joints)
        ra = self._bends(measured, points, self.actuated)
        cols = []
        for marker, seg in self.hanging:
            p = measured.local[:, self._col[marker]]
            cols += self._in_segment(p, seg, points, axes, xy)
        for j in self.passive_joints:
            # the far side is the one whose path to the body frame crosses this joint
            parent_is_far = self.towards_body.get(j.parent, (None,))[0] == j.name
            near, far = (j.child, j.parent) if parent_is_far else (j.parent, j.child)
            if self.segments[far].from_joints:
                p = points[self.child_joints[far][0].name]
            else:
                p = measured.frames[far][0]
            cols += self._in_segment(p, near, points, axes, xy)
        return Kinematics(xy, heading, ra, np.stack(cols, axis=1))

    def stats(self, measured, joints: dict) -> tuple[list[float], float, float]:
        points = self._joint_points(measured, joints)
        frame = self.body.body_frame
        length, spread = 0.0, []
        if self.segments[frame].from_joints:
            d = points[self.child_joints[frame][0].name] - points[self.parent_joint[frame].name]
            dist = np.hypot(*d.T)
            length = float(dist.mean())
            spread.append(float(dist.std()))
        for by_seg in joints["centres"].values():
            if len(by_seg) == 2:  # how far the two segments' estimates of one centre differ
                a, b = (
                    measured.frames[s][0] + rotate(measured.frames[s][1], np.asarray(c)[None])
                    for s, c in by_seg.items()
                )
                spread.append(float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1)))))
        rms = float(np.sqrt(np.mean(np.square(spread)))) if spread else 0.0
        return measured.plane.basis[2].tolist(), length, rms


def _segment_pose(
    name: str, markers: Sequence[str], points: np.ndarray, seen: np.ndarray
) -> tuple[tuple[np.ndarray, np.ndarray], int]:
    """A rigid segment's frame ((origin (n, 2) mm, angle (n,) rad)) from its frame
    markers ``points`` (n, m, 2) mm (gaps filled by interpolation) and which of them the
    capture saw (``seen`` (n, m) bool), and the number of frames whose pose rests on
    interpolated points (fewer than two seen)."""
    two = points[:, :2]
    d = two[:, 1] - two[:, 0]
    if np.any(np.hypot(d[:, 0], d[:, 1]) < 1e-6):
        raise PreprocessError(
            f"segment {name}: its frame markers {markers[0]} and {markers[1]} coincide"
        )
    origin, angle = two.mean(axis=1), np.arctan2(d[:, 1], d[:, 0])
    n_seen = seen.sum(axis=1)
    if len(markers) > 2:
        # the markers' places in the first estimate's frame, learned from the frames that
        # saw them all (`rigid_fit`'s, when none is missing), then each frame's rigid fit:
        # of every marker, or of those seen where two or more are
        full = n_seen == len(markers)
        ref = full if full.any() else np.ones(len(full), bool)
        template = to_frame(points[ref], origin[ref], angle[ref]).mean(axis=0)
        origin, angle = procrustes(template, points, angle)
        partial = (n_seen >= 2) & ~full
        for mask in {tuple(row) for row in seen[partial]}:
            keep = np.asarray(mask)
            rows = partial & (seen == keep).all(axis=1)
            origin[rows], angle[rows] = procrustes(
                template[keep], points[rows][:, keep], angle[rows]
            )
    return (origin, angle), int((n_seen < 2).sum())


def _common_point(
    o1: np.ndarray, a1: np.ndarray, o2: np.ndarray, a2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The point fixed in two 2D frames (origins (n, 2) mm, angles (n,) rad), least
    squares over the frames: (its coordinates in frame 1, in frame 2), each (2,) mm."""
    c1, s1, c2, s2 = np.cos(a1), np.sin(a1), np.cos(a2), np.sin(a2)
    # o1 + R(a1) p1 = o2 + R(a2) p2, two rows per frame in (p1x, p1y, p2x, p2y)
    rows_x = np.column_stack([c1, -s1, -c2, s2])
    rows_y = np.column_stack([s1, c1, -s2, -c2])
    design = np.concatenate([rows_x, rows_y])
    rhs = np.concatenate([o2[:, 0] - o1[:, 0], o2[:, 1] - o1[:, 1]])
    sol, *_ = np.linalg.lstsq(design, rhs, rcond=None)
    return sol[:2], sol[2:]
