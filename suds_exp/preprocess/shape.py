"""Step 3, shape: the actuated shape r_a and the passive shape r_p (PCA of 12 coordinates).

r_a = (phi1, phi2): each outer segment's axis runs between its origin (motor axis) and the
centroid of its two top-surface markers projected on the plane (the paper's segment
X-axis). phi1 = heading(head axis, joint -> centroid) - heading(body X);
phi2 = heading(body X) - heading(tail axis, centroid -> joint). CCW positive, rad.

Passive state: plane XY of the two spoke markers and the four flipper markers in the frame
of the segment each is attached to (origin at the segment origin, X along the segment
axis pointing tail-to-head, Y to the left): 12 numbers, mm. PCA over all trials of a
version reduces them to k components r_p (mm).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from suds_exp.preprocess.body_frame import BodyPose, SegmentFrames
from suds_exp.robot import PASSIVE_ROLES

PASSIVE_NAMES = tuple(f"{role}_{axis}" for role, _ in PASSIVE_ROLES for axis in "xy")


def _heading(v: np.ndarray) -> np.ndarray:
    return np.arctan2(v[:, 1], v[:, 0])


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


def segment_axes(frames: SegmentFrames, pose: BodyPose) -> tuple[np.ndarray, np.ndarray]:
    """World (plane) headings of the head and tail axes, each (n_frames,) rad."""
    head = _heading(frames.head_origin - pose.head_joint)
    tail = _heading(pose.tail_joint - frames.tail_origin)
    return head, tail


def actuated_shape(frames: SegmentFrames, pose: BodyPose) -> np.ndarray:
    """r_a = (phi1, phi2), array of shape (n_frames, 2), rad (continuous in time)."""
    head, tail = segment_axes(frames, pose)
    phi1 = _wrap(head - pose.heading)
    phi2 = _wrap(pose.heading - tail)
    return np.unwrap(np.stack([phi1, phi2], axis=1), axis=0)


def cartesian_shape(frames: SegmentFrames, pose: BodyPose) -> np.ndarray:
    """r_a as Cartesian values (the paper: "We used cartesian values rather than angles to
    represent the pose"): each outer segment's top-marker centroid in the body frame.

    Returns an array of shape (n_frames, 4), mm: head x, head y, tail x, tail y (body
    frame: origin midway between the motor axes, +X towards the head).
    """
    c, s = np.cos(pose.heading), np.sin(pose.heading)

    def in_body(p):
        d = p - pose.xy
        return np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)

    return np.hstack([in_body(frames.head_origin), in_body(frames.tail_origin)])


#: r_a of each representation (preprocessing parameter ``ra_repr``).
ACTUATED_SHAPES = {"angles": actuated_shape, "cartesian": cartesian_shape}


def passive_state(
    frames: SegmentFrames, pose: BodyPose, points: dict[str, np.ndarray]
) -> np.ndarray:
    """The 12 passive coordinates, array of shape (n_frames, 12), mm (order `PASSIVE_NAMES`).

    ``points`` maps each role of `PASSIVE_ROLES` to its plane XY track (n_frames, 2) mm.
    """
    head, tail = segment_axes(frames, pose)
    origin = {"head": pose.head_joint, "tail": pose.tail_joint}
    angle = {"head": head, "tail": tail}
    cols = []
    for role, segment in PASSIVE_ROLES:
        d = points[role] - origin[segment]
        c, s = np.cos(angle[segment]), np.sin(angle[segment])
        cols.append(c * d[:, 0] + s * d[:, 1])
        cols.append(-s * d[:, 0] + c * d[:, 1])
    return np.stack(cols, axis=1)


@dataclass
class PassivePCA:
    """PCA of the passive 12-vector (unscaled, mm), components with a fixed sign.

    Parameters
    ----------
    n_components : int
        Number k of components kept as r_p.

    Attributes (after `fit`)
    ------------------------
    mean_ : array of shape (12,), mm
    components_ : array of shape (12, 12)
        All principal axes as rows, by decreasing variance; the first k give r_p. Each
        row's largest-magnitude loading is positive.
    explained_variance_ : array of shape (12,), mm^2
    explained_variance_ratio_ : array of shape (12,)
    """

    n_components: int = 4

    def fit(self, passive: np.ndarray) -> PassivePCA:
        """Fit on passive states, array of shape (n_samples, 12), mm."""
        x = np.asarray(passive, dtype=float)
        self.mean_ = x.mean(axis=0)
        centred = x - self.mean_
        cov = centred.T @ centred / max(len(x) - 1, 1)
        values, vectors = np.linalg.eigh(cov)
        order = np.argsort(values)[::-1]
        values, vectors = np.clip(values[order], 0.0, None), vectors[:, order].T
        flip = np.sign(vectors[np.arange(len(vectors)), np.argmax(np.abs(vectors), axis=1)])
        self.components_ = vectors * flip[:, None]
        self.explained_variance_ = values
        total = values.sum()
        self.explained_variance_ratio_ = values / total if total > 0 else np.zeros_like(values)
        return self

    def transform(self, passive: np.ndarray) -> np.ndarray:
        """r_p, array of shape (n_samples, k), mm."""
        return (np.asarray(passive) - self.mean_) @ self.components_[: self.n_components].T

    def transform_rate(self, rate: np.ndarray, passive: np.ndarray | None = None) -> np.ndarray:
        """dr_p/dt from passive-state rates (n_samples, 12) mm/s -> (n_samples, k) mm/s
        (``passive``, the state, is what nonlinear reducers need; a linear map ignores it)."""
        return np.asarray(rate) @ self.components_[: self.n_components].T

    def to_dict(self) -> dict:
        return {
            "n_components": self.n_components,
            "mean": self.mean_.tolist(),
            "components": self.components_.tolist(),
            "explained_variance": self.explained_variance_.tolist(),
            "explained_variance_ratio": self.explained_variance_ratio_.tolist(),
        }

    @classmethod
    def from_dict(cls, state: dict) -> PassivePCA:
        pca = cls(int(state["n_components"]))
        pca.mean_ = np.asarray(state["mean"])
        pca.components_ = np.asarray(state["components"])
        pca.explained_variance_ = np.asarray(state["explained_variance"])
        pca.explained_variance_ratio_ = np.asarray(state["explained_variance_ratio"])
        return pca
