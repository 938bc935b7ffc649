"""Bootstrap sampling of one draw: the test trial and range, then the training cycles.

Given the draw's random generator (`Draw.seed`):

1. test: a trial of the test condition picked uniformly among the eligible ones (for a
   same-condition draw, those that leave at least ``n_cycles`` complete cycles in the
   condition's other trials), and within its longest run of complete cycles a random
   contiguous range of ``min(test_cycles, run length)`` cycles;
2. training: the runs of complete cycles of the train condition's trials, the test trial
   excluded, in a random order; from each in turn a random contiguous range of as many
   cycles as still needed, until ``n_cycles`` are drawn. Usually the first trial is long
   enough, as in the paper ("a 30 cycle interval from that trial").

Recordings without conditions (an experiment design with no axis but the frequency,
`suds_exp.experiment`) have the one condition label ``all``; its draws are run by trial:
draw ``b`` tests on the ``b``-th eligible trial (in trial order) instead of a random one,
training on the others (leave-one-trial-out).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from suds_exp.campaign.bank import SampleBank
from suds_exp.campaign.conditions import Condition, format_condition
from suds_exp.campaign.grid import Draw
from suds_exp.errors import CampaignError
from suds_exp.experiment import BY_TRIAL_LABEL


@dataclass(frozen=True)
class Sample:
    """Cycle ranges of one draw, as trial indices into the bank.

    ``train``: list of (trial index, first cycle, last cycle); ``test``: one such tuple.
    """

    train: list[tuple[int, int, int]]
    test: tuple[int, int, int]


def _eligible_tests(bank: SampleBank, train: Condition, test: Condition, n_cycles: int):
    trials = bank.trials_of(test)
    if train != test:
        return trials
    total = sum(bank.n_cycles(i) for i in trials)
    return [i for i in trials if total - bank.n_cycles(i) >= n_cycles]


def draw_sample(bank: SampleBank, draw: Draw, test_cycles: int) -> Sample:
    """The training and test cycle ranges of ``draw`` (see the module docstring)."""
    rng_test, rng_train = (np.random.default_rng(s) for s in draw.seed().spawn(2))
    eligible = _eligible_tests(bank, draw.train, draw.test, draw.n_cycles)
    if not eligible:
        raise CampaignError(f"{format_condition(draw.test)}: no test trial available for {draw}")
    if draw.train == draw.test and draw.test[0] == BY_TRIAL_LABEL:
        # recordings without conditions: draw b tests on the b-th eligible trial, so
        # `boots` = number of trials leaves each trial out once
        ti = eligible[draw.boot % len(eligible)]
    else:
        ti = eligible[int(rng_test.integers(len(eligible)))]
    a, b = max(bank.runs[ti], key=lambda r: r[1] - r[0])
    m = min(test_cycles, b - a + 1)
    start = a + int(rng_test.integers(b - a + 2 - m))
    test = (ti, start, start + m - 1)

    segments = [(i, a, b) for i in bank.trials_of(draw.train) if i != ti for a, b in bank.runs[i]]
    remaining = draw.n_cycles
    train: list[tuple[int, int, int]] = []
    for j in rng_train.permutation(len(segments)):
        i, a, b = segments[j]
        take = min(remaining, b - a + 1)
        first = a + int(rng_train.integers(b - a + 2 - take))
        train.append((i, first, first + take - 1))
        remaining -= take
        if remaining == 0:
            break
    if remaining:
        raise CampaignError(
            f"{format_condition(draw.train)}: only {draw.n_cycles - remaining} complete cycles "
            f"outside the test trial; {draw.n_cycles} asked"
        )
    return Sample(train=train, test=test)


#: The options a feasibility error suggests changing.
FEASIBILITY_PARAMS = ("train_cycles", "sweep", "skip_infeasible")


def check_feasible(
    bank: SampleBank,
    train_conditions: list[Condition],
    test_conditions: list[Condition],
    max_cycles: dict[Condition, int],
) -> None:
    """Refuse a grid some of whose draws cannot be made, naming the condition and the most
    training cycles it can give; ``max_cycles`` is the most asked of each train condition."""
    for cond in test_conditions:
        if not bank.trials_of(cond):
            raise CampaignError(
                f"test_conditions: {format_condition(cond)} has no trial with a complete cycle",
                param="test_conditions",
            )
    for cond in train_conditions:
        trials = bank.trials_of(cond)
        total = sum(bank.n_cycles(i) for i in trials)
        if not trials:
            raise CampaignError(
                f"train_conditions: {format_condition(cond)} has no trial with a complete cycle",
                param="train_conditions",
            )
        need = max_cycles.get(cond, 0)
        if cond in set(test_conditions):
            best = total - min(bank.n_cycles(i) for i in trials)
            if need > best:
                raise CampaignError(
                    f"{format_condition(cond)}: at most {best} complete training cycles remain "
                    f"outside a test trial of the same condition, but {need} are asked; lower "
                    "train_cycles/sweep, leave the condition out, or pass skip_infeasible to "
                    "leave out the (condition, size) cells the data cannot supply",
                    param=FEASIBILITY_PARAMS,
                )
        elif need > total:
            raise CampaignError(
                f"{format_condition(cond)}: {total} complete cycles in all, but {need} are "
                "asked; lower train_cycles/sweep, leave the condition out, or pass "
                "skip_infeasible to leave out the (condition, size) cells the data cannot supply",
                param=FEASIBILITY_PARAMS,
            )


def infeasible_cells(
    bank: SampleBank,
    train_conditions: list[Condition],
    test_conditions: list[Condition],
    train_cycles: int,
    sweep: list[int],
) -> list[tuple[Condition, int, str]]:
    """The (train condition, training cycles, scope) cells of the grid whose draws cannot
    be made, in grid order: scope ``all`` when the condition has fewer complete cycles in
    all than asked (every draw training on it at that size), ``same-condition`` when only
    the same-condition draws fail (the test trial leaves too few cycles in the others).
    Conditions with no complete cycle are not cells: `check_feasible` refuses them."""
    tests = set(test_conditions)
    cells = []
    for cond in train_conditions:
        trials = bank.trials_of(cond)
        if not trials:
            continue
        total = sum(bank.n_cycles(i) for i in trials)
        best = total - min(bank.n_cycles(i) for i in trials)
        sizes = {int(train_cycles)} | ({int(n) for n in sweep} if cond in tests else set())
        for n in sorted(sizes):
            if n > total and n == train_cycles:
                cells.append((cond, n, "all"))
            elif cond in tests and n > best:
                cells.append((cond, n, "same-condition"))
    return cells
