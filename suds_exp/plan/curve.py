"""When more data of this kind stops helping: the learning curve and its stopping signal.

The held-out error of the learner is measured at two nested training sizes, one double
the other (half the training cycles, all of them): the version's cycle blocks
(one cycle of one trial each) are split into `N_FOLDS` folds by a seeded shuffle, each
fold predicted by maps fitted on growing prefixes of the other folds' blocks. The error
is the RMS of the forward body velocity v_x (mm/s) on the held-out blocks, averaged over
folds; its spread is the standard error of that mean across the folds.

The signal is plain: if the last doubling of cycles lowered the held-out error by less
than its spread, the next doubling (of the same kind of data) will not help more, since
a learning curve flattens as it goes; say so.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from suds_exp.gait.predict import fit_map
from suds_exp.models.registry import GMR
from suds_exp.plan.ensemble import cycle_blocks

N_FOLDS = 4
#: Fewest cycle blocks the curve is drawn from (two per fold, so the smallest training
#: size still holds at least one cycle).
MIN_BLOCKS = 8


@dataclass
class StopSignal:
    """The learning curve's verdict. cycles: training cycles of each point (n,);
    error_mm_s: held-out RMS of v_x (mm/s) at each; spread_mm_s: its standard error;
    last_drop_mm_s: error lost over the last doubling; stop: True when that drop is less
    than the spread; message: the plain sentence."""

    stop: bool
    message: str
    cycles: list[float]
    error_mm_s: list[float]
    spread_mm_s: list[float]
    last_drop_mm_s: float | None

    def to_dict(self) -> dict:
        out = asdict(self)
        for key in ("cycles", "error_mm_s", "spread_mm_s"):
            out[key] = [round(float(v), 4) for v in out[key]]
        if self.last_drop_mm_s is not None:
            out["last_drop_mm_s"] = round(float(self.last_drop_mm_s), 4)
        return out


def _rms_vx(fitted, blocks: list[pd.DataFrame]) -> float:
    frame = pd.concat(blocks, ignore_index=True)
    predicted = fitted.model.predict(frame)["vx"].to_numpy(float)
    return float(np.sqrt(np.nanmean((predicted - frame["vx"].to_numpy(float)) ** 2)))


def learning_curve(samples: pd.DataFrame, learner: str = GMR, seed: int = 0) -> StopSignal:
    """The held-out error at doubling training sizes and the stopping signal (see the
    module docstring) of the samples frame ``samples``."""
    blocks = cycle_blocks(samples)
    if len(blocks) < MIN_BLOCKS:
        return StopSignal(
            False,
            f"too few cycles to draw a learning curve ({len(blocks)} of {MIN_BLOCKS}): record more",
            [],
            [],
            [],
            None,
        )
    order = np.random.default_rng([seed, 7]).permutation(len(blocks))
    folds = np.array_split(order, N_FOLDS)
    n_train = len(blocks) - max(len(f) for f in folds)
    # two sizes are what the signal reads (the last doubling); each costs N_FOLDS fits
    sizes = sorted({max(1, n_train // 2), n_train})
    errors = np.full((N_FOLDS, len(sizes)), np.nan)
    for i, held in enumerate(folds):
        rest = [j for j in order if j not in set(held)]
        test = [blocks[j] for j in held]
        for s, n in enumerate(sizes):
            train = pd.concat([blocks[j] for j in rest[:n]], ignore_index=True)
            errors[i, s] = _rms_vx(fit_map(train, learner), test)
    mean = errors.mean(axis=0)
    spread = errors.std(axis=0, ddof=1) / np.sqrt(N_FOLDS)
    drop = float(mean[-2] - mean[-1]) if len(sizes) > 1 else None
    # training sizes in cycles: a block is one cycle
    cycles = [float(n) for n in sizes]
    if drop is None:
        stop, message = False, "too few cycles for two training sizes: record more"
    elif drop < spread[-1]:
        stop = True
        message = (
            f"stop: the last doubling of cycles ({sizes[-2]} -> {sizes[-1]}) lowered the "
            f"held-out error by {drop:.2f} mm/s, less than its spread {spread[-1]:.2f} mm/s; "
            "more data of this kind will not help"
        )
    else:
        stop = False
        message = (
            f"continue: the last doubling of cycles ({sizes[-2]} -> {sizes[-1]}) lowered the "
            f"held-out error by {drop:.2f} mm/s, more than its spread {spread[-1]:.2f} mm/s"
        )
    return StopSignal(stop, message, cycles, mean.tolist(), spread.tolist(), drop)
