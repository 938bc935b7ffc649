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

For the map goal the signal looks forward (`forecast_signal`), as the question is
whether the next doubling of cycles will help: the planner's own model of the target's
prediction variance (the bootstrap's noise plus the path jackknife's bias between paths,
`suds_exp.plan.recommend`) says how much of it the trials it would choose for the next
doubling remove; the expected error before and after is the root mean of that variance
per target. If the expected drop is less than the bootstrap spread of the target's
predictions, more data will not help more than noise can tell. Only the user's data
enter (the target is the user's; nothing is simulated).

`target_signal` judges the last doubling on the target instead: the
map fitted on the first half of the recorded cycles and the map fitted on all of them
predict the target's net displacement per cycle; if the last doubling moved those
predictions by less than their bootstrap spread, the data of the second half did not
teach the map anything about the target it could tell from noise (kept for callers; it
rarely fires, as each new path moves a refit by more than the bootstrap spread).

`plan loop --goal map` says stop once the forecast holds at two successive iterations
and keeps saying it (`latched`), so one lucky refit neither fires it nor a later one
unfires it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from suds_exp.gait.predict import fit_map
from suds_exp.models.registry import GMR
from suds_exp.plan.ensemble import MapEnsemble, cycle_blocks
from suds_exp.plan.recommend import bias_variance, recommend_map
from suds_exp.plan.target import Target

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
    change_mm: float | None = None
    spread_mm: float | None = None

    def to_dict(self) -> dict:
        out = asdict(self)
        for key in ("cycles", "error_mm_s", "spread_mm_s"):
            out[key] = [round(float(v), 4) for v in out[key]]
        for key in ("last_drop_mm_s", "change_mm", "spread_mm"):
            if out[key] is not None:
                out[key] = round(float(out[key]), 4)
        for key in ("change_mm", "spread_mm"):  # only the target's signal has them
            if out[key] is None:
                del out[key]
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


def target_signal(
    samples: pd.DataFrame, ensemble: MapEnsemble, target: Target, learner: str = GMR
) -> StopSignal:
    """The stopping signal judged on ``target`` (see the module docstring): the RMS over
    the target's (gait, frequency) pairs of the change (mm) of the predicted net
    displacement per cycle between the map fitted on the first half of the cycles
    (recording order: trial id, then cycle) and ``ensemble.point`` (fitted on all of
    them), against the RMS of ``ensemble``'s bootstrap standard deviation there (mm).
    Needs `MIN_BLOCKS` cycles in the half."""
    blocks = cycle_blocks(samples)
    half = len(blocks) // 2
    if half < MIN_BLOCKS:
        return StopSignal(
            False,
            f"too few cycles to judge a doubling on the target ({len(blocks)} of "
            f"{2 * MIN_BLOCKS}): record more",
            [],
            [],
            [],
            None,
        )
    first = fit_map(pd.concat(blocks[:half], ignore_index=True), learner)
    sq = []
    for g, f in target.pairs():
        a, b = first.motion(g, f), ensemble.point.motion(g, f)
        sq.append((a.forward_mm - b.forward_mm) ** 2 + (a.lateral_mm - b.lateral_mm) ** 2)
    change = float(np.sqrt(np.mean(sq)))
    variance = [ensemble.displacement_spread([g], f)[0] for g, f in target.pairs()]
    spread = float(np.sqrt(np.mean(variance)))
    doubling = f"the last doubling of cycles ({half} -> {len(blocks)})"
    if change < spread:
        stop, message = (
            True,
            (
                f"stop: {doubling} moved the target's predictions by {change:.2f} mm per cycle, "
                f"less than their bootstrap spread {spread:.2f} mm; more data of this kind "
                "will not help"
            ),
        )
    else:
        stop, message = (
            False,
            (
                f"continue: {doubling} moved the target's predictions by {change:.2f} mm per "
                f"cycle, more than their bootstrap spread {spread:.2f} mm"
            ),
        )
    return StopSignal(stop, message, [float(half), float(len(blocks))], [], [], None,
                      change, spread)  # fmt: skip


def forecast_signal(
    samples: pd.DataFrame,
    ensemble: MapEnsemble,
    target: Target,
    cycles: int,
    learner: str = GMR,
    bias: np.ndarray | None = None,
) -> StopSignal:
    """The map goal's stopping signal (see the module docstring): the expected drop (mm
    per cycle) of the target's prediction error over the next doubling of the recorded
    cycles, spent on the trials of ``cycles`` cycles `recommend_map` would choose, against
    the RMS bootstrap standard deviation (mm) of ``ensemble``'s predictions there.

    The expected error is sqrt(V / T) for the total variance V (mm^2: bootstrap noise plus
    path-jackknife bias, ``bias`` when the caller has it) over T target pairs; after the
    doubling V less what the chosen trials remove. ``change_mm`` is the drop,
    ``spread_mm`` the spread, ``cycles`` [now, after the doubling]."""
    pairs = target.pairs()
    n = len(cycle_blocks(samples))
    trials = max(1, round(n / cycles))
    if bias is None:
        bias = bias_variance(samples, target, learner, ensemble.point)
    noise = np.array([ensemble.displacement_spread([g], f)[0] for g, f in pairs])
    recs = recommend_map(ensemble, target, cycles, trials, samples, learner, bias)
    total = float(noise.sum() + bias.sum())
    removed = min(total, float(sum(r.score for r in recs)))
    before = float(np.sqrt(total / len(pairs)))
    after = float(np.sqrt((total - removed) / len(pairs)))
    drop, spread = before - after, float(np.sqrt(noise.mean()))
    doubling = (
        f"the next doubling of cycles ({n} -> {n + len(recs) * cycles}, the {len(recs)} "
        f"trials planned) is expected to lower the target's prediction error by {drop:.2f} "
        f"mm per cycle ({before:.2f} -> {after:.2f})"
    )
    if drop < spread:
        message = (
            f"stop: {doubling}, less than its bootstrap spread {spread:.2f} mm; more data "
            "of this kind will not help"
        )
    else:
        message = f"continue: {doubling}, more than its bootstrap spread {spread:.2f} mm"
    return StopSignal(drop < spread, message, [float(n), float(n + len(recs) * cycles)],
                      [], [], None, drop, spread)  # fmt: skip


def latched(now: StopSignal, before: StopSignal | None, fired: bool) -> StopSignal:
    """The signal a loop reports: stop once ``now`` and ``before`` (the previous
    iteration's, None at the first) both say stop, and from then on (``fired``: a stored
    iteration already said stop); otherwise ``now`` with stop False."""
    if fired and not now.stop:
        return StopSignal(True, "stop (said before; now " + now.message + ")", now.cycles,
                          now.error_mm_s, now.spread_mm_s, now.last_drop_mm_s, now.change_mm,
                          now.spread_mm)  # fmt: skip
    if now.stop and (fired or (before is not None and before.stop)):
        return now
    if now.stop:
        return StopSignal(False, "continue (once more to confirm): " + now.message, now.cycles,
                          now.error_mm_s, now.spread_mm_s, now.last_drop_mm_s, now.change_mm,
                          now.spread_mm)  # fmt: skip
    return now
