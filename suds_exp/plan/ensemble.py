"""A learned map and its uncertainty: the point fit, bootstrap refits over cycles and,
on request, refits that each leave one recorded path out.

The uncertainty of a prediction comes from the learner itself: it is refitted on
``n_boot`` resamples of the training data and the spread of the refits' predictions is
the prediction's standard error. The resampled unit is one cycle of one trial (a block
of consecutive samples), not one trial: a loop starts from a single trial, and a
bootstrap over one trial has no spread at all. Each drawn block becomes its own series
(renumbered trial id), so a learner that reads series (branching, SUDS) never joins two
blocks into one.

The cycle bootstrap sees the noise of what is recorded, not how much a prediction for a
gait no trial ran depends on which gaits were recorded. The path jackknife measures
that: each recorded path (a gait at a frequency) is left out in turn and the learner
refitted (`leave_path_out`). The gait goal's spread for a new gait (`MapEnsemble.fit`
with ``paths=True``) counts both: with the bootstrap alone its planned trials missed
their predictions by several spreads on the simulator (docs/results/adaptive.md, "How
far to trust a planned gait's spread").
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

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


def count_cycles(samples: pd.DataFrame) -> float:
    """Gait cycles a samples frame holds, as the user recorded them: per trial, its
    samples' span in time (samples x the median sampling interval, s) x its frequency
    (Hz), summed. A trial of unknown frequency counts its cycle blocks instead.

    Not the number of cycle blocks: the phaser counts loops of the shape path, so a gait
    that runs its loop twice a cycle gives two blocks a cycle, and each trial's part
    cycles at its ends are blocks of their own."""
    total = 0.0
    for _, trial in samples.groupby("trial_id", sort=False):
        frequency = float(pd.to_numeric(trial["frequency_hz"], errors="coerce").iloc[0])
        t = np.sort(trial["t"].to_numpy(float))
        if not np.isfinite(frequency) or len(t) < 2:
            total += trial["cycle"].nunique()
            continue
        total += len(t) * float(np.median(np.diff(t))) * frequency
    return total


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


def path_hz(frequency_hz: float) -> float:
    """A path's frequency as stored (6 decimals), so 1/3 Hz planned is 0.333333 recorded."""
    return round(float(frequency_hz), 6)


def recorded_paths(samples: pd.DataFrame | None) -> list[tuple[str, float]]:
    """The distinct (gait label, frequency Hz) of the recorded trials, sorted."""
    if samples is None or samples.empty:
        return []
    pairs = samples[["gait", "frequency_hz"]].drop_duplicates()
    labels = pairs["gait"].astype(str)
    freqs = [path_hz(f) for f in pairs["frequency_hz"].astype(float)]
    return sorted(set(zip(labels, freqs, strict=True)))


def leave_path_out(samples: pd.DataFrame) -> Iterator[pd.DataFrame]:
    """For each recorded path (`recorded_paths`, in order), the samples without its
    trials."""
    labels = samples["gait"].astype(str)
    freqs = samples["frequency_hz"].astype(float)
    for label, f in recorded_paths(samples):
        held = (labels == label) & np.isclose(freqs, f)
        yield samples[~held]


def jackknife_variance(values: Sequence[float] | np.ndarray) -> np.ndarray:
    """The jackknife variance of k leave-one-out estimates (axis 0): (k - 1) / k times
    the sum of their squared deviations from their mean; zeros for fewer than two."""
    values = np.asarray(values, float)
    k = len(values)
    if k < 2:
        return np.zeros(values.shape[1:])
    return (k - 1) / k * np.sum((values - values.mean(axis=0)) ** 2, axis=0)


@dataclass
class MapEnsemble:
    """A learner fitted on all the samples (``point``), on ``n_boot`` cycle-bootstrap
    resamples (``members``) and, when asked, on the samples without each recorded path
    in turn (``paths``; empty with fewer than two paths: nothing to leave out)."""

    point: FittedMap
    members: list[FittedMap]
    paths: list[FittedMap] = field(default_factory=list)

    @classmethod
    def fit(
        cls,
        samples: pd.DataFrame,
        learner: str = GMR,
        n_boot: int = N_BOOT,
        seed: int = 0,
        paths: bool = False,
    ) -> MapEnsemble:
        """Fit ``learner`` on ``samples`` (a version's frame) and on ``n_boot`` block
        bootstrap draws seeded by ``seed``; ``paths``: also once without each recorded
        path (`leave_path_out`), when at least two are recorded."""
        point = fit_map(samples, learner)
        members = [fit_map(frame, learner) for frame in block_draws(samples, n_boot, seed)]
        held = []
        if paths and len(recorded_paths(samples)) >= 2:
            held = [fit_map(frame, learner) for frame in leave_path_out(samples)]
        return cls(point, members, held)

    def motion(self, gait: Gait, frequency_hz: float) -> CycleMotion:
        """The point fit's net motion per cycle of ``gait`` at frequency_hz (Hz)."""
        return self.point.motion(gait, frequency_hz)

    def forward(self, gait: Gait, frequency_hz: float) -> tuple[float, float]:
        """(point prediction, spread) of the forward displacement per cycle of ``gait``
        at frequency_hz, mm: the spread is the bootstrap standard deviation, with the
        path jackknife's variance (`jackknife_variance` of the ``paths`` refits' forward
        displacements) added when the ensemble has them."""
        point = self.point.forward(gait, frequency_hz)
        variance = 0.0
        if len(self.members) > 1:
            variance += float(np.var([m.forward(gait, frequency_hz) for m in self.members], ddof=1))
        if self.paths:
            held = [m.forward(gait, frequency_hz) for m in self.paths]
            variance += float(jackknife_variance(held))
        return point, float(np.sqrt(variance))

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
