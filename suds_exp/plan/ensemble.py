"""A learned map and its uncertainty: the point fit and bootstrap refits over cycles.

The uncertainty of a prediction comes from the learner itself: it is refitted on
``n_boot`` resamples of the training data and the spread of the refits' predictions is
the prediction's standard error. The resampled unit is one cycle of one trial (a block
of consecutive samples), not one trial: a loop starts from a single trial, and a
bootstrap over one trial has no spread at all. Each drawn block becomes its own series
(renumbered trial id), so a learner that reads series (branching, SUDS) never joins two
blocks into one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from suds_exp.gait.motion import CycleMotion
from suds_exp.gait.predict import FittedMap, fit_map
from suds_exp.gait.shape import Gait
from suds_exp.models.registry import GMR

#: Bootstrap refits of a plan: each costs one fit (about 50 ms for GMR on a few thousand
#: samples) and then one rollout per gait evaluated.
N_BOOT = 6


def cycle_blocks(samples: pd.DataFrame) -> list[pd.DataFrame]:
    """The samples split into one frame per (trial_id, cycle), in recording order."""
    return [b for _, b in samples.groupby(["trial_id", "cycle"], sort=True)]


def block_draws(samples: pd.DataFrame, n_boot: int, seed: int):
    """``n_boot`` samples frames, each the cycle blocks of ``samples`` resampled with
    replacement (draw b seeded by (seed, b)); each drawn block is a series of its own,
    renumbered 1..n."""
    blocks = cycle_blocks(samples)
    for b in range(n_boot):
        rng = np.random.default_rng([seed, b])
        pick = rng.integers(0, len(blocks), size=len(blocks))
        yield pd.concat(
            [blocks[j].assign(trial_id=i + 1) for i, j in enumerate(pick)], ignore_index=True
        )


@dataclass
class MapEnsemble:
    """A learner fitted on all the samples (``point``) and on ``n_boot`` cycle-bootstrap
    resamples (``members``)."""

    point: FittedMap
    members: list[FittedMap]

    @classmethod
    def fit(
        cls, samples: pd.DataFrame, learner: str = GMR, n_boot: int = N_BOOT, seed: int = 0
    ) -> MapEnsemble:
        """Fit ``learner`` on ``samples`` (a version's frame) and on ``n_boot`` block
        bootstrap draws seeded by ``seed``."""
        point = fit_map(samples, learner)
        members = [fit_map(frame, learner) for frame in block_draws(samples, n_boot, seed)]
        return cls(point, members)

    def motion(self, gait: Gait, frequency_hz: float) -> CycleMotion:
        """The point fit's net motion per cycle of ``gait`` at frequency_hz (Hz)."""
        return self.point.motion(gait, frequency_hz)

    def forward(self, gait: Gait, frequency_hz: float) -> tuple[float, float]:
        """(point prediction, bootstrap standard deviation) of the forward displacement
        per cycle of ``gait`` at frequency_hz, mm."""
        point = self.point.forward(gait, frequency_hz)
        if not self.members:
            return point, 0.0
        boots = [m.forward(gait, frequency_hz) for m in self.members]
        return point, float(np.std(boots, ddof=1)) if len(boots) > 1 else 0.0

    def displacements(self, pairs: Sequence[tuple[Gait, float]]) -> tuple[np.ndarray, np.ndarray]:
        """Net displacement per cycle (forward, lateral; mm) of each (gait, frequency Hz)
        of ``pairs``: the refits' (len(members), len(pairs), 2) and the point fit's
        (len(pairs), 2)."""

        def xy(fitted) -> np.ndarray:
            motions = [fitted.motion(g, f) for g, f in pairs]
            return np.array([[m.forward_mm, m.lateral_mm] for m in motions]).reshape(-1, 2)

        members = np.array([xy(m) for m in self.members]).reshape(-1, len(pairs), 2)
        return members, xy(self.point)

    def displacement_spread(self, gaits: Sequence[Gait], frequency_hz: float) -> np.ndarray:
        """Bootstrap variance of each gait's net displacement per cycle (forward and
        lateral together), mm^2: array (len(gaits),)."""
        out = np.zeros(len(gaits))
        if len(self.members) < 2:
            return out
        for j, g in enumerate(gaits):
            motions = [m.motion(g, frequency_hz) for m in self.members]
            xy = np.array([[m.forward_mm, m.lateral_mm] for m in motions])
            out[j] = float(xy.var(axis=0, ddof=1).sum())
        return out
