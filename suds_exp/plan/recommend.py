"""Which trial to record next, and why.

Two goals:

- ``"map"``: learn the map well over a target set (`Target`). The candidates are the
  declared levels (the paper's gaits at its frequencies) and the target's own gait files.
  A trial's value is the expected reduction of the prediction variance integrated over
  the target's paths. Each target's bootstrap variance (mm^2, net displacement per
  cycle) is spread evenly over the samples of its path; a path sample's variance falls
  like that of a local mean, as 1/n in the cycles n recorded near it (each cycle
  weighted by a Gaussian kernel of its distance in the (shape, direction of shape
  velocity) metric of `suds_exp.gait.support`), so a trial bringing m such cycles there
  removes the share m / (n0 + n + m) of it (n0 = `PRIOR_CYCLES`, the prior's worth). The
  kernel's length-scale is the candidates' spacing (`candidate_spacing`: the widest gap
  from a candidate's path to its nearest neighbour's): the learner interpolates between
  neighbouring paths, so a cycle informs the map as far as the next candidate's path.
  A cycle at another frequency than the target's counts half (the map is
  rate-independent only as far as the robot is). What is already recorded is so
  discounted, a path sample far from all data keeps nearly all its variance for the
  first trial that comes near, and a batch of ``n`` trials is chosen greedily, each
  scored as if the ones before it were recorded.

  Why not the bootstrap alone: the cycle bootstrap sees the noise of what is recorded,
  not the bias of a map that has seen only a few paths (after 35 cycles of three gaits
  its variance over the default target was about 5 mm^2 against a squared error near
  40 mm^2), so on its own it keeps choosing the paths nearest the target. The score
  therefore adds a bias term: how much each target's prediction depends on which paths
  were recorded, measured by the path jackknife (`bias_variance`: leave each recorded
  (gait, frequency) out, refit, predict the target). Like a jackknife variance it falls
  as 1/k in the k distinct paths recorded, so a trial on a new path removes the share
  w / (k + w) of it (w = 1 at the target's frequency, `OTHER_FREQUENCY_WEIGHT` at
  another) and a repeat of a recorded path removes none: more cycles of a path lower
  the noise, not the bias between paths. The two terms add.
- ``"gait"``: the best forward displacement per cycle within the bound. The next trial is
  a new Fourier gait (written to a file) that maximises the upper confidence bound
  (point prediction + `KAPPA` x spread) inside the joint bound and inside a trust region
  around the recorded data (the designer's `optimise_gait`); its reason is the expected
  improvement over the best recorded gait under a normal prediction. The spread is the
  bootstrap's and the path jackknife's together (`MapEnsemble.forward` of an ensemble
  fitted with ``paths=True``): the bootstrap alone does not see how much a new gait's
  prediction depends on which gaits were recorded. When that step's predicted gain is
  below its spread, the map cannot resolve it: the
  trust-region search has converged on a local optimum of the map as learned so far. The
  same bound is then searched whole (`_look_beyond`; the refits' spread grows away from
  the data, so the upper bound rewards exploring where the map has not been told), and
  the gait with the larger expected improvement of the two is recommended. A look beyond
  is an extrapolation by design; the best gait reported is always a recorded one, so no
  unrecorded prediction reaches the answer. Both searches also start from loops traced
  2 .. ``order`` times a cycle (`suds_exp.gait.design.traced_starts`): a local search
  from a loop traced once keeps its zero harmonics near zero, and on a rate-independent
  body a loop traced k times a cycle moves about k times as far per cycle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.spatial import cKDTree

from suds_exp.gait.design import circle, optimise_gait, traced_starts
from suds_exp.gait.predict import fit_map
from suds_exp.gait.shape import TWO_PI, FourierGait, Gait, paper_gaits, within_bound
from suds_exp.gait.support import SHAPE_RADIUS, Support, actuated_columns, direction_features
from suds_exp.models.registry import GMR
from suds_exp.plan.ensemble import (
    MapEnsemble,
    count_cycles,
    jackknife_variance,
    leave_path_out,
    path_hz,
    recorded_paths,
)
from suds_exp.plan.target import Target
from suds_exp.robot import FREQUENCIES_HZ

#: Weight of the bootstrap spread in the gait goal's upper confidence bound.
KAPPA = 1.0
#: Length-scale (rad, the support metric) of `nearness` when the candidates give none
#: (a single candidate path): the support's own radius.
VISIT_RADIUS = SHAPE_RADIUS
#: Starting lags (rad) of the gait search's circles beside the best recorded gait.
START_LAGS_RAD = (-0.6, 0.0, 0.6)
#: The look over the whole bound: circles of these radii (fractions of the bound) at
#: these lags (rad), each traced 1 .. order times a cycle, are scored first, and the
#: search starts from the `GLOBAL_STARTS` best of them (a grid of single loops, chosen as
#: the span of amplitude and tilt, not from any simulated result).
GLOBAL_RADII_OF_BOUND = (0.5, 0.75, 1.0)
GLOBAL_LAGS_RAD = (-1.2, -0.9, -0.6, -0.3, 0.0, 0.3, 0.6, 0.9, 1.2)
GLOBAL_STARTS = 2


@dataclass
class Trial:
    """A trial to record: a gait (a declared level's name, or a gait whose file is
    ``file``), frequency_hz (Hz) and cycles."""

    gait: Gait
    frequency_hz: float
    cycles: int
    file: str | None = None

    def to_dict(self) -> dict:
        return {
            "gait": self.file or self.gait.name,
            "frequency_hz": round(float(self.frequency_hz), 6),
            "cycles": int(self.cycles),
        }


@dataclass
class Recommendation:
    """A trial and why: ``score`` in ``unit`` (mm^2 of variance removed, or mm per cycle
    of expected improvement), ``reason`` the sentence."""

    trial: Trial
    score: float
    unit: str
    reason: str
    predicted_forward_mm: float | None = None
    spread_mm: float | None = None

    def to_dict(self) -> dict:
        out = {"trial": self.trial.to_dict(), "score": round(float(self.score), 4)}
        out |= {"unit": self.unit, "reason": self.reason}
        if self.predicted_forward_mm is not None:
            out["predicted_forward_mm"] = round(float(self.predicted_forward_mm), 3)
            out["spread_mm"] = round(float(self.spread_mm or 0.0), 3)
        return out


def _path_features(gait: Gait, n: int = 64) -> np.ndarray:
    theta = TWO_PI * np.arange(n) / n
    return direction_features(gait.shape(theta), gait.rate(theta))


def declared_levels() -> list[tuple[Gait, float]]:
    """The paper's declared levels: every gait at every frequency (Hz), in its order."""
    return [(g, f) for g in paper_gaits() for f in FREQUENCIES_HZ]


#: The prior's worth in cycles: a path sample's variance is that of a local mean with
#: this many cycles' precision before any data (so a far trial's tiny weight cannot
#: claim a whole unvisited sample's variance).
PRIOR_CYCLES = 1.0
#: Weight of a recorded or planned cycle at another frequency than a target's.
OTHER_FREQUENCY_WEIGHT = 0.5


def nearness(distance: np.ndarray, scale: float = VISIT_RADIUS) -> np.ndarray:
    """Weight (0..1) of a cycle at ``distance`` (rad, support metric) from a path sample:
    exp(-d^2 / 2 scale^2), scale in rad."""
    return np.exp(-0.5 * (np.asarray(distance, float) / scale) ** 2)


def candidate_spacing(gaits: list[Gait], n: int = 64) -> float:
    """The widest gap (rad, support metric) from a sample of one candidate path to the
    nearest other candidate path, over the distinct paths of ``gaits``; `VISIT_RADIUS`
    for fewer than two paths."""
    paths = {g.name: _path_features(g, n) for g in gaits}
    if len(paths) < 2:
        return VISIT_RADIUS
    widest = 0.0
    for name, path in paths.items():
        others = np.vstack([p for k, p in paths.items() if k != name])
        widest = max(widest, float(cKDTree(others).query(path)[0].max()))
    return widest or VISIT_RADIUS


def _frequency_weight(a: float, b: float) -> float:
    return 1.0 if path_hz(a) == path_hz(b) else OTHER_FREQUENCY_WEIGHT


def recorded_cycles_near(
    samples: pd.DataFrame | None, target: Target, n: int = 64, scale: float = VISIT_RADIUS
) -> np.ndarray:
    """Recorded cycles near each sample of each target path: (len(target.pairs()), n);
    scale: `nearness`'s length-scale, rad.

    A trial counts its cycles at each path sample, weighted by `nearness` of its nearest
    sample and by `OTHER_FREQUENCY_WEIGHT` off the target's frequency."""
    pairs = target.pairs()
    out = np.zeros((len(pairs), n))
    if samples is None or samples.empty:
        return out
    paths = [_path_features(g, n) for g, _ in pairs]
    ra_cols, dra_cols = actuated_columns(samples)
    for _, trial in samples.groupby("trial_id"):
        feats = direction_features(trial[ra_cols].to_numpy(float), trial[dra_cols].to_numpy(float))
        tree = cKDTree(feats)
        cycles = count_cycles(trial)
        freq = float(trial["frequency_hz"].iloc[0])
        for k, ((_, f), path) in enumerate(zip(pairs, paths, strict=True)):
            near = nearness(tree.query(path)[0], scale)
            out[k] += cycles * _frequency_weight(freq, f) * near
    return out


def _displacement(fitted, gait: Gait, frequency_hz: float) -> np.ndarray:
    m = fitted.motion(gait, frequency_hz)
    return np.array([m.forward_mm, m.lateral_mm])


def paths_worth(paths: list[tuple[str, float]], frequency_hz: float) -> float:
    """The recorded paths' worth to a target at frequency_hz (Hz): one a distinct gait
    at that frequency, `OTHER_FREQUENCY_WEIGHT` one at another frequency."""
    return float(sum(_frequency_weight(f, frequency_hz) for _, f in paths))


def bias_variance(
    samples: pd.DataFrame | None, target: Target, learner: str = GMR, point=None
) -> np.ndarray:
    """The variance (mm^2, net displacement per cycle, forward and lateral together) of
    each target's prediction over which paths were recorded: the path jackknife. Each
    recorded path (`recorded_paths`: gait and frequency) is left out in turn, the
    learner refitted without its trials, and the target predicted; the variance is
    (k - 1) / k times the sum of the squared deviations of those k predictions from
    their mean. With fewer than two paths there is nothing to leave out: the squared
    displacement ``point`` (the `FittedMap` on all the samples; fitted here when None)
    predicts for the target (a map that has seen one path errs elsewhere by the order
    of the motion itself). Zeros without samples. Shape (len(target.pairs()),)."""
    pairs = target.pairs()
    paths = recorded_paths(samples)
    if not paths:
        return np.zeros(len(pairs))
    if len(paths) < 2:
        point = point if point is not None else fit_map(samples, learner)
        return np.array([float(_displacement(point, g, f) @ _displacement(point, g, f))
                         for g, f in pairs])  # fmt: skip
    preds = []
    for without in leave_path_out(samples):
        fitted = fit_map(without, learner)
        preds.append([_displacement(fitted, g, ft) for g, ft in pairs])
    return jackknife_variance(np.array(preds)).sum(axis=1)  # (k, targets, 2) -> (targets,)


def recommend_map(
    ensemble: MapEnsemble,
    target: Target,
    cycles: int,
    n: int = 1,
    samples: pd.DataFrame | None = None,
    learner: str = GMR,
    bias: np.ndarray | None = None,
) -> list[Recommendation]:
    """The ``n`` trials of ``cycles`` cycles that remove the most prediction variance
    over the target (see the module docstring): the noise term integrated over the
    target's paths plus the bias term, chosen greedily, in that order. ``samples``: the
    recorded data (the version's frame) whose cycles near each path sample discount a
    new trial's and whose paths give the bias term (refitted with ``learner``); None
    counts none and adds no bias term; ``bias``: `bias_variance` of ``samples`` when
    the caller has it (computed here when None)."""
    pairs = target.pairs()
    n_path = 64
    variance = np.array([ensemble.displacement_spread([g], f)[0] for g, f in pairs])
    per_sample = np.repeat(variance[:, None] / n_path, n_path, axis=1)
    candidates = declared_levels() + [
        (g, f)
        for g, file in zip(target.gaits, target.files, strict=False)
        for f in target.frequencies_hz
    ]
    scale = candidate_spacing([g for g, _ in candidates], n_path)
    recorded = recorded_cycles_near(samples, target, n_path, scale)
    if bias is None:
        bias = bias_variance(samples, target, learner, ensemble.point)
    covered = recorded_paths(samples)
    paths = [_path_features(g, n_path) for g, _ in pairs]
    brings, reach = [], []
    for gait, freq in candidates:
        tree = cKDTree(_path_features(gait, n_path))
        visited = np.array([nearness(tree.query(path)[0], scale) for path in paths])
        weights = np.array([_frequency_weight(freq, f) for _, f in pairs])
        brings.append(cycles * weights[:, None] * visited)
        reach.append(int(np.sum(visited.max(axis=1) > 0.5)))
    recs: list[Recommendation] = []
    taken: set[int] = set()
    for _ in range(min(n, len(candidates))):
        noise = np.full(len(candidates), -np.inf)
        between = np.zeros(len(candidates))
        worth = np.array([paths_worth(covered, f) for _, f in pairs])
        for i, m in enumerate(brings):
            if i in taken:
                continue
            noise[i] = float(np.sum(per_sample * m / (PRIOR_CYCLES + recorded + m)))
            gait, freq = candidates[i]
            if (gait.name, path_hz(freq)) not in covered and worth.min() > 0:
                w = np.array([_frequency_weight(freq, f) for _, f in pairs])
                between[i] = float(np.sum(bias * w / (worth + w)))
        removed = noise + between
        i = int(np.argmax(removed))
        m = brings[i]
        near = recorded[m > 0.5 * m.max()]
        gait, freq = candidates[i]
        reason = (
            f"expected to remove {removed[i]:.2f} mm^2 of the target's prediction variance "
            f"of {per_sample.sum() + bias.sum():.2f}: {noise[i]:.2f} of its noise "
            f"(bootstrap) and {between[i]:.2f} of its bias between paths (path jackknife "
            f"over {len(covered)} recorded paths; {reach[i]} of {len(pairs)} targets "
            f"visited, where {float(near.mean()) if near.size else 0.0:.1f} cycles are "
            "recorded on average)"
        )
        trial = Trial(gait, freq, cycles, _file_of(gait, target))
        recs.append(Recommendation(trial, float(removed[i]), "mm^2", reason))
        # the next pick is scored as if this one were recorded
        per_sample = per_sample * (PRIOR_CYCLES + recorded) / (PRIOR_CYCLES + recorded + m)
        recorded = recorded + m
        if (gait.name, path_hz(freq)) not in covered and worth.min() > 0:
            w = np.array([_frequency_weight(freq, f) for _, f in pairs])
            bias = bias * worth / (worth + w)
            covered = covered + [(gait.name, path_hz(freq))]
        taken.add(i)
    return recs


def _file_of(gait: Gait, target: Target) -> str | None:
    for g, file in zip(target.gaits, target.files, strict=False):
        if g is gait:
            return file
    return None


def expected_improvement(mean: float, sd: float, best: float) -> float:
    """E[max(F - best, 0)] for F ~ N(mean, sd^2), mm."""
    if sd <= 0:
        return max(mean - best, 0.0)
    z = (mean - best) / sd
    cdf = 0.5 * (1 + math.erf(z / math.sqrt(2)))
    pdf = math.exp(-0.5 * z * z) / math.sqrt(2 * math.pi)
    return (mean - best) * cdf + sd * pdf


def recommend_gait(
    ensemble: MapEnsemble,
    support: Support,
    recorded: list[Gait],
    target: Target,
    trust: float,
    cycles: int,
    name: str,
    order: int = 2,
    max_evals: int = 150,
) -> tuple[Recommendation, Gait, float]:
    """The next gait trial of the gait goal (see the module docstring) and the best
    recorded gait with its point prediction (mm per cycle).

    support: the recorded data's; recorded: the gaits recorded so far; trust: the trust
    radius (rad, support metric); name: the new gait's name (its file's name)."""
    freq = target.frequencies_hz[0]
    preds = [ensemble.forward(g, freq)[0] for g in recorded]
    i_best = int(np.argmax(preds))
    best_gait, best_value = recorded[i_best], float(preds[i_best])

    def ucb(g: Gait) -> float:
        mean, sd = ensemble.forward(g, freq)
        return mean + KAPPA * sd

    starts = [
        circle(1.0, order, lag=lag, traces=k) for k in range(1, order + 1) for lag in START_LAGS_RAD
    ]
    if isinstance(best_gait, FourierGait) and best_gait.order == order:
        starts[:0] = [best_gait, *traced_starts([best_gait], order)]
    starts = [_inside(g, support, target.bound, trust) for g in starts]
    gait, _ = optimise_gait(ucb, support, target.bound, trust, starts, max_evals, name)
    mean, sd = ensemble.forward(gait, freq)
    ei = expected_improvement(mean, sd, best_value)
    where = f"trust radius {trust:.2f} rad"
    if mean - best_value < sd:
        # The map cannot tell the best step inside the trust region from standing still:
        # the local search has converged on the map as learned so far. Look over the whole
        # bound, where the refits' spread grows away from the data and earns exploration;
        # the trial's own recording then teaches the map there.
        far = _look_beyond(ucb, support, target.bound, order, max_evals, name, [gait, best_gait])
        far_mean, far_sd = ensemble.forward(far, freq)
        far_ei = expected_improvement(far_mean, far_sd, best_value)
        if far_ei > ei:
            where = (
                f"beyond the trust radius {trust:.2f} rad, whose best step was predicted "
                f"{mean:.1f} +/- {sd:.1f} (expected improvement {ei:.2f})"
            )
            gait, mean, sd, ei = far, far_mean, far_sd, far_ei
    reason = (
        f"predicted {mean:.1f} +/- {sd:.1f} mm/cycle against the best recorded gait's "
        f"{best_value:.1f}: expected improvement {ei:.2f} mm/cycle ({where})"
    )
    rec = Recommendation(Trial(gait, freq, cycles, name), ei, "mm/cycle", reason, mean, sd)
    return rec, best_gait, best_value


def _look_beyond(
    objective,
    support: Support,
    bound: float,
    order: int,
    max_evals: int,
    name: str,
    seeds: list[Gait],
) -> FourierGait:
    """The gait maximising ``objective`` (mm) within the joint bound alone (rad): the
    circles of `GLOBAL_RADII_OF_BOUND` x `GLOBAL_LAGS_RAD`, traced 1 .. ``order`` times a
    cycle, and ``seeds`` (Fourier gaits of ``order``; others are left out) and the seeds
    traced again (`traced_starts`) are scored, and the search starts from the
    `GLOBAL_STARTS` best."""
    grid = [
        within_bound(circle(f * bound, order, lag=lag, traces=k), bound)
        for k in range(1, order + 1)
        for f in GLOBAL_RADII_OF_BOUND
        for lag in GLOBAL_LAGS_RAD
    ]
    seeds = [g for g in seeds if isinstance(g, FourierGait) and g.order == order]
    grid += seeds + traced_starts(seeds, order)
    scores = [objective(g) for g in grid]
    starts = [grid[i] for i in np.argsort(scores)[::-1][:GLOBAL_STARTS]]
    gait, _ = optimise_gait(objective, support, bound, np.inf, starts, max_evals, name)
    return gait


def _inside(gait: FourierGait, support: Support, bound: float, trust: float) -> FourierGait:
    """The start shrunk towards its centre until it is inside the bound and the trust
    region (the designer's rule); as it is when no shrinking gets it there."""
    gait = within_bound(gait, bound)
    for scale in np.linspace(1.0, 0.3, 15):
        x = gait.to_vector().copy()
        x[2:] *= scale
        g = FourierGait.from_vector(x, gait.name)
        if support.gait_distance(g) <= trust:
            return g
    return gait
