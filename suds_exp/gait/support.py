"""Where a learned map can be trusted: the support of its training data.

A learned motility map is a function of the shape r_a and of the direction the shape
moves in (it is homogeneous of degree 1 in dr_a/dt, so the speed adds nothing). Its
support is therefore a set in (r_a, direction of dr_a/dt): a gait whose shapes were all
visited, but in other directions, still asks the map to extrapolate (the map of the
granular robot depends strongly on the direction, see the granular notes). The distance
of a gait from the data is the largest, over the gait's samples, of the distance to the
nearest training sample in the features (phi1, phi2, w cos psi, w sin psi), psi the
direction of dr_a/dt and w = `DIRECTION_WEIGHT` rad (so a reversed direction counts
like 2 w rad of shape).
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


def direction_features(ra: np.ndarray, dra: np.ndarray, weight: float = DIRECTION_WEIGHT):
    """(n, 4): phi1, phi2 (rad) and the unit direction of dr_a/dt times weight (rad)."""
    speed = np.linalg.norm(dra, axis=1, keepdims=True)
    unit = dra / np.where(speed > 0, speed, 1.0)
    return np.hstack([ra, weight * unit])


@dataclass
class Support:
    """The training data's support: KD-trees over shapes (n, 2) and over
    (shape, weighted direction) features (n, 4) of the training samples."""

    shapes: np.ndarray
    features: np.ndarray

    def __post_init__(self):
        self._shape_tree = cKDTree(self.shapes)
        self._feature_tree = cKDTree(self.features)

    @classmethod
    def of(cls, samples: pd.DataFrame) -> Support:
        """The support of a samples frame (columns ra_1, ra_2, dra_1, dra_2)."""
        ra = samples[["ra_1", "ra_2"]].to_numpy(float)
        dra = samples[["dra_1", "dra_2"]].to_numpy(float)
        moving = np.linalg.norm(dra, axis=1) > 1e-6
        return cls(ra, direction_features(ra[moving], dra[moving]))

    def shape_distance(self, points: np.ndarray) -> np.ndarray:
        """Distance (rad) of shapes (n, 2) to the nearest training shape: (n,)."""
        return self._shape_tree.query(np.asarray(points, float))[0]

    def inside(self, points: np.ndarray, radius: float = SHAPE_RADIUS) -> np.ndarray:
        """(n,) bool: shapes within ``radius`` rad of the training shapes."""
        return self.shape_distance(points) <= radius

    def gait_distance(self, gait: Gait, n: int = 64) -> float:
        """Largest distance (rad, in the (shape, direction) metric) of the gait's n
        samples over a cycle from the training samples."""
        theta = TWO_PI * np.arange(n) / n
        f = direction_features(gait.shape(theta), gait.rate(theta))
        return float(self._feature_tree.query(f)[0].max())

    def summary(self) -> dict:
        """JSON-ready: samples, and the shape range covered (rad)."""
        lo, hi = self.shapes.min(axis=0), self.shapes.max(axis=0)
        return {
            "n_samples": int(len(self.shapes)),
            "phi1_range": [round(float(lo[0]), 4), round(float(hi[0]), 4)],
            "phi2_range": [round(float(lo[1]), 4), round(float(hi[1]), 4)],
        }
