"""Discovery: a sparse learned correction for the gap no named effect explains.

The correction is additive on each replayed channel (body velocity vx, vy, wz and, when
compared, the passive-shape coordinates r_p):

    channel_model = channel_replay + sum_j xi_j * feature_j

with the features of `features.feature_library`. It reuses the one replay of the current
model (no replay per feature): the target is the replay's residual, measured minus
replayed, divided by the channel's loss scale. Per channel:

1. the features are scaled by their RMS over the training samples; orthogonal matching
   pursuit (scikit-learn) gives the nested supports of 1..``max_terms`` terms;
2. the number of terms is chosen by grouped cross-validation over the training trials
   (folds hold whole trials), the fewest terms whose error is within one standard error
   of the best (0 terms is a candidate: "no correction");
3. the chosen support is re-fitted by least squares on all training trials, and its
   coefficients get a percentile interval from a bootstrap over training trials.

The correction is then judged like a named effect, on the held-out trials only: the
one-sided paired t-test over held-out trials that the relative loss reduction exceeds
``min_improvement``, at ``alpha``. A correction that fails it is reported but not added.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from sklearn.linear_model import orthogonal_mp
from sklearn.model_selection import GroupKFold

from suds_exp.discrepancy.features import IN_CHANNEL_UNIT, PHYSICS, Feature, channel_unit
from suds_exp.discrepancy.fit_candidates import held_out_p, trial_losses
from suds_exp.discrepancy.replay import CHANNELS as BODY_CHANNELS
from suds_exp.errors import DiscrepancyError


@dataclass(frozen=True)
class DiscoverySettings:
    """Hyper-parameters of the sparse correction.

    Parameters
    ----------
    max_terms : int
        Largest number of terms per channel.
    n_folds : int
        Grouped cross-validation folds over training trials (at most one per trial).
    one_se : bool
        Choose the fewest terms within one standard error of the best CV error.
    n_boot : int
        Bootstrap replicates over training trials for the coefficient intervals.
    level : float
        Confidence level of those intervals.
    """

    max_terms: int = 4
    n_folds: int = 5
    one_se: bool = True
    n_boot: int = 200
    level: float = 0.95

    def __post_init__(self) -> None:
        if self.max_terms < 1:
            raise DiscrepancyError(f"max_terms {self.max_terms}: must be >= 1", param="max_terms")


@dataclass
class Term:
    """One term of the correction: ``coef * feature`` added to ``channel``."""

    channel: str
    feature: Feature
    coef: float
    ci: tuple[float, float]
    weight: float  # |coef| * feature RMS / channel loss scale: the term's share

    @property
    def unit(self) -> str:
        """Unit of the coefficient: channel unit per feature unit."""
        cu, fu = channel_unit(self.channel), self.feature.unit
        if IN_CHANNEL_UNIT in fu:
            # a feature in the channel's own unit: the coefficient carries the rest
            rest = fu.replace(IN_CHANNEL_UNIT, "").strip()
            if not rest:
                return "-"
            return f"1/({rest[1:]})" if rest.startswith("/") else f"1/({rest})"
        return cu if fu == "-" else f"{cu} / ({fu})"


@dataclass
class Discovery:
    """A fitted correction and its held-out verdict (losses are per held-out trial)."""

    channels: tuple[str, ...]
    features: list[Feature]
    coef: np.ndarray  # (n_channels, n_features), physical units; 0 off the support
    n_shared: int = -1  # the first n_shared features are shared; the rest per channel
    terms: list[Term] = field(default_factory=list)
    cv_terms: dict = field(default_factory=dict)  # channel -> chosen number of terms
    test_trials: np.ndarray = field(default_factory=lambda: np.zeros(0))
    test_before: np.ndarray = field(default_factory=lambda: np.zeros(0))
    test_after: np.ndarray = field(default_factory=lambda: np.zeros(0))
    p_value: float = 1.0
    significant: bool = False
    seconds: float = 0.0

    @property
    def improvement(self) -> float:
        """Fraction of the held-out loss the correction removes."""
        before = float(np.mean(self.test_before)) if len(self.test_before) else 0.0
        return 1.0 - float(np.mean(self.test_after)) / before if before > 0 else 0.0

    @property
    def leading(self) -> list[str]:
        """Feature names by total share over channels, largest first."""
        share: dict[str, float] = {}
        for t in self.terms:
            if t.feature.family != "constant":
                share[t.feature.name] = share.get(t.feature.name, 0.0) + t.weight
        return sorted(share, key=share.get, reverse=True)

    @property
    def physics(self) -> str:
        """What the correction most resembles, '' with no term: the physics
        (`features.PHYSICS`) whose terms carry the largest total share over all channels.
        By share, not by the single largest term: one effect shows in several channels
        (an inertia lags vx, vy and wz alike) and is not outvoted by one large term."""
        return self.physics_of(self.channels)

    @property
    def physics_by_part(self) -> dict[str, str]:
        """The same reading for the body velocity (vx, vy, wz) and for the passive shape
        (r_p) apart: an effect acts on one and shows in the other through the body's
        mechanics, so the two may read differently (asymmetric drag is a sign-dependent
        force on the body and reshapes the flippers' stroke), '' for a part with no term."""
        body = tuple(c for c in self.channels if c in BODY_CHANNELS)
        passive = tuple(c for c in self.channels if c not in BODY_CHANNELS)
        return {"body": self.physics_of(body), "passive": self.physics_of(passive)}

    def physics_of(self, channels) -> str:
        """The physics whose terms carry the largest total share over ``channels``."""
        share: dict[str, float] = {}
        for t in self.terms:
            if t.feature.family != "constant" and t.channel in channels:
                name = PHYSICS.get(t.feature.family, t.feature.family)
                share[name] = share.get(name, 0.0) + t.weight
        return max(share, key=share.get) if share else ""

    def equations(self) -> list[str]:
        """One line per corrected channel, e.g. ``vx += -0.19 [-0.21, -0.17] s * dv_x/dt``."""
        lines = []
        for ch in self.channels:
            terms = [t for t in self.terms if t.channel == ch]
            if not terms:
                continue
            parts = [
                f"{t.coef:+.4g} [{t.ci[0]:.3g}, {t.ci[1]:.3g}] {t.unit}"
                + ("" if t.feature.name == "1" else f" * {t.feature.name}")
                for t in terms
            ]
            lines.append(f"{ch} ({channel_unit(ch)}) += " + " ".join(parts))
        return lines

    def predict(self, X: np.ndarray, Xc: np.ndarray | None = None) -> np.ndarray:
        """The correction, (..., n_channels) in the channels' units, from the shared
        features X (..., n_shared) and the per-channel ones Xc (..., n_channels, n_rest);
        NaN features of unused columns do not matter."""
        n = self.coef.shape[1] if self.n_shared < 0 else self.n_shared
        shared = self.coef[:, :n]
        used = np.flatnonzero(np.any(shared != 0, axis=0))
        out = np.zeros(X.shape[:-1] + (len(self.channels),))
        if len(used):
            out = out + np.einsum("...f,cf->...c", X[..., used], shared[:, used])
        rest = self.coef[:, n:]
        if Xc is not None and np.any(rest != 0):
            out = out + np.nansum(np.where(rest != 0, Xc, 0.0) * rest, axis=-1)
        return out


def _support_path(X: np.ndarray, y: np.ndarray, max_terms: int) -> list[np.ndarray]:
    """Nested OMP supports of 1..max_terms columns of (already scaled) X."""
    k = min(max_terms, X.shape[1], max(len(y) - 1, 1))
    path = orthogonal_mp(X, y, n_nonzero_coefs=k, return_path=True)
    path = path.reshape(X.shape[1], -1)
    return [np.flatnonzero(path[:, j]) for j in range(path.shape[1])]


def _lstsq(X: np.ndarray, y: np.ndarray, support: np.ndarray) -> np.ndarray:
    coef = np.zeros(X.shape[1])
    if len(support):
        coef[support] = np.linalg.lstsq(X[:, support], y, rcond=None)[0]
    return coef


def _choose_terms(X, y, groups, settings: DiscoverySettings) -> np.ndarray:
    """Support chosen by grouped CV over the number of terms (see the module docstring)."""
    n_groups = len(np.unique(groups))
    folds = min(settings.n_folds, n_groups)
    if folds < 2:
        return np.zeros(0, int)
    errs = np.full((folds, settings.max_terms + 1), np.nan)
    for i, (tr, va) in enumerate(GroupKFold(n_splits=folds).split(X, y, groups)):
        errs[i, 0] = np.mean(y[va] ** 2)
        for j, sup in enumerate(_support_path(X[tr], y[tr], settings.max_terms)):
            coef = _lstsq(X[tr], y[tr], sup)
            errs[i, j + 1] = np.mean((y[va] - X[va] @ coef) ** 2)
    filled = ~np.all(np.isnan(errs), axis=0)
    mean = np.where(filled, np.nanmean(np.where(np.isnan(errs), np.inf, errs), axis=0), np.inf)
    best = int(np.argmin(mean))
    k = best
    if settings.one_se:
        se = np.nanstd(errs[:, best]) / np.sqrt(folds)
        k = int(np.flatnonzero(mean <= mean[best] + se)[0])
    if k == 0:
        return np.zeros(0, int)
    path = _support_path(X, y, k)
    return path[min(k, len(path)) - 1]


def _boot_intervals(X, y, groups, support, settings: DiscoverySettings, rng):
    """Percentile intervals of the support's coefficients over trial bootstraps."""
    trials, inv = np.unique(groups, return_inverse=True)
    Xs = X[:, support]
    G = np.zeros((len(trials), len(support), len(support)))
    b = np.zeros((len(trials), len(support)))
    np.add.at(G, inv, Xs[:, :, None] * Xs[:, None, :])
    np.add.at(b, inv, Xs * y[:, None])
    w = rng.multinomial(len(trials), np.full(len(trials), 1 / len(trials)), size=settings.n_boot)
    reps = []
    for wi in w:
        A = np.tensordot(wi, G, axes=1)
        try:
            reps.append(np.linalg.solve(A, wi @ b))
        except np.linalg.LinAlgError:
            continue
    reps = np.asarray(reps).reshape(-1, len(support))
    tail = (1 - settings.level) / 2
    return np.quantile(reps, tail, axis=0), np.quantile(reps, 1 - tail, axis=0)


@dataclass(frozen=True)
class Gap:
    """What a correction is fitted to and tested on: the current model's replay ``sim``
    and the measurement ``meas``, arrays (n_windows, n_samples, n_channels); the
    channels' loss ``scales`` (n_channels,); each window's ``trial_id`` (n_windows,); the
    ids of the ``train_trials`` (every other window is held out)."""

    sim: np.ndarray
    meas: np.ndarray
    scales: np.ndarray
    trial_id: np.ndarray
    train_trials: object

    @cached_property
    def is_train(self) -> np.ndarray:
        """(n_windows,) bool: the window is of a training trial."""
        return np.isin(self.trial_id, np.asarray(list(self.train_trials)))

    def remainder(self) -> np.ndarray:
        """(meas - sim) / scales, a row a sample: (n_windows * n_samples, n_channels)."""
        return ((self.meas - self.sim) / self.scales).reshape(-1, self.sim.shape[-1])

    def held_out(self, replays: np.ndarray, min_improvement: float):
        """(trials, losses (2, n_trials), p) of two ``replays`` (2, n_held_out_windows,
        n_samples, n_channels) of the held-out windows, before and after a correction:
        p of the one-sided test that the second removes more than ``min_improvement``
        of the first's loss (`held_out_p`)."""
        test = ~self.is_train
        trials, loss = trial_losses(replays, self.meas[test], self.scales, self.trial_id[test])
        return trials, loss, held_out_p(loss[0], loss[1], min_improvement)


def discover(
    X: np.ndarray,
    features: list[Feature],
    gap: Gap,
    channels: tuple[str, ...],
    alpha: float,
    min_improvement: float,
    settings: DiscoverySettings | None = None,
    rng: np.random.Generator | None = None,
    Xc: np.ndarray | None = None,
    channel_feats: list[Feature] = (),
) -> Discovery:
    """Fit the sparse correction on training trials and test it on the others.

    Parameters
    ----------
    X : array (n_windows, n_samples, n_features)
        `feature_library` of the windows (shared by every channel).
    gap : Gap
        The current model's replay and the measurement (channels as `replay`), the
        workflow's loss scales and the training trials.
    channels : names of the channels.
    alpha, min_improvement : the held-out test's level and margin (as for candidates).
    Xc : array (n_windows, n_samples, n_channels, n_rest), optional
        Features that differ per channel (`features.channel_features`,
        `features.effect_features`), described by ``channel_feats``.
    """
    started = time.perf_counter()
    s = settings or DiscoverySettings()
    rng = rng or np.random.default_rng(0)
    n_win, n_s, n_f = X.shape
    channel_feats = list(channel_feats)
    if Xc is None:
        Xc = np.zeros((n_win, n_s, len(channels), 0))
    n_g = Xc.shape[-1]
    sim, scales = gap.sim, gap.scales
    groups_all = np.repeat(gap.trial_id, n_s)
    target = gap.remainder()
    row_train = np.repeat(gap.is_train, n_s)
    coef = np.zeros((len(channels), n_f + n_g))
    terms = []
    chosen = {}
    all_feats = list(features) + channel_feats
    for c, ch in enumerate(channels):
        flat_X = np.concatenate([X, Xc[..., c, :]], axis=-1).reshape(-1, n_f + n_g)
        ok = row_train & np.all(np.isfinite(flat_X), axis=1) & np.isfinite(target[:, c])
        rms = np.sqrt(np.mean(flat_X[ok] ** 2, axis=0))
        usable = rms > 0
        Xs = np.where(usable, flat_X / np.where(usable, rms, 1.0), 0.0)
        Xc_, yc, gc = Xs[ok][:, usable], target[ok, c], groups_all[ok]
        support_u = _choose_terms(Xc_, yc, gc, s)
        support = np.flatnonzero(usable)[support_u]
        chosen[ch] = len(support)
        if not len(support):
            continue
        xi = _lstsq(Xs[ok], yc, support)
        lo, hi = _boot_intervals(Xs[ok], yc, gc, support, s, rng)
        for j, f in enumerate(support):
            to_phys = scales[c] / rms[f]
            coef[c, f] = xi[f] * to_phys
            a, b = sorted((lo[j] * to_phys, hi[j] * to_phys))
            terms.append(Term(ch, all_feats[f], coef[c, f], (a, b), abs(xi[f])))
    out = Discovery(tuple(channels), all_feats, coef, n_f, terms, chosen)
    test = ~gap.is_train
    corrected = sim[test] + np.nan_to_num(out.predict(X[test], Xc[test]))
    trials, loss, p = gap.held_out(np.stack([sim[test], corrected]), min_improvement)
    out.test_trials, out.test_before, out.test_after = trials, loss[0], loss[1]
    out.p_value = p if terms else 1.0
    out.significant = out.p_value < alpha
    out.seconds = time.perf_counter() - started
    return out


@dataclass
class Constancy:
    """Is a named effect's strength constant? (`effect_constancy`; losses per held-out
    trial, of the remainder with the effect's contribution re-scaled by a constant, and
    with it varying along distance, time and direction.)"""

    effect: str
    test_before: np.ndarray
    test_after: np.ndarray
    p_value: float
    significant: bool
    varies_with: str  # family of the largest varying term: distance|time|sign|condition
    # the fit is pinned at an edge of its realistic range (`CandidateResult.at_range_edge`)
    at_range_edge: bool = False

    @property
    def improvement(self) -> float:
        """Fraction of the constant-effect remainder a varying strength removes."""
        b = float(np.mean(self.test_before))
        return 1.0 - float(np.mean(self.test_after)) / b if b > 0 else 0.0


def effect_constancy(
    Xe: np.ndarray,
    features: list[Feature],
    gap: Gap,
    alpha: float,
    min_improvement: float,
    effect: str = "",
) -> Constancy:
    """Test that a just-named effect has one strength everywhere.

    ``Xe`` (n_windows, n_samples, n_channels, n) is `features.effect_features` of the
    effect: its contribution D and D times distance, time, each segment sliding forward
    and each condition. On the training trials, per channel, the remainder ``meas - sim``
    of ``gap`` (its ``sim`` is the replay with the effect) is regressed by least squares once on D
    alone (a constant re-scaling of the effect: absorbs a slightly mis-fitted parameter)
    and once on all of them. On the held-out trials, the one-sided paired t-test that the
    varying fit removes more than ``min_improvement`` of the constant fit's loss, at
    ``alpha``. A significant result means the data want the effect stronger in some
    parts and weaker in others: the effect mimics something the library does not hold,
    and is reported as a partial explanation, not as the cause.
    """
    n_win, n_s, n_ch, n_e = Xe.shape
    scales = gap.scales
    row_train = np.repeat(gap.is_train, n_s)
    target = gap.remainder()
    corr = np.zeros((2, n_win * n_s, n_ch))
    share = np.zeros(n_e)
    for c in range(n_ch):
        Xf = Xe[..., c, :].reshape(-1, n_e) / scales[c]
        ok = np.all(np.isfinite(Xf), axis=1) & np.isfinite(target[:, c])
        fit = ok & row_train
        rms = np.sqrt(np.mean(Xf[fit] ** 2, axis=0))
        if not fit.any() or rms[0] == 0:
            continue
        for k, cols in enumerate((np.array([0]), np.flatnonzero(rms > 0))):
            b = np.linalg.lstsq(Xf[fit][:, cols], target[fit, c], rcond=None)[0]
            corr[k, ok, c] = Xf[ok][:, cols] @ b * scales[c]
            if k == 1:
                share[cols] += np.abs(b) * rms[cols]
    corr = corr.reshape(2, n_win, n_s, n_ch)
    test = ~gap.is_train
    _, loss, p = gap.held_out(gap.sim[None, test] + corr[:, test], min_improvement)
    varying = share[1:]
    fam = features[1 + int(np.argmax(varying))].family if varying.any() else ""
    return Constancy(effect, loss[0], loss[1], p, p < alpha, fam)
