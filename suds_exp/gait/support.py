"""Where a learned map can be trusted: the support of its training data.

A learned motility map is a function of the shape r_a and of the direction the shape
moves in (it is homogeneous of degree 1 in dr_a/dt, so the speed adds nothing). Its
support is therefore a set in (r_a, direction of dr_a/dt): a gait whose shapes were all
visited, but in other directions, still asks the map to extrapolate (the map of the
granular robot depends strongly on the direction, see the granular notes). The distance
of a gait from the data is the largest, over the gait's samples, of the distance to the
nearest training sample in the features (r_a, w u), u the unit direction of dr_a/dt
and w = `DIRECTION_WEIGHT` rad (so a reversed direction counts like 2 w rad of shape);
for the swimmer (phi1, phi2, w cos psi, w sin psi). A body of m actuated joints has 2 m
features. A gait is inside the support when that distance is at most `SHAPE_RADIUS`
(`Support.flag`, the flag `gait predict` and `gait design` print and store).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.spatial import cKDTree

from suds_exp.gait.shape import TWO_PI, Gait

#: Weight (rad) of the shape-velocity direction against the shape in the support's metric.
DIRECTION_WEIGHT = 0.5
#: A shape within this distance (rad) of a training sample is inside the shape support.
SHAPE_RADIUS = 0.1


def actuated_columns(samples: pd.DataFrame) -> tuple[list[str], list[str]]:
    """(["ra_1", .., "ra_m"], ["dra_1", .., "dra_m"]): the consecutive r_a columns."""
    m = 0
    while f"ra_{m + 1}" in samples.columns:
        m += 1
    return [f"ra_{j}" for j in range(1, m + 1)], [f"dra_{j}" for j in range(1, m + 1)]


def direction_features(ra: np.ndarray, dra: np.ndarray, weight: float = DIRECTION_WEIGHT):
    """(n, 2 m): r_a (n, m) rad and the unit direction of dr_a/dt (n, m) times weight
    (rad)."""
    speed = np.linalg.norm(dra, axis=1, keepdims=True)
    unit = dra / np.where(speed > 0, speed, 1.0)
    return np.hstack([ra, weight * unit])


@dataclass
class Support:
    """The training data's support: KD-trees over shapes (n, m) and over
    (shape, weighted direction) features (n, 2 m) of the training samples."""

    shapes: np.ndarray
    features: np.ndarray

    def __post_init__(self):
        self._shape_tree = cKDTree(self.shapes)
        self._feature_tree = cKDTree(self.features)

    @classmethod
    def of(cls, samples: pd.DataFrame) -> Support:
        """The support of a samples frame (columns ra_1 .. ra_m, dra_1 .. dra_m)."""
        ra_cols, dra_cols = actuated_columns(samples)
        ra = samples[ra_cols].to_numpy(float)
        dra = samples[dra_cols].to_numpy(float)
        moving = np.linalg.norm(dra, axis=1) > 1e-6
        return cls(ra, direction_features(ra[moving], dra[moving]))

    def shape_distance(self, points: np.ndarray) -> np.ndarray:
        """Distance (rad) of shapes (n, m) to the nearest training shape: (n,)."""
        return self._shape_tree.query(np.asarray(points, float))[0]

    def inside(self, points: np.ndarray, radius: float = SHAPE_RADIUS) -> np.ndarray:
        """(n,) bool: shapes within ``radius`` rad of the training shapes."""
        return self.shape_distance(points) <= radius

    def gait_distance(self, gait: Gait, n: int = 64) -> float:
        """Largest distance (rad, in the (shape, direction) metric) of the gait's n
        samples over a cycle from the training samples. The gait's columns must be the
        training samples' joints, in their order (`suds_exp.gait.joints.match_joints`)."""
        theta = TWO_PI * np.arange(n) / n
        f = direction_features(gait.shape(theta), gait.rate(theta))
        return float(self._feature_tree.query(f)[0].max())

    def flag(self, gait: Gait, radius: float = SHAPE_RADIUS) -> dict:
        """JSON-ready: ``distance_rad`` (`gait_distance`), ``radius_rad`` and ``inside``
        (the distance is at most radius: the map interpolates; else it extrapolates)."""
        distance = self.gait_distance(gait)
        return {
            "distance_rad": round(distance, 4),
            "radius_rad": radius,
            "inside": bool(distance <= radius),
        }

    def summary(self, joints=None) -> dict:
        """JSON-ready: samples, and the shape range covered (rad) of each joint, as
        ``<joint>_range`` (default names phi1 .. phim)."""
        lo, hi = self.shapes.min(axis=0), self.shapes.max(axis=0)
        names = joints or [f"phi{j + 1}" for j in range(self.shapes.shape[1])]
        out: dict = {"n_samples": int(len(self.shapes))}
        for j, name in enumerate(names):
            out[f"{name}_range"] = [round(float(lo[j]), 4), round(float(hi[j]), 4)]
        return out
