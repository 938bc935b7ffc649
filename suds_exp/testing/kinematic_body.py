"""A kinematic generator for any described planar body: known joint angles, known body
path, markers with noise and gaps.

`serial_body` builds a chain of rigid links (a snake robot, a Purcell swimmer) as a body
description and its geometry; `PlanarBody.move` moves any described planar body: each
joint follows a known angle, the body frame a known path, and every marker its segment
(passive markers swing on a hinge of their segment by a known angle). Truth is analytic:
joint angles (rad) and the body velocity in the body frame (mm/s, rad/s).

Geometry conventions (those of `suds_exp.body.segments`): each segment's frame has +X
along its axis; a joint's angle is the child's frame angle minus its parent's; the body
frame is the ``body_frame`` segment's point ``body_origin`` with its +X.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.body.description import Body, parse_body
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
    body_origin : tuple
        The body origin (x, y) mm in the body frame segment's frame.
    """

    body: Body
    markers: dict[str, tuple[float, float, float]]
    hinges: dict[str, tuple[float, float, float, float]]
    joints: dict[str, tuple[tuple[float, float], tuple[float, float]]]
    body_origin: tuple[float, float]
    toml: str = field(default="", repr=False)

    def poses(self, t: np.ndarray, angles: dict[str, np.ndarray], path: tuple) -> dict:
        """World pose of every segment's frame: name -> (origin (n, 2) mm, angle (n,) rad),
        given the joint angles (name -> (n,) rad) and the body path (x, y, heading)."""
        x, y, heading = path
        frame = self.body.body_frame
        c, s = np.cos(heading), np.sin(heading)
        ox, oy = self.body_origin
        origin = np.column_stack([x - (c * ox - s * oy), y - (s * ox + c * oy)])
        poses = {frame: (origin, heading)}
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
                a_far = a + sign * angles[j.name]
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
        lines += [
            "[[joints]]",
            f'name = "q{i}"',
            f'parent = "s{i}"',
            f'child = "s{i + 1}"',
            f'kind = "{kind}"',
        ]
        joints[f"q{i}"] = ((L, 0.0), (0.0, 0.0))
    hinges = {}
    if fin:
        lines += ["[passive_markers]", f'fin = "{names[-1]}"']
        hinges["fin"] = (L, 0.0, 20.0, 10.0)
    text = "\n".join(lines) + "\n"
    return PlanarBody(parse_body(text, f"{name}.toml"), markers, hinges, joints, (L / 2, 0), text)


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
) -> tuple[Path, pd.DataFrame]:
    """Move ``planar`` (default: `travelling_wave`, `wavy_path`; the passive markers swing
    by 0.4 sin(2 pi t)), add Gaussian noise (``noise_mm`` per coordinate) and ``n_gaps``
    runs of 1..``max_gap_frames`` missing frames per marker, and write the markers as a
    marker CSV (`suds_exp.ingest.csv_reader`). Returns (the file, the truth frame of
    `PlanarBody.move`)."""
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
    path = Path(path)
    capture = Capture(
        path, "csv", rate_hz, list(planar.body.markers), np.arange(1, len(t) + 1), t, xyz
    )
    write_marker_csv(path, capture)
    return path, truth
