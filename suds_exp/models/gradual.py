"""Gradual SUDS: an online GMR that brings in passive coordinates as the data support them.

The paper's Future Work: "the transition from GMR to GMR+SUDS could be made more gradual,
adding shape variables as more data becomes available." `GradualGMRSuds` starts as
`OnlineGMR` (v_b on r_a, dr_a/dt) and runs, beside the current model, a candidate that
also conditions on the next passive coordinate (rp_1 first: the passive PCs come in
order of variance). Both learn every batch online; before learning, each batch scores
both by its held-out log-likelihood log p(v_b | inputs) (prequential, Dawid 1984: every
score is on data the model has not seen, so a richer model that only fits noise does not
gain). When over the last `window` scored batches the candidate is ahead by more than
`min_gain` nats per sample and consistently so (t-statistic of the per-batch gains
above `min_t`), it becomes the current model, the coordinate is recorded in
`added_` (with the sample count and batch at which it came in), and the next candidate
takes one more coordinate. Predictions are those of the current model: v_b only (the
coordinates in use are inputs; dr_p/dt is not predicted).

Likelihoods of the two models are comparable although each standardises with its own
warm-up: both are densities of v_b in mm/s and rad/s (the change of variables is undone).
"""

from __future__ import annotations

from collections import deque

import numpy as np
import pandas as pd
from scipy.special import logsumexp

from suds_exp.models.base import (
    Learner,
    ModelError,
    as_array,
    passive_columns,
    require_columns,
)
from suds_exp.models.online import ONLINE_PARAMETERS, OnlineGMR
from suds_exp.models.params import Integer, Param, Real, pick
from suds_exp.robot import DRA_COLUMNS, RA_COLUMNS, VB_COLUMNS

_LOG_2PI = np.log(2 * np.pi)


def _ready(model) -> bool:
    return model is not None and getattr(model, "is_ready_", False)


class _PassiveSubset(OnlineGMR):
    """OnlineGMR of v_b on (r_a, rp_1..rp_j, dr_a/dt), j = `n_passive`."""

    def __init__(self, n_passive: int = 0, **params):
        super().__init__(**params)
        self.n_passive = n_passive

    def _columns(self, samples):
        rp = [f"rp_{i}" for i in range(1, self.n_passive + 1)]
        return list(RA_COLUMNS) + rp + list(DRA_COLUMNS), list(VB_COLUMNS), [], []

    def log_likelihood(self, samples: pd.DataFrame) -> np.ndarray:
        """log p(v_b | inputs) per sample (n,), density in the units of vx, vy, wz."""
        Xin, f = self._inputs(samples)
        d = Xin.shape[1]
        x = (Xin - self.center_[:d]) / self.scale_[:d]
        y = (as_array(samples, VB_COLUMNS, self.name) / f[:, None] - self.center_[d:]) / (
            self.scale_[d:]
        )
        cov = self.covariances_
        cxx, cyx, cyy = cov[:, :d, :d], cov[:, d:, :d], cov[:, d:, d:]
        # residual covariance of y given x per component: S_yy - S_yx S_xx^-1 S_xy
        cond = cyy - cyx @ np.linalg.solve(cxx, np.swapaxes(cyx, 1, 2))
        L = np.linalg.cholesky(cond)
        r = y[:, None, :] - self._cond.local_means(x)  # (n, K, q)
        z = np.linalg.solve(L[None], r[..., None])[..., 0]
        q = y.shape[1]
        logn = (
            -0.5 * (z * z).sum(-1)
            - np.log(np.diagonal(L, axis1=1, axis2=2)).sum(-1)
            - 0.5 * q * _LOG_2PI
        )
        gate = self._cond.log_gate(x)
        gate = gate - logsumexp(gate, axis=1, keepdims=True)
        jac = np.log(self.scale_[d:]).sum() + q * np.log(f)
        return logsumexp(gate + logn, axis=1) - jac


class GradualGMRSuds(Learner):
    """Online GMR that adds passive coordinates rp_1, rp_2, ... one at a time.

    Fitted attributes: `passive_columns_` (coordinates in use), `added_` (list of
    {"column", "n_seen", "batch"}), `current_`, `candidate_` (None when every coordinate
    is in), `n_seen_`, `n_batches_`, `gain_history_` (per scored batch: mean gain).

    Parameters
    ----------
    n_components, reg_covar, forgetting, warmup_samples, sweeps, min_share,
    random_state : as `OnlineGMR`, for the current model and the candidate.
    window : int, default 10
        Batches (cycles) of held-out scores the decision looks at.
    min_gain : float, default 0.05
        Candidate's mean held-out log-likelihood gain over the window, nats per sample,
        needed to take it ...
    min_t : float, default 3.0
        ... and the gain's t-statistic over the window's batches (mean / standard error):
        one batch's gain varies by about 0.1 nats per sample on a coordinate that carries
        nothing, so a mean gain alone lets noise in now and then.
    """

    name = "GradualGMR+SUDS"
    _hyper_parameters = {
        **pick(
            ONLINE_PARAMETERS,
            "n_components",
            "reg_covar",
            "forgetting",
            "warmup_samples",
            "sweeps",
            "min_share",
        ),
        "window": Param(10, Integer(1)),
        "min_gain": Param(0.05, Real(0.0)),
        # not checked, as before: any number is a threshold
        "min_t": Param(3.0),
        **pick(ONLINE_PARAMETERS, "random_state"),
    }

    def _sub(self, n_passive: int) -> _PassiveSubset:
        return _PassiveSubset(
            n_passive,
            n_components=self.n_components,
            reg_covar=self.reg_covar,
            forgetting=self.forgetting,
            warmup_samples=self.warmup_samples,
            sweeps=self.sweeps,
            min_share=self.min_share,
            random_state=self.random_state,
        )

    def _reset(self):
        self._validate_params()
        self.current_ = self._sub(0)
        self.candidate_ = None
        self.passive_columns_ = []
        self.added_ = []
        self.n_seen_ = 0
        self.n_batches_ = 0
        self.gain_history_ = []
        self._scores = deque(maxlen=self.window)

    def fit(self, samples: pd.DataFrame, y=None):
        """Start afresh and learn `samples` as a stream, one (trial, cycle) batch at a time."""
        self._reset()
        require_columns(samples, ("trial_id", "t", "cycle"), self.name)
        for _, batch in samples.sort_values(["trial_id", "t"]).groupby(
            ["trial_id", "cycle"], sort=False
        ):
            self.partial_fit(batch)
        return self

    def partial_fit(self, samples: pd.DataFrame, y=None):
        """Score the batch under the current model and the candidate, then learn it."""
        if not hasattr(self, "current_"):
            self._reset()
        self._k = len(passive_columns(samples)[0])
        cur, cand = self.current_, self.candidate_
        if _ready(cur) and _ready(cand):
            gain = float(np.mean(cand.log_likelihood(samples) - cur.log_likelihood(samples)))
            self._scores.append(gain)
            self.gain_history_.append(gain)
        cur.partial_fit(samples)
        if cand is not None:
            cand.partial_fit(samples)
        self.n_seen_ += len(samples)
        self.n_batches_ += 1
        if cand is not None and self._supported():
            self.current_ = cand
            column = f"rp_{cand.n_passive}"
            self.passive_columns_.append(column)
            self.added_.append({"column": column, "n_seen": self.n_seen_, "batch": self.n_batches_})
            self._scores.clear()
            cand = None
        if cand is None and len(self.passive_columns_) < self._k:
            # the next candidate learns from here on; `cur` keeps its head start
            self.candidate_ = self._sub(len(self.passive_columns_) + 1)
        elif cand is None:
            self.candidate_ = None
        if _ready(self.current_):
            self.n_features_in_ = self.current_.n_features_in_
        return self

    def _supported(self) -> bool:
        """The candidate's gain over the window is large and consistent (see class doc)."""
        if len(self._scores) < self.window:
            return False
        g = np.asarray(self._scores)
        sd = g.std(ddof=1) if len(g) > 1 else 0.0
        t = np.inf if sd == 0 else g.mean() / (sd / np.sqrt(len(g)))
        return bool(g.mean() > self.min_gain and t > self.min_t)

    def predict(self, samples: pd.DataFrame) -> pd.DataFrame:
        """Predicted vx, vy (mm/s), wz (rad/s) of the current model, input's index."""
        if not _ready(getattr(self, "current_", None)):
            raise ModelError(f"{self.name}: predict called before the model started")
        return self.current_.predict(samples)
