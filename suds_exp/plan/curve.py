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
per target. If the expected drop is less than the bootstrap spread of that error (the
issue's "flattens": the next doubling lowers the error by less than its bootstrap
spread), more data will not help more than noise can tell. The spread is of the RMS
error over the target, not of single predictions (several times wider): each bootstrap
refit's RMS error against a truth drawn from the same variance model, spread across
refits (`error_spread`). Only the user's data enter (the target is the user's; nothing
is simulated). The latched signal aims at the count from which the curve stays flat
(`Flattening.flat_from`), not at the first count the definition holds at (at one
trial the error's spread is wide enough to call almost any drop flat).

Why the forecast is calibrated, and how. The variance model counts all of the
target's variance as removable: a new path removes its share of the bias, more cycles
their share of the noise. Part of it no data of this kind remove: the learner's own
error where it has data, and the scatter from one fit to the next. Uncalibrated, the
forecast drop stays above the error's spread long after the measured error stops
falling (twice too late on the simulator's map loops, docs/results/adaptive.md). The
data's own history says how much is removable: the same forecast
made on the first half of the cycles (recording order) expected to remove the fraction
q of the variance V_h it saw, and the model on all the cycles sees V_now. If q is the
right rate for the removable part A_h and the rest is a floor, the fall V_h - V_now is
q A_h, so A_h = (V_h - V_now) / q and A_h (1 - q) is still removable now; the forecast
removes its fraction of that share of V_now only (`removable_share`). No constant is
fitted: a variance that did not fall over the last doubling leaves nothing removable,
one that fell as the model said leaves the model's forecast as it was. While the first
half holds a single recorded path the model's error there is its prior (the motion
itself), not a measurement, and the forecast is not calibrated.

Why not an empirical learning curve of held-out error (leave a recorded path out,
predict its measured motion, at nested training sizes, fit a n^-b + c): on the map
loops the held-out paths are the extremes of what is recorded (D+, S+), whose error is
an extrapolation (10 mm against about 2 on the interpolated target) and moves up or
down by millimetres as one more trial arrives, so its slope says nothing about the
target's.

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
from suds_exp.plan.ensemble import MapEnsemble, count_cycles, cycle_blocks
from suds_exp.plan.recommend import bias_variance, recommend_map, recorded_paths
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
    trained = np.full((N_FOLDS, len(sizes)), np.nan)
    for i, held in enumerate(folds):
        rest = [j for j in order if j not in set(held)]
        test = [blocks[j] for j in held]
        for s, n in enumerate(sizes):
            train = pd.concat([blocks[j] for j in rest[:n]], ignore_index=True)
            errors[i, s] = _rms_vx(fit_map(train, learner), test)
            trained[i, s] = count_cycles(train)
    mean = errors.mean(axis=0)
    spread = errors.std(axis=0, ddof=1) / np.sqrt(N_FOLDS)
    drop = float(mean[-2] - mean[-1]) if len(sizes) > 1 else None
    # training sizes in the cycles the user recorded (mean over folds), not in blocks
    cycles = [float(c) for c in trained.mean(axis=0)]
    doubling = (
        f"the last doubling of cycles ({cycles[0]:.0f} -> {cycles[-1]:.0f} of the "
        f"{count_cycles(samples):.0f} recorded, the rest held out)"
    )
    if drop is None:
        stop, message = False, "too few cycles for two training sizes: record more"
    elif drop < spread[-1]:
        stop = True
        message = (
            f"stop: {doubling} lowered the held-out error by {drop:.2f} mm/s, less than its "
            f"spread {spread[-1]:.2f} mm/s; more data of this kind will not help"
        )
    else:
        stop = False
        message = (
            f"continue: {doubling} lowered the held-out error by {drop:.2f} mm/s, more than "
            f"its spread {spread[-1]:.2f} mm/s"
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
    first_half = pd.concat(blocks[:half], ignore_index=True)
    first = fit_map(first_half, learner)
    sq = []
    for g, f in target.pairs():
        a, b = first.motion(g, f), ensemble.point.motion(g, f)
        sq.append((a.forward_mm - b.forward_mm) ** 2 + (a.lateral_mm - b.lateral_mm) ** 2)
    change = float(np.sqrt(np.mean(sq)))
    variance = [ensemble.displacement_spread([g], f)[0] for g, f in target.pairs()]
    spread = float(np.sqrt(np.mean(variance)))
    sizes = [count_cycles(first_half), count_cycles(samples)]
    doubling = f"the last doubling of cycles ({sizes[0]:.0f} -> {sizes[1]:.0f})"
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
    return StopSignal(stop, message, sizes, [], [], None,
                      change, spread)  # fmt: skip


#: Draws of the target's unknown truth under the planner's model that the error's
#: bootstrap spread is averaged over (`error_spread`); cheap (arrays of a few numbers).
TRUTH_DRAWS = 200


def error_spread(
    members: np.ndarray, point: np.ndarray, variance: np.ndarray, seed: int = 0,
    draws: int = TRUTH_DRAWS,
) -> float:  # fmt: skip
    """The bootstrap standard deviation (mm) of the target's RMS error, as the planner's
    model expects it, from the user's data alone.

    members: the bootstrap refits' net displacement per cycle (forward, lateral; mm) at
    each target pair, (B, T, 2); point: the full fit's, (T, 2); variance: the model's
    expected squared error of the point fit at each pair (mm^2, bootstrap noise plus
    path-jackknife bias), (T,). The truth is unknown; under the model it is the point
    prediction plus an error drawn N(0, variance / 2) in each of forward and lateral.
    For each of ``draws`` such truths (seeded by ``seed``), each refit's error is the
    RMS over the target of its distance from the truth, as the measured curve's is; the
    spread is the root mean over the draws of those errors' variance across refits
    (ddof 1). 0 with fewer than two refits."""
    members = np.asarray(members, float)
    point = np.asarray(point, float)
    if members.shape[0] < 2:
        return 0.0
    sd = np.sqrt(np.maximum(np.asarray(variance, float), 0.0) / 2)[None, :, None]
    truths = point[None] + np.random.default_rng([seed, 44]).normal(
        size=(draws, *point.shape)
    ) * sd  # fmt: skip
    # (draws, B): each refit's RMS error over the target against each drawn truth
    errors = np.sqrt(np.mean(np.sum((members[None] - truths[:, None]) ** 2, axis=3), axis=2))
    return float(np.sqrt(np.mean(errors.var(axis=1, ddof=1))))


@dataclass
class Doubling:
    """The forecast of the next doubling: the expected RMS error (mm per cycle) over the
    target before and after it as the planner's variance model says, and the error's
    bootstrap spread (mm). ``removable`` (0..1) is the share of the variance now that
    data can remove at all (`removable_share`; 1, the model's own view, when not
    calibrated): the model's forecast removes its fraction of that share only.
    ``drop_mm`` is the drop so calibrated; ``stop`` when it is less than the spread."""

    before_mm: float
    after_mm: float
    spread_mm: float
    removable: float = 1.0

    @property
    def forecast_drop_mm(self) -> float:
        """The model's drop, uncalibrated (mm)."""
        return self.before_mm - self.after_mm

    @property
    def drop_mm(self) -> float:
        b2, a2 = self.before_mm**2, self.after_mm**2
        return float(self.before_mm - np.sqrt(max(0.0, b2 - self.removable * (b2 - a2))))

    @property
    def stop(self) -> bool:
        return self.drop_mm < self.spread_mm


def forecast_doubling(
    members: np.ndarray, point: np.ndarray, variance: np.ndarray, removed: float,
    seed: int = 0,
) -> Doubling:  # fmt: skip
    """The issue's "flattens" test applied to the planner's forecast: the expected error
    is sqrt(V / T) for the total variance V = sum(variance) (mm^2) over the T target
    pairs, after the doubling sqrt((V - removed) / T), against `error_spread` of
    ``members``, ``point`` and ``variance`` (shapes as there). Not calibrated."""
    variance = np.asarray(variance, float)
    total = float(variance.sum())
    removed = min(total, max(0.0, float(removed)))
    return Doubling(
        float(np.sqrt(total / len(variance))),
        float(np.sqrt((total - removed) / len(variance))),
        error_spread(members, point, variance, seed),
    )


def removable_share(half: Doubling, before_now_mm: float) -> float:
    """The share (0..1) of the variance now that data can remove, from the doubling just
    recorded (see the module docstring). ``half``: the model's forecast made on the first
    half of the cycles (its doubling is the second half); ``before_now_mm``: the model's
    expected error on all of them (mm).

    Per target pair (mm^2): the model expected to remove the fraction
    q = 1 - after^2 / before^2 of its variance V_h at half; the variance fell by
    D = V_h - V_now. If q is right for the part A_h of V_h that data remove and the rest
    is a floor, A_h = D / q (clipped to [0, V_h]) and A_h (1 - q) is left removable now;
    the share is that over V_now, clipped to [0, 1]. 1 (no calibration) when the half's
    forecast removes nothing."""
    v_half, v_now = half.before_mm**2, before_now_mm**2
    q = 1.0 - half.after_mm**2 / v_half if v_half > 0 else 0.0
    if q <= 0 or v_now <= 0:
        return 1.0
    a_half = float(np.clip((v_half - v_now) / q, 0.0, v_half))
    return float(np.clip(a_half * (1.0 - q) / v_now, 0.0, 1.0))


def _forecast(samples, ensemble, target, cycles, learner, bias, seed):
    """The uncalibrated `Doubling` of ``samples`` (see `forecast_signal`), the trials
    planned for it and the cycles recorded (`count_cycles`, rounded)."""
    pairs = target.pairs()
    n = round(count_cycles(samples))
    trials = max(1, round(n / cycles))
    if bias is None:
        bias = bias_variance(samples, target, learner, ensemble.point)
    members, point = ensemble.displacements(pairs)
    noise = members.var(axis=0, ddof=1).sum(axis=1) if len(members) > 1 else np.zeros(len(pairs))
    recs = recommend_map(ensemble, target, cycles, trials, samples, learner, bias)
    d = forecast_doubling(members, point, noise + bias, sum(r.score for r in recs), seed)
    return d, recs, n


def forecast_signal(
    samples: pd.DataFrame,
    ensemble: MapEnsemble,
    target: Target,
    cycles: int,
    learner: str = GMR,
    bias: np.ndarray | None = None,
    seed: int = 0,
) -> StopSignal:
    """The map goal's stopping signal (see the module docstring): the expected drop (mm
    per cycle) of the target's RMS prediction error over the next doubling of the
    recorded cycles, spent on the trials of ``cycles`` cycles `recommend_map` would
    choose, calibrated by what the last doubling removed, against the bootstrap spread
    (mm) of that error.

    The variance per target pair is ``ensemble``'s bootstrap variance plus the
    path-jackknife bias (``bias`` when the caller has it); the trials remove what their
    scores say (`forecast_doubling`). The same forecast made on the first half of the
    cycle blocks (recording order; its own ``len(ensemble.members)`` refits) gives the
    share of the variance now that data can remove (`removable_share`), which the
    drop is calibrated by; uncalibrated while the half holds fewer than two recorded
    paths.
    ``change_mm`` is the calibrated drop, ``spread_mm`` the spread, ``cycles`` [now,
    after the doubling]; ``seed`` seeds the spread's draws and the half's refits."""
    d, recs, n = _forecast(samples, ensemble, target, cycles, learner, bias, seed)
    half_note = ""
    blocks = cycle_blocks(samples)
    half = pd.concat(blocks[: len(blocks) // 2], ignore_index=True) if len(blocks) > 1 else None
    # with one path the model's error is its prior (the motion itself), not a measurement:
    # nothing to calibrate by
    if half is not None and len(recorded_paths(half)) >= 2:
        half_ens = MapEnsemble.fit(half, learner, len(ensemble.members), seed + 1)
        h, _, m = _forecast(half, half_ens, target, cycles, learner, None, seed + 1)
        d.removable = removable_share(h, d.before_mm)
        half_note = (
            f"; the planner's model says {d.forecast_drop_mm:.2f}, but the last doubling "
            f"({m} -> {n} cycles) took it from {h.before_mm:.2f} to {d.before_mm:.2f} where "
            f"the model expected {h.after_mm:.2f}, so {100 * d.removable:.0f} % of its "
            "variance now is removable"
        )
    doubling = (
        f"the next doubling of cycles ({n} -> {n + len(recs) * cycles}, the {len(recs)} "
        f"trials planned) is expected to lower the target's prediction error by "
        f"{d.drop_mm:.2f} mm per cycle ({d.before_mm:.2f} now{half_note})"
    )
    if d.stop:
        message = (
            f"stop: {doubling}, less than that error's bootstrap spread {d.spread_mm:.2f} mm; "
            "more data of this kind will not help"
        )
    else:
        message = (
            f"continue: {doubling}, more than that error's bootstrap spread {d.spread_mm:.2f} mm"
        )
    return StopSignal(d.stop, message, [float(n), float(n + len(recs) * cycles)],
                      [], [], None, d.drop_mm, d.spread_mm)  # fmt: skip


@dataclass
class Flattening:
    """Where a learning curve flattens by the definition "the next doubling of cycles
    lowers the error by less than its bootstrap spread", tested at each count c whose
    doubling the curve reaches. ``tested``: (c, holds) in order; ``first``: the first c
    where it holds; ``flat_from``: the first c from which it holds at every tested count
    (None when it holds nowhere / fails at the last)."""

    tested: list[tuple[float, bool]]
    first: float | None
    flat_from: float | None


def flattening(cycles, error, spread) -> Flattening:
    """The definition (`Flattening`) on a curve: ``cycles`` the counts (increasing),
    ``error`` the error at each (mm), ``spread`` its bootstrap standard deviation there
    (mm). The drop of count c is the error at c less the error at the first count
    >= 2 c."""
    cycles, error, spread = (np.asarray(a, float) for a in (cycles, error, spread))
    tested = []
    for i, c in enumerate(cycles):
        later = np.flatnonzero(cycles >= 2 * c)
        if c > 0 and later.size:
            tested.append((float(c), bool(error[i] - error[later[0]] < spread[i])))
    first = next((c for c, holds in tested if holds), None)
    flat_from = next((c for i, (c, _) in enumerate(tested) if all(h for _, h in tested[i:])), None)
    return Flattening(tested, first, flat_from)


def within(fired: float | None, at: float | None, share: float = 0.2) -> bool | None:
    """Whether a signal first fired at ``fired`` cycles is within ``share`` of ``at``
    (None when either is None)."""
    if fired is None or at is None:
        return None
    return bool(abs(fired - at) <= share * at)


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
