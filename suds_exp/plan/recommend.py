"""Which trial to record next, and why.

Two goals:

- ``"map"``: learn the map well over a target set (`Target`). The candidates are the
  declared levels (the paper's gaits at its frequencies) and the target's own gait files.
  A trial's value is the expected reduction of the prediction uncertainty over the
  target: the bootstrap variance (mm^2) of each target's net displacement per cycle,
  times the share of that target's path the trial would visit (in the (shape, direction
  of shape velocity) metric of `suds_exp.gait.support`; recorded data make a map's
  bootstrap spread collapse where they are), summed over the target. A trial at another
  frequency than a target's counts half for it: the map is rate-independent only as far
  as the robot is.
- ``"gait"``: the best forward displacement per cycle within the bound. The next trial is
  a new Fourier gait (written to a file) that maximises the upper confidence bound
  (point prediction + `KAPPA` x bootstrap spread) inside the joint bound and inside a
  trust region around the recorded data (the designer's `optimise_gait`); its reason is
  the expected improvement over the best recorded gait under a normal prediction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from suds_exp.gait.design import circle, optimise_gait
from suds_exp.gait.shape import TWO_PI, FourierGait, Gait, paper_gaits, within_bound
from suds_exp.gait.support import SHAPE_RADIUS, Support, direction_features
from suds_exp.plan.ensemble import MapEnsemble
from suds_exp.plan.target import Target
from suds_exp.robot import FREQUENCIES_HZ

#: Weight of the bootstrap spread in the gait goal's upper confidence bound.
KAPPA = 1.0
#: Share of a target's path a trial visits: its samples within this distance (rad, the
#: support metric) of the trial's path.
VISIT_RADIUS = SHAPE_RADIUS
#: Starting lags (rad) of the gait search's circles beside the best recorded gait.
START_LAGS_RAD = (-0.6, 0.0, 0.6)


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


def visited_share(candidate: Gait, target: Gait) -> float:
    """Share (0..1) of ``target``'s path within `VISIT_RADIUS` of ``candidate``'s."""
    d = cKDTree(_path_features(candidate)).query(_path_features(target))[0]
    return float(np.mean(d <= VISIT_RADIUS))


def declared_levels() -> list[tuple[Gait, float]]:
    """The paper's declared levels: every gait at every frequency (Hz), in its order."""
    return [(g, f) for g in paper_gaits() for f in FREQUENCIES_HZ]


def recommend_map(
    ensemble: MapEnsemble, target: Target, cycles: int, n: int = 1
) -> list[Recommendation]:
    """The ``n`` trials of ``cycles`` cycles that remove the most bootstrap variance of
    the target's predictions (see the module docstring), best first."""
    pairs = target.pairs()
    variance = np.array([ensemble.displacement_spread([g], f)[0] for g, f in pairs])
    candidates = declared_levels() + [
        (g, f)
        for g, file in zip(target.gaits, target.files, strict=False)
        for f in target.frequencies_hz
    ]
    recs = []
    for gait, freq in candidates:
        shares = np.array(
            [visited_share(gait, g) * (1.0 if math.isclose(f, freq) else 0.5) for g, f in pairs]
        )
        removed = float(np.sum(variance * shares))
        covered = int(np.sum(shares > 0))
        file = _file_of(gait, target)
        trial = Trial(gait, freq, cycles, file)
        reason = (
            f"expected to remove {removed:.2f} mm^2 of the target's prediction variance "
            f"({covered} of {len(pairs)} targets visited; total {variance.sum():.2f} mm^2)"
        )
        recs.append(Recommendation(trial, removed, "mm^2", reason))
    recs.sort(key=lambda r: -r.score)
    return recs[:n]


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

    starts = [circle(1.0, order, lag=lag) for lag in START_LAGS_RAD]
    if isinstance(best_gait, FourierGait) and best_gait.order == order:
        starts.insert(0, best_gait)
    starts = [_inside(g, support, target.bound, trust) for g in starts]
    gait, _ = optimise_gait(ucb, support, target.bound, trust, starts, max_evals, name)
    mean, sd = ensemble.forward(gait, freq)
    ei = expected_improvement(mean, sd, best_value)
    reason = (
        f"predicted {mean:.1f} +/- {sd:.1f} mm/cycle against the best recorded gait's "
        f"{best_value:.1f}: expected improvement {ei:.2f} mm/cycle (trust radius {trust:.2f} rad)"
    )
    rec = Recommendation(Trial(gait, freq, cycles, name), ei, "mm/cycle", reason, mean, sd)
    return rec, best_gait, best_value


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
