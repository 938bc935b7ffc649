"""A kinematic generator for any described planar body: known joint angles, known body
path, markers with noise and gaps.

`serial_body` builds a chain of rigid links (a snake robot, a Purcell swimmer) as a body
description and its geometry; `PlanarBody.move` moves any described planar body: each
joint follows a known angle, the body frame a known path, and every marker its segment
(passive markers swing on a hinge of their segment by a known angle). Truth is analytic:
joint angles (rad) and the body velocity in the body frame (mm/s, rad/s).

`random_tree_body` builds a random valid tree of 2-6 such links: any segment the root,
any segment the body frame, joints listed in any order, passive joints and a passive
marker; `PlanarBody.relisted` lists the same body's joints in another order.

Conventions (those documented in `suds_exp.body.segments`, computed here from the exact
geometry rather than from markers): a joint's value is its bend, zero when the two
segments it joins are in line and counter-clockwise positive for the child seen from
above; the body frame is the documented one of the ``body_frame`` segment
(`PlanarBody.body_frame_in_segment`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.body.description import Body, Joint, parse_body
from suds_exp.ingest.capture import Capture
from suds_exp.ingest.csv_reader import write_marker_csv

#: A function of time (n,) s -> (value (n,), its time derivative (n,)).
Signal = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def sine(amplitude: float, frequency_hz: float, phase: float = 0.0, offset: float = 0.0):
    """offset + amplitude sin(2 pi f t + phase) and its derivative (a `Signal`)."""
    w = 2 * np.pi * frequency_hz

    def signal(t):
        return offset + amplitude * np.sin(w * t + phase), amplitude * w * np.cos(w * t + phase)

    return signal


@dataclass(frozen=True)
class PlanarBody:
    """A described body with its geometry, in mm.

    Attributes
    ----------
    body : Body
        Its description (segments, joints, passive markers, body frame).
    markers : dict
        Segment marker -> (x, y, z) mm in its segment's frame.
    hinges : dict
        Passive marker -> (hinge x, hinge y, arm length, z) mm in its segment's frame;
        the marker sits at hinge + arm (cos b, sin b) for its hinge angle b.
    joints : dict
        Joint name -> ((x, y) in the parent's frame, (x, y) in the child's frame), mm.
    """

    body: Body
    markers: dict[str, tuple[float, float, float]]
    hinges: dict[str, tuple[float, float, float, float]]
    joints: dict[str, tuple[tuple[float, float], tuple[float, float]]]
    toml: str = field(default="", repr=False)

    # -- the documented conventions, from the exact geometry ------------------------------
    def _joint_at(self, segment: str, joint: str) -> np.ndarray:
        j = next(j for j in self.body.joints if j.name == joint)
        return np.asarray(self.joints[joint][0 if j.parent == segment else 1], dtype=float)

    def _origin(self, segment: str) -> np.ndarray:
        seg = next(s for s in self.body.segments if s.name == segment)
        if seg.from_joints:
            ends = [self._joint_at(segment, j.name) for j in self._joints_of(segment)]
            return 0.5 * (ends[0] + ends[1])
        first, second = seg.frame_markers[:2]
        return 0.5 * (np.asarray(self.markers[first][:2]) + np.asarray(self.markers[second][:2]))

    def _joints_of(self, segment: str):
        return [j for j in self.body.joints if segment in (j.parent, j.child)]

    def _far(self, segment: str, joint: str) -> np.ndarray:
        """The point of ``segment`` its side of ``joint`` points to (its frame, mm): the
        other joint of a two-joint segment, else its frame origin."""
        joints = self._joints_of(segment)
        if len(joints) == 2:
            other = next(j.name for j in joints if j.name != joint)
            return self._joint_at(segment, other)
        return self._origin(segment)

    def bend_offsets(self) -> dict[str, float]:
        """Joint -> the child's frame angle minus the parent's when the joint is straight
        (bend zero), rad."""
        out = {}
        for j in self.body.joints:
            parent = self._joint_at(j.parent, j.name) - self._far(j.parent, j.name)
            child = self._far(j.child, j.name) - self._joint_at(j.child, j.name)
            out[j.name] = float(np.arctan2(parent[1], parent[0]) - np.arctan2(child[1], child[0]))
        return out

    def body_frame_in_segment(self) -> tuple[np.ndarray, float]:
        """The body frame's origin (2,) mm and +X angle (rad) in its segment's frame."""
        frame = self.body.body_frame
        origin = self._origin(frame)
        parent = [j for j in self.body.joints if j.child == frame]
        kids = [j for j in self.body.joints if j.parent == frame]
        if parent:
            start = self._joint_at(frame, parent[0].name)
            end = self._joint_at(frame, kids[0].name) if len(kids) == 1 else origin
        elif len(kids) == 1:
            start, end = origin, self._joint_at(frame, kids[0].name)
        else:
            seg = next(s for s in self.body.segments if s.name == frame)
            first, second = seg.frame_markers[:2]
            start, end = np.asarray(self.markers[first][:2]), np.asarray(self.markers[second][:2])
        d = np.asarray(end) - np.asarray(start)
        return origin, float(np.arctan2(d[1], d[0]))

    def relisted(self, order: list[str]) -> PlanarBody:
        """The same body with its joints listed in ``order`` (joint names)."""
        by_name = {j.name: j for j in self.body.joints}
        head, _, _ = self.toml.partition("[[joints]]")
        _, _, passive = self.toml.partition("[passive_markers]")
        lines = [head.rstrip("\n")]
        for name in order:
            lines += _joint_lines(by_name[name])
        if passive:
            lines += ["[passive_markers]" + passive.rstrip("\n")]
        text = "\n".join(lines) + "\n"
        return PlanarBody(
            parse_body(text, self.body.source), self.markers, self.hinges, self.joints, text
        )

    def poses(self, t: np.ndarray, angles: dict[str, np.ndarray], path: tuple) -> dict:
        """World pose of every segment's frame: name -> (origin (n, 2) mm, angle (n,) rad),
        given the joint bends (name -> (n,) rad) and the body frame's path (x, y, heading)."""
        x, y, heading = path
        frame = self.body.body_frame
        (ox, oy), alpha = self.body_frame_in_segment()
        heading = heading - alpha
        c, s = np.cos(heading), np.sin(heading)
        origin = np.column_stack([x - (c * ox - s * oy), y - (s * ox + c * oy)])
        poses = {frame: (origin, heading)}
        offsets = self.bend_offsets()
        todo = [frame]
        while todo:
            here = todo.pop()
            for j in self.body.joints:
                at_parent, at_child = (np.asarray(p, dtype=float) for p in self.joints[j.name])
                if j.parent == here and j.child not in poses:
                    near, far, p_near, p_far, sign = j.parent, j.child, at_parent, at_child, 1
                elif j.child == here and j.parent not in poses:
                    near, far, p_near, p_far, sign = j.child, j.parent, at_child, at_parent, -1
                else:
                    continue
                o, a = poses[near]
                centre = o + _rotate(a, p_near)
                a_far = a + sign * (angles[j.name] + offsets[j.name])
                poses[far] = (centre - _rotate(a_far, p_far), a_far)
                todo.append(far)
        return poses

    def move(
        self,
        t: np.ndarray,
        joint_signals: dict[str, Signal],
        path: tuple[Signal, Signal, Signal],
        hinge_signals: dict[str, Signal] | None = None,
    ) -> tuple[np.ndarray, pd.DataFrame]:
        """Markers (n, n_markers, 3) mm in ``body.markers`` order, and the truth frame:
        ``t``, ``x``, ``y``, ``theta`` (body frame pose, mm, rad), ``vx``, ``vy`` (mm/s),
        ``wz`` (rad/s) in the body frame, and each joint's angle (rad) by its name."""
        hinge_signals = hinge_signals or {}
        angles = {name: f(t)[0] for name, f in joint_signals.items()}
        (x, dx), (y, dy), (th, dth) = (f(t) for f in path)
        poses = self.poses(t, angles, (x, y, th))
        segment_of = {m: s.name for s in self.body.segments for m in s.markers}
        segment_of.update(self.body.passive_markers)
        xyz = np.zeros((len(t), len(self.body.markers), 3))
        for i, m in enumerate(self.body.markers):
            o, a = poses[segment_of[m]]
            if m in self.markers:
                px, py, pz = self.markers[m]
                local = np.broadcast_to([px, py], (len(t), 2))
            else:
                hx, hy, arm, pz = self.hinges[m]
                b = hinge_signals[m](t)[0] if m in hinge_signals else np.zeros(len(t))
                local = np.column_stack([hx + arm * np.cos(b), hy + arm * np.sin(b)])
            xyz[:, i, :2] = o + _rotate(a, local)
            xyz[:, i, 2] = pz
        c, s = np.cos(th), np.sin(th)
        truth = pd.DataFrame(
            {"t": t, "x": x, "y": y, "theta": th, "vx": c * dx + s * dy, "vy": -s * dx + c * dy}
        )
        truth["wz"] = dth
        for name, value in angles.items():
            truth[name] = value
        return xyz, truth


def _rotate(angle: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate the 2-vectors v ((2,) or (n, 2)) by per-frame angles (n,) rad."""
    v = np.broadcast_to(v, (len(angle), 2))
    c, s = np.cos(angle), np.sin(angle)
    return np.column_stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]])


def serial_body(
    n_segments: int,
    passive: tuple[int, ...] = (),
    link_mm: float = 60.0,
    half_width_mm: float = 12.0,
    fin: bool = False,
    name: str = "serial",
) -> PlanarBody:
    """A chain of ``n_segments`` rigid links ``s1`` (tail) .. ``sN`` (head), joints ``q1``
    .. ``q{N-1}`` (``q_i`` from ``s_i`` to ``s_{i+1}``; those numbered in ``passive`` are
    passive, the others actuated), body frame on the middle link (at its midpoint).

    Each link carries three frame markers: two at (L/2, +-w) and one at (0.3 L, 1.5 w),
    z = 10 mm. ``fin``: a passive marker ``fin`` on a 20 mm arm hinged at the head link's
    tip (the passive state a body with no passive joint needs).
    """
    if n_segments < 2:
        raise ValueError(f"n_segments={n_segments}: a serial body needs at least 2")
    names = [f"s{i}" for i in range(1, n_segments + 1)]
    L, w = link_mm, half_width_mm
    lines = [f'name = "{name}"', f'body_frame = "{names[(n_segments - 1) // 2]}"']
    markers: dict[str, tuple[float, float, float]] = {}
    for seg in names:
        seg_markers = {f"{seg}_a": (L / 2, w, 10.0), f"{seg}_b": (L / 2, -w, 10.0)}
        seg_markers[f"{seg}_c"] = (0.3 * L, 1.5 * w, 10.0)
        markers.update(seg_markers)
        table = ", ".join(f'{m} = "top"' for m in seg_markers)
        lines += [f"[segments.{seg}]", f"markers = {{ {table} }}"]
    joints = {}
    for i in range(1, n_segments):
        kind = "passive" if i in passive else "actuated"
        lines += _joint_lines(Joint(f"q{i}", f"s{i}", f"s{i + 1}", kind))
        joints[f"q{i}"] = ((L, 0.0), (0.0, 0.0))
    hinges = {}
    if fin:
        lines += ["[passive_markers]", f'fin = "{names[-1]}"']
        hinges["fin"] = (L, 0.0, 20.0, 10.0)
    text = "\n".join(lines) + "\n"
    return PlanarBody(parse_body(text, f"{name}.toml"), markers, hinges, joints, text)


def _joint_lines(joint: Joint) -> list[str]:
    return [
        "[[joints]]",
        f'name = "{joint.name}"',
        f'parent = "{joint.parent}"',
        f'child = "{joint.child}"',
        f'kind = "{joint.kind}"',
    ]


#: Where a tree link's joints sit in its frame, in the order its joints are numbered: its
#: two ends on its axis, then a side mount (a hub's third joint).
_SLOTS = ((0.0, 0.0), (1.0, 0.0), (0.5, 2.5))


def random_tree_body(
    seed: int,
    n_segments: int,
    link_mm: float = 60.0,
    half_width_mm: float = 12.0,
    name: str = "tree",
) -> PlanarBody:
    """A random valid tree of ``n_segments`` (2-6) rigid links ``s1`` .. ``sN``, each with
    three frame markers as `serial_body`'s: a random tree shape (a link carries at most 3
    joints), a random root (the one segment that is no joint's child), a random body frame
    segment, joints ``q*`` (numbered by the tree, not the listing) listed in a random order,
    some of them passive, and a passive marker ``fin`` on a random link's hinge.

    A link's joints sit at its ends (0, 0) and (L, 0) and, for a third, at (L/2, 2.5 w) mm
    in its frame, numbered in the order the tree grew. Same ``seed``, same body.
    """
    if not 2 <= n_segments <= 6:
        raise ValueError(f"n_segments={n_segments}: a random tree has 2 to 6 links")
    rng = np.random.default_rng(seed)
    L, w = link_mm, half_width_mm
    names = [f"s{i}" for i in range(1, n_segments + 1)]
    edges: list[tuple[int, int]] = []
    degree = [0] * n_segments
    for i in range(1, n_segments):
        k = int(rng.choice([k for k in range(i) if degree[k] < len(_SLOTS)]))
        edges.append((k, i))
        degree[k] += 1
        degree[i] += 1
    slot: dict[tuple[int, int], tuple[float, float]] = {}
    used = [0] * n_segments
    for e, (a, b) in enumerate(edges):
        for seg in (a, b):
            sx, sy = _SLOTS[used[seg]]
            slot[(e, seg)] = (sx * L, sy * w)
            used[seg] += 1
    root = int(rng.integers(n_segments))
    # orient every edge away from the root: its parent is the end nearer the root
    depth = {root: 0}
    while len(depth) < n_segments:
        for a, b in edges:
            if a in depth and b not in depth:
                depth[b] = depth[a] + 1
            elif b in depth and a not in depth:
                depth[a] = depth[b] + 1
    n_passive = int(rng.integers(0, len(edges)))
    passive = set(rng.choice(len(edges), size=n_passive, replace=False).tolist())
    joint_list, joints = [], {}
    for e, (a, b) in enumerate(edges):
        parent, child = (a, b) if depth[a] < depth[b] else (b, a)
        kind = "passive" if e in passive else "actuated"
        joint_list.append(Joint(f"q{e + 1}", names[parent], names[child], kind))
        joints[f"q{e + 1}"] = (slot[(e, parent)], slot[(e, child)])
    order = rng.permutation(len(joint_list))
    frame = names[int(rng.integers(n_segments))]
    fin_on = names[int(rng.integers(n_segments))]
    lines = [f'name = "{name}"', f'body_frame = "{frame}"']
    markers: dict[str, tuple[float, float, float]] = {}
    for seg in names:
        seg_markers = {
            f"{seg}_a": (L / 2, w, 10.0),
            f"{seg}_b": (L / 2, -w, 10.0),
            f"{seg}_c": (0.3 * L, 1.5 * w, 10.0),
        }
        markers.update(seg_markers)
        table = ", ".join(f'{m} = "top"' for m in seg_markers)
        lines += [f"[segments.{seg}]", f"markers = {{ {table} }}"]
    for i in order:
        lines += _joint_lines(joint_list[i])
    lines += ["[passive_markers]", f'fin = "{fin_on}"']
    text = "\n".join(lines) + "\n"
    hinges = {"fin": (0.5 * L, -2.5 * w, 20.0, 10.0)}
    return PlanarBody(parse_body(text, f"{name}.toml"), markers, hinges, joints, text)


def travelling_wave(
    body: Body, amplitude: float = 0.5, frequency_hz: float = 1.0, lag: float = 0.9
) -> dict[str, Signal]:
    """A wave running along the joints in description order: actuated joint i at
    amplitude sin(2 pi f t - i lag); passive joints follow half as much, a quarter period
    later (a known, smooth motion, not a physical one)."""
    out = {}
    for i, j in enumerate(body.joints):
        if j.kind == "actuated":
            out[j.name] = sine(amplitude, frequency_hz, -i * lag)
        else:
            out[j.name] = sine(0.5 * amplitude, frequency_hz, -i * lag - np.pi / 2, 0.05)
    return out


def wavy_path(speed_mm_s: float = 60.0, frequency_hz: float = 1.0) -> tuple[Signal, Signal, Signal]:
    """A body path: forward at ``speed_mm_s`` with a surge, a sway and a yaw at the gait
    frequency (x, y mm; heading rad)."""
    surge = sine(0.15 * speed_mm_s / (2 * np.pi * frequency_hz), 2 * frequency_hz)
    w = 2 * np.pi * frequency_hz

    def x(t):
        s, ds = surge(t)
        return speed_mm_s * t + s, speed_mm_s + ds

    def heading(t):
        return 0.3 + 0.25 * np.sin(w * t + 0.4), 0.25 * w * np.cos(w * t + 0.4)

    return x, sine(4.0, frequency_hz, 1.1), heading


def write_body_trial(
    planar: PlanarBody,
    path: str | Path,
    seconds: float = 6.0,
    rate_hz: float = 100.0,
    noise_mm: float = 0.1,
    n_gaps: int = 2,
    max_gap_frames: int = 10,
    seed: int = 0,
    joint_signals: dict[str, Signal] | None = None,
    body_path: tuple[Signal, Signal, Signal] | None = None,
    gaps: dict[str, tuple[int, int]] | None = None,
) -> tuple[Path, pd.DataFrame]:
    """Move ``planar`` (default: `travelling_wave`, `wavy_path`; the passive markers swing
    by 0.4 sin(2 pi t)), add Gaussian noise (``noise_mm`` per coordinate) and ``n_gaps``
    runs of 1..``max_gap_frames`` missing frames per marker, and write the markers as a
    marker CSV (`suds_exp.ingest.csv_reader`). Returns (the file, the truth frame of
    `PlanarBody.move`). ``gaps``: marker -> (first frame index, length), missing frames
    added to the random ones."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(round(seconds * rate_hz))) / rate_hz
    signals = joint_signals or travelling_wave(planar.body)
    hinges = {m: sine(0.4, 1.0) for m in planar.hinges}
    xyz, truth = planar.move(t, signals, body_path or wavy_path(), hinges)
    xyz = xyz + rng.normal(0.0, noise_mm, xyz.shape)
    for m in range(xyz.shape[1]):
        for _ in range(n_gaps):
            length = int(rng.integers(1, max_gap_frames + 1))
            start = int(rng.integers(1, len(t) - length - 1))
            xyz[start : start + length, m] = np.nan
    for marker, (start, length) in (gaps or {}).items():
        xyz[start : start + length, planar.body.markers.index(marker)] = np.nan
    path = Path(path)
    capture = Capture(
        path, "csv", rate_hz, list(planar.body.markers), np.arange(1, len(t) + 1), t, xyz
    )
    write_marker_csv(path, capture)
    return path, truth
