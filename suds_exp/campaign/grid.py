"""The job grid of a campaign, job keys, and seeds derived from keys alone.

A job is one learner on one draw; a draw is (campaign, train condition, test condition,
bootstrap index, training cycles). Every learner of a campaign sees the same draws (the
same training cycles and test trial for a given draw key), so learners are compared on
paired samples; the draw's random numbers come from a SHA-256 of the draw key, and a
learner's own `random_state` (when it has one left at None) from the job key. Numbers
therefore do not depend on the machine, the number of workers or the order of execution.

Grid:
- main: every (train, test) pair of the train and test conditions x `boots` draws, each
  with `train_cycles` training cycles;
- sample-efficiency sweep: for every condition that is both a train and a test condition,
  the same-condition pair (train = test condition, test on a different trial) x `boots`
  draws x every number of training cycles in `sweep` (the value `train_cycles` is the
  main grid's job already);
- skipped cells: a campaign run with ``--skip-infeasible`` leaves out the draws its data
  cannot supply, named as (train condition, training cycles, scope): scope
  ``same-condition`` leaves out the same-condition draws of that size, ``all`` every draw
  training on that condition with that many cycles.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from suds_exp.campaign.conditions import Condition

#: Columns of `results` that make a job's key, in order.
KEY_COLUMNS = (
    "campaign",
    "model",
    "train_gait",
    "train_frequency_hz",
    "test_gait",
    "test_frequency_hz",
    "boot",
    "n_cycles",
)


@dataclass(frozen=True)
class Draw:
    """One bootstrap draw; with a learner name it is a job."""

    campaign: str
    train: Condition
    test: Condition
    boot: int
    n_cycles: int

    def key_string(self) -> str:
        return "|".join(
            [
                self.campaign,
                self.train[0],
                f"{self.train[1]:.6f}",
                self.test[0],
                f"{self.test[1]:.6f}",
                str(self.boot),
                str(self.n_cycles),
            ]
        )

    def seed(self) -> np.random.SeedSequence:
        """The draw's seed: SHA-256 of its key string, as a 128-bit SeedSequence entropy."""
        return np.random.SeedSequence(_digest(self.key_string()))

    def model_seed(self, model: str) -> int:
        """A 32-bit seed for learner ``model``'s own randomness in this draw."""
        return _digest(self.key_string() + "|" + model) & 0xFFFFFFFF

    def job_key(self, model: str) -> tuple:
        return (
            self.campaign,
            model,
            self.train[0],
            self.train[1],
            self.test[0],
            self.test[1],
            self.boot,
            self.n_cycles,
        )


def _digest(text: str) -> int:
    return int.from_bytes(hashlib.sha256(text.encode("utf-8")).digest()[:16], "little")


def enumerate_draws(
    campaign: str,
    train_conditions: list[Condition],
    test_conditions: list[Condition],
    boots: int,
    train_cycles: int,
    sweep: list[int],
    skip=(),
) -> list[Draw]:
    """Every draw of the campaign grid (main grid, then the sweep), in a fixed order:
    each cell of `enumerate_cells` with its ``boots`` draws in turn.

    ``skip``: (train condition, n_cycles, scope) cells to leave out (see the module
    docstring); scope is ``same-condition`` or ``all``.
    """
    return [
        Draw(campaign, tr, te, b, n)
        for tr, te, n in enumerate_cells(
            train_conditions, test_conditions, train_cycles, sweep, skip
        )
        for b in range(boots)
    ]


def enumerate_cells(
    train_conditions: list[Condition],
    test_conditions: list[Condition],
    train_cycles: int,
    sweep: list[int],
    skip=(),
) -> list[tuple[Condition, Condition, int]]:
    """The grid's cells (train condition, test condition, training cycles), main grid
    then sweep, in `enumerate_draws`'s order; a cell holds one draw per bootstrap index.

    A campaign's draws are its cells times its bootstraps, so code that works on the
    cells (the runner's pending jobs) never has to build every draw.
    """
    cells = [(tr, te, train_cycles) for tr in train_conditions for te in test_conditions]
    same = [c for c in train_conditions if c in set(test_conditions)]
    cells += [(c, c, n) for c in same for n in sweep if n != train_cycles]
    if skip:
        left_out = {(tuple(c), int(n), scope) for c, n, scope in skip}
        cells = [
            (tr, te, n)
            for tr, te, n in cells
            if (tr, n, "all") not in left_out
            and not (tr == te and (tr, n, "same-condition") in left_out)
        ]
    return cells
