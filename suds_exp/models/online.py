"""Online GMR and GMR+SUDS: A-GBR whose mixture follows a stream of samples.

The Future Work of the paper asks for "an online version of GMR or GMR+SUDS" for a robot
whose world changes. `OnlineGMR` and `OnlineGMRSuds` keep the regression of `gmr.GMR` /
`gmr.GMRSuds` (same inputs, outputs, homogeneous augmentation, predictions, rollout) and
replace the batch EM by stepwise EM on per-component sufficient statistics
(Neal & Hinton 1998; Cappe & Moulines 2009, "Online EM algorithm for latent data models"):

- state: for each component k the weighted count N_k, sum of z (S1_k, (K, D)) and sum of
  z z^T (S2_k, (K, D, D)), z the standardised joint vector (inputs, outputs);
- `partial_fit(samples)`: old statistics are discounted by (1 - forgetting) per sample of
  the new batch, then `sweeps` E/M passes over the new batch alone (responsibilities of
  the batch under the current parameters; parameters from discounted old + batch
  statistics), and the batch's last statistics are added for good. With forgetting = 0
  this is Neal & Hinton's incremental EM visiting every sample once (step size
  gamma_n = n_batch / N_total, Cappe & Moulines' cumulative average); with forgetting > 0 it
  is their constant-step variant: a sample `a` samples old weighs (1 - forgetting)^a,
  an effective memory of 1 / forgetting samples.
- start: samples are buffered until `warmup_samples` have arrived, then the mixture is
  initialised by the batch EM of `suds_exp.models.mixture` on the buffer (which also fixes
  the standardisation and the homogeneity speed floor, as `GMR.fit` does).
- birth: a component whose share of the weight falls below `min_share` / K (after a change,
  the data it explained are no longer seen and forgetting drains it) is re-born at the
  batch sample the mixture explains worst, with the covariance of the batch and the
  weight of `1 / K` of the batch; `n_births_` counts them.

`fit(samples)` is a fresh start: the buffer initialisation on all of `samples` (exactly the
batch EM of `GMR` with its defaults), so `fit` then `partial_fit` is a batch model that
keeps learning. Branching and the "dilation" augment are batch-only and not offered.

Cost (benchmarks/online.py): one `partial_fit` of one 1-Hz cycle (100 samples) took a median
of 32 ms (OnlineGMR) and 44 ms (OnlineGMR+SUDS), 3-5 % of the cycle, on a shared 2-core
machine; most of it is pandas column handling, not EM.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.special import logsumexp

from suds_exp.models.base import (
    ModelError,
    actuated_columns,
    as_array,
    require_columns,
    rollout_bounds,
)
from suds_exp.models.gmr import GMR, GMR_PARAMETERS, GMRSuds
from suds_exp.models.mixture import Conditional, fit_mixture, log_gaussians
from suds_exp.models.params import Integer, Options, Param, Real, pick
from suds_exp.models.suds_variant import SUDS_PARAMETERS

#: The online learners' hyper-parameters: GMR's that stream learning keeps (the same
#: defaults and checks; no dilation) and their own. `gradual.GradualGMRSuds` shares them.
ONLINE_PARAMETERS: dict[str, Param] = {
    **pick(GMR_PARAMETERS, "n_components", "reg_covar", "max_iter", "tol"),
    "augment": Param("homogeneous", Options(("homogeneous", "none"))),
    **pick(GMR_PARAMETERS, "augment_power", "speed_floor"),
    "forgetting": Param(0.002, Real(0.0, high=1, high_open=True)),
    "warmup_samples": Param(500, Integer(1)),
    "sweeps": Param(2, Integer(1)),
    "min_share": Param(0.05, Real(0.0)),
    **pick(GMR_PARAMETERS, "random_state"),
}


class _OnlineMixin:
    """`partial_fit` and the sufficient-statistics state shared by both online learners."""

    # Batch-only features of GMR, fixed off for the online learners (read by GMR's code).
    branching = "none"
    select_k = "none"
    augment_copies = 0
    augment_weight = 0.0
    augment_range = GMR_PARAMETERS["augment_range"].default
    branch_mix = 0.0
    branch_memory = 1.0
    k_candidates = ()

    # -- public ------------------------------------------------------------------------
    def fit(self, samples: pd.DataFrame, y=None):
        """Forget everything, then initialise from all of `samples` by batch EM."""
        self._reset()
        self._validate()
        self._start(samples)
        return self

    def partial_fit(self, samples: pd.DataFrame, y=None):
        """Learn from one more batch of samples (e.g. one cycle), oldest to newest.

        `samples` is a samples frame (see `GMR.fit`); rows are taken in (trial_id, t)
        order, so forgetting discounts older rows more. Until `warmup_samples` rows have
        arrived they are only buffered (`is_ready_` False; `predict` raises ModelError).
        """
        if not hasattr(self, "n_seen_"):
            self._reset()
            self._validate()
        if not self.is_ready_:
            cin, cout, *_ = self._columns(samples)
            require_columns(samples, ("trial_id", "t", *cin, *cout), self.name)
            self._buffer.append(samples)
            self.n_seen_ += len(samples)
            if self.n_seen_ >= self.warmup_samples:
                buffered = pd.concat(self._buffer, ignore_index=True)
                self._buffer = []
                self._start(buffered)
            return self
        require_columns(
            samples, ("trial_id", "t", *self.columns_in_, *self.columns_out_), self.name
        )
        order = np.lexsort((samples["t"].to_numpy(float), samples["trial_id"].to_numpy()))
        X = self._standardised(samples)[order]
        self._step(X)
        self.n_seen_ += len(samples)
        if self.rp_columns_:
            rp = as_array(samples, self.rp_columns_, self.name)
            self._rp_range = np.vstack(
                [np.minimum(self._rp_range[0], rp.min(0)), np.maximum(self._rp_range[1], rp.max(0))]
            )
            self.rp_bounds_ = rollout_bounds(self._rp_range)
        return self

    def _check_fitted(self):
        if not getattr(self, "is_ready_", False):
            raise ModelError(
                f"{self.name}: predict called before the model started (fit, or "
                f"partial_fit of at least warmup_samples={self.warmup_samples} samples)"
            )

    # -- internals ---------------------------------------------------------------------
    def _reset(self):
        for attr in [a for a in vars(self) if a.endswith("_") and not a.startswith("__")]:
            delattr(self, attr)
        self.n_seen_ = 0
        self.is_ready_ = False
        self.n_births_ = 0
        self._buffer = []

    def _standardised(self, samples) -> np.ndarray:
        Xin, f = self._inputs(samples)
        Z = np.hstack([Xin, as_array(samples, self.columns_out_, self.name) / f[:, None]])
        return (Z - self.center_) / self.scale_

    def _start(self, samples):
        """Batch initialisation (as `GMR.fit` without BIC or branching) and the statistics."""
        cin, cout, rp_cols, drp_cols = self._columns(samples)
        require_columns(samples, ("trial_id", "t", *cin, *cout), self.name)
        if len(samples) < self.n_components:
            raise ModelError(
                f"{self.name}: {len(samples)} samples cannot start n_components="
                f"{self.n_components}; give more data or fewer components"
            )
        self.columns_in_, self.columns_out_ = cin, cout
        self.rp_columns_, self.drp_columns_ = rp_cols, drp_cols
        self.ra_columns_, self.dra_columns_ = actuated_columns(samples)
        speed = np.linalg.norm(as_array(samples, self.dra_columns_, self.name), axis=1)
        typical = float(np.median(speed)) or float(np.mean(speed)) or 1.0
        self.speed_floor_ = self.speed_floor * typical
        Xin, f = self._inputs(samples)
        Z = np.hstack([Xin, as_array(samples, cout, self.name) / f[:, None]])
        self.center_ = Z.mean(axis=0)
        self.scale_ = np.where(Z.std(axis=0) > 0, Z.std(axis=0), 1.0)
        order = np.lexsort((samples["t"].to_numpy(float), samples["trial_id"].to_numpy()))
        X = ((Z - self.center_) / self.scale_)[order]
        rng = np.random.default_rng([self.random_state, self.n_components])
        mix = fit_mixture(X, self.n_components, None, self.max_iter, self.tol, self.reg_covar, rng)
        self.n_iter_, self.converged_ = mix.n_iter, mix.converged
        self.n_components_ = len(mix.priors)
        self.n_features_in_ = Xin.shape[1]
        self.transition_ = None  # no branch filter online
        # statistics of the buffer under the fitted mixture, each sample discounted by age
        w = self._ages(len(X))
        resp = self._resp(X, mix.priors, mix.means, mix.covariances)
        self.stat_n_, self.stat_s1_, self.stat_s2_ = self._stats(X, resp * w[:, None])
        self._set_parameters()
        self.is_ready_ = True
        self.n_seen_ = len(samples)
        if rp_cols:
            rp = as_array(samples, rp_cols, self.name)
            self._rp_range = np.vstack([rp.min(0), rp.max(0)])
            self.rp_bounds_ = rollout_bounds(self._rp_range)

    def _ages(self, n: int) -> np.ndarray:
        """Weights (n,) of a batch's samples at its end: (1 - forgetting)^(n - 1 - i)."""
        return (1.0 - self.forgetting) ** np.arange(n - 1, -1, -1, dtype=float)

    @staticmethod
    def _resp(X, priors, means, cov) -> np.ndarray:
        logp = log_gaussians(X, means, cov) + np.log(priors)
        return np.exp(logp - logsumexp(logp, axis=1, keepdims=True))

    @staticmethod
    def _stats(X, rw):
        """(N (K,), S1 (K, D), S2 (K, D, D)) of samples X (n, D) with weights rw (n, K)."""
        n, D = X.shape
        outer = (X[:, :, None] * X[:, None, :]).reshape(n, D * D)
        return rw.sum(0), rw.T @ X, (rw.T @ outer).reshape(-1, D, D)

    def _parameters(self, n, s1, s2):
        """Priors, means, covariances (standardised units) from statistics, as EM's M-step."""
        nk = n + 10 * np.finfo(float).eps
        means = s1 / nk[:, None]
        cov = s2 / nk[:, None, None] - np.einsum("kd,ke->kde", means, means)
        cov = 0.5 * (cov + np.swapaxes(cov, 1, 2)) + self.reg_covar * np.eye(means.shape[1])
        return nk / nk.sum(), means, cov

    def _set_parameters(self):
        self.priors_, self.means_, self.covariances_ = self._parameters(
            self.stat_n_, self.stat_s1_, self.stat_s2_
        )
        d = self.n_features_in_
        D = self.means_.shape[1]
        self._cond = Conditional.of(
            self.priors_, self.means_, self.covariances_, np.arange(d), np.arange(d, D)
        )

    def _step(self, X: np.ndarray):
        """Stepwise EM on one standardised batch X (n, D), time-ordered."""
        n = len(X)
        decay = (1.0 - self.forgetting) ** n
        n0, s10, s20 = self.stat_n_ * decay, self.stat_s1_ * decay, self.stat_s2_ * decay
        w = self._ages(n)
        priors, means, cov = self.priors_, self.means_, self.covariances_
        for _ in range(self.sweeps):
            resp = self._resp(X, priors, means, cov)
            bn, bs1, bs2 = self._stats(X, resp * w[:, None])
            priors, means, cov = self._parameters(n0 + bn, s10 + bs1, s20 + bs2)
        self.stat_n_, self.stat_s1_, self.stat_s2_ = n0 + bn, s10 + bs1, s20 + bs2
        self._births(X, w, priors, means, cov)
        self._set_parameters()

    def _births(self, X, w, priors, means, cov):
        """Re-seed components drained below `min_share` / K at the worst-explained samples."""
        K = len(priors)
        dead = np.flatnonzero(self.stat_n_ < self.min_share / K * self.stat_n_.sum())
        if not len(dead):
            return
        loglik = logsumexp(log_gaussians(X, means, cov) + np.log(priors), axis=1)
        # the newborn is as wide as the batch it comes from, not as the whole history: after
        # a change that pins a coordinate (a jammed flipper), a component as wide as the old
        # data could never win samples from one that has already shrunk onto the new data
        mean_b = w @ X / w.sum()
        cov_b = (X - mean_b).T @ ((X - mean_b) * w[:, None]) / w.sum()
        for k, i in zip(dead, np.argsort(loglik)[: len(dead)], strict=False):
            nk = w.sum() / K
            self.stat_n_[k] = nk
            self.stat_s1_[k] = nk * X[i]
            self.stat_s2_[k] = nk * (cov_b + np.outer(X[i], X[i]))
            self.n_births_ += 1


class OnlineGMR(_OnlineMixin, GMR):
    """A-GBR of v_b on (r_a, dr_a/dt) learned from a stream by stepwise EM.

    Parameters (GMR's, minus the batch-only ones)
    ----------
    n_components, reg_covar, max_iter, tol, augment ("homogeneous" | "none"),
    augment_power, speed_floor, random_state : as `GMR` (max_iter, tol: the start's EM).
    forgetting : float in [0, 1), default 0.002
        Fraction of weight lost per new sample: memory about 1 / forgetting samples
        (0.002: 500 samples, 5 s at 100 Hz). 0 = never forget (incremental EM).
    warmup_samples : int, default 500
        Samples buffered before the mixture starts (batch EM on the buffer).
    sweeps : int, default 2
        E/M passes over each new batch.
    min_share : float, default 0.05
        A component below min_share / n_components of the weight is re-born.

    Fitted attributes: those of `GMR` (priors_, means_, covariances_, center_, scale_, ...)
    plus `stat_n_` (K,), `stat_s1_` (K, D), `stat_s2_` (K, D, D) (standardised units),
    `n_seen_`, `is_ready_`, `n_births_`.
    """

    name = "OnlineGMR"
    _hyper_parameters = ONLINE_PARAMETERS


class OnlineGMRSuds(_OnlineMixin, GMRSuds):
    """A-GBR of (v_b, dr_p/dt) on (r_a, r_p, dr_a/dt) learned from a stream.

    Parameters of `OnlineGMR` plus `mode` ("measured" | "rollout") as `GMRSuds`.
    """

    name = "OnlineGMR+SUDS"
    _hyper_parameters = ONLINE_PARAMETERS | SUDS_PARAMETERS
