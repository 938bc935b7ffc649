"""GMR and GMR+SUDS: augmented Gaussian branching regression (A-GBR, Hu & Revzen 2025).

The paper names the ingredients but publishes no equations or code; this is our design.

Regression. A full-covariance Gaussian mixture (K = `n_components`, EM in
`suds_exp.models.mixture`) is fitted to the joint vectors z = (x, y), with
x = (r_a, dr_a/dt), y = v_b for GMR and x = (r_a, r_p, dr_a/dt), y = (v_b, dr_p/dt) for
GMR+SUDS (dr_p/dt is not needed on the right-hand side, Bittner et al. 2022). Every
column is standardised with the training mean and standard deviation. The prediction is
the responsibility-weighted sum of the components' affine conditional means,
E[y | x] = sum_k h_k(x) (mu_y,k + S_yx,k S_xx,k^-1 (x - mu_x,k)), with gates
h_k(x) proportional to pi_k N(x | mu_x,k, S_xx,k).

Augmentation: a bias towards linearity in dr_a/dt. The physics is rate-independent:
time-rescaling a motion by s > 0 scales every rate (dr_a/dt, v_b, dr_p/dt) by s and leaves
the shapes alone, so v_b is homogeneous of degree 1 in dr_a/dt. It is not linear:
friction may depend on the direction of motion (a Finsler-like map), so mirrored (s < 0)
data are never assumed. Three variants (`augment`):

- "homogeneous" (default): a change of variables. With rho = sqrt(|dr_a/dt|^2 + f0^2)
  (f0 = `speed_floor` x the training median of |dr_a/dt|, so a robot at rest does not
  divide by zero), every rate column is divided by rho^alpha (alpha = `augment_power`)
  before the mixture is fitted, and predictions are multiplied back by rho^alpha. With
  alpha = 1 the mixture models v_b / |dr_a/dt| as a function of (r_a[, r_p], direction
  of dr_a/dt) and each component's affine conditional mean gives
  v_b ~ a_k |dr_a/dt| + B_k dr_a/dt: linear in dr_a/dt plus a direction-dependent
  |dr_a/dt| term, exactly rate-independent. alpha in (0, 1) weakens the bias (a robot
  whose inertia makes speed matter a little); alpha = 0 switches it off.
- "dilation": data augmentation. Each training sample gets `augment_copies` copies
  (r, s dr/dt, s v_b[, s dr_p/dt]) with s log-uniform in `augment_range`, weighted
  `augment_weight` in EM (originals weigh 1), so components stretch along rays through
  dr_a/dt = 0. Softer and dearer (EM sees (1 + copies) x the samples); kept for the
  ablation.
- "none": plain GMR.

Measured (benchmarks/models.py --boots 6, simulator data, 30 training cycles of O at
1/2 Hz, mean RMSE of vx): "homogeneous" against "none" changes the error by -3 % (GMR)
and +30 % (GMR+SUDS) on the training condition, by -87 % / -74 % at 1 Hz, -76 % / -55 %
at 1/3 Hz and -46 % / -4 % on gait D+. "dilation" lies between the two for GMR; for
GMR+SUDS it beats "homogeneous" on the training condition (2.74 against 3.59 mm/s) and
at 1 Hz (7.66 against 11.65) but loses at 1/3 Hz (6.96 against 3.41); on D+ it is the
worst of the three for both learners.

Branching: the map may be multi-valued, the body moving differently at one
(r_a, dr_a/dt) depending on recent history (flippers open or closed). Two mechanisms
(`branching`):

- "filter": the mixture components act as branches. From the training trials
  (consecutive samples of one trial, joint-space responsibilities gamma) we learn a
  transition matrix T_jk ~ sum_t gamma_t-1,j gamma_t,k, blended with the priors,
  T = (1 - branch_mix) T + branch_mix 1 pi^T, so no branch is ever unreachable.
  Prediction runs a forward filter per trial, alpha_t,k ~ N(x_t | mu_x,k, S_xx,k)
  (alpha_t-1 T)_k, started at the priors, and uses alpha_t in place of the gates: the
  branch the system was on a moment ago selects among components that explain x_t
  equally well. Samples must be time-ordered within a trial at the training sample
  spacing (the campaign decimates every condition to the same samples per cycle).
- "history": two more inputs, the chord r_a(s) - r_a(s - `branch_memory`) over the
  last `branch_memory` rad of arc length travelled in actuated-shape space (where the
  shape came from; rate-independent), so the mixture can split a region by history.
- "none" (default): plain gating h_k(x).

Measured (same ablation, with "homogeneous"): "filter" changes the error by at most 6 %
anywhere; with dr_a/dt among the inputs a periodic gait never revisits an
(r_a, dr_a/dt) point, so gating on x alone is already unambiguous. "history" is a mixed
bag: on the simulator it cuts GMR+SUDS's error by 35 % on the training condition and by
53 % at 1 Hz but nearly doubles it on D+ (+93 %); for GMR it is +2 % / +14 % / -15 %
(same, 1 Hz, D+); on the synthetic swimmer GMR gains 17 % on the training gait and
loses 41 % on D+. History chords of another gait lie outside the training data, and most
pairs of a campaign cross gaits, so both mechanisms stay available and off by default.

Rollout (GMR+SUDS, mode="rollout"): r_p starts at each trial's first measured value and
is integrated by explicit Euler with the predicted dr_p/dt, clipped to the training range
widened by a tenth of its width (`rollout_bounds`); v_b is predicted from the rolled-out
r_p.

Choosing K: `select_k="bic"` fits every K in `k_candidates` and keeps the lowest BIC
(weighted log-likelihood, augmented samples counted with their weight); off by default
so the cost of a campaign is predictable.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from suds_exp.errors import ConfigError
from suds_exp.models.base import (
    Columns,
    Learner,
    TimeSeries,
    actuated_columns,
    as_array,
    require_columns,
    rollout_bounds,
)
from suds_exp.models.mixture import (
    Conditional,
    exp_inplace,
    fit_mixture,
    responsibilities,
    row_max,
)
from suds_exp.models.params import Integer, Options, Param, Real, Rule
from suds_exp.models.suds_variant import SUDS_PARAMETERS, check_mode, required_passive_columns
from suds_exp.robot import RA_COLUMNS, VB_COLUMNS


def history_features(
    samples: pd.DataFrame, memory: float, columns: tuple | list = RA_COLUMNS
) -> np.ndarray:
    """Where the actuated shape came from: r_a(s) - r_a(s - memory), shape (n, m), in the
    units of the r_a `columns` (rad for joint angles, mm for the paper's Cartesian values).

    s is the arc length travelled in actuated-shape space within each trial (rad), so the
    feature is rate-independent; before a trial has travelled `memory` rad the chord
    reaches back to its first sample. Returned in the caller's row order.
    """
    ts = TimeSeries.of(samples)
    ra = as_array(samples, columns, "GMR")[ts.order]
    step = np.linalg.norm(np.diff(ra, axis=0, prepend=ra[:1]), axis=1)
    step[ts.first] = 0.0
    out = np.empty_like(ra)
    for a, b in zip(ts.starts[:-1], ts.starts[1:], strict=True):
        s = np.cumsum(step[a:b])
        # strictly increasing abscissa for interp even where the shape stood still
        s = s + np.arange(b - a) * 1e-12
        back = s - memory
        for j in range(ra.shape[1]):
            out[a:b, j] = ra[a:b, j] - np.interp(back, s, ra[a:b, j])
    return ts.unsort(out)


def forward_filter(log_emit, transition, priors, first) -> np.ndarray:
    """Filtered branch probabilities alpha, shape (n, K), for time-ordered samples.

    log_emit (n, K): log N(x_t | component k); transition (K, K), rows sum to 1;
    priors (K,); first (n,) bool marks the first sample of each trial (restart).
    """
    e = exp_inplace(log_emit - row_max(log_emit)[:, None])
    out = np.empty_like(e)
    a = priors
    for t in range(len(e)):
        a = e[t] * (priors if first[t] else a @ transition)
        s = a.sum()
        a = a / s if s > 0 else e[t] * priors / (e[t] @ priors)
        out[t] = a
    return out


def _augment_range(name: str, value, model) -> None:
    ok = (
        isinstance(value, tuple | list)
        and len(value) == 2
        and all(isinstance(v, int | float) for v in value)
        and 0 < value[0] <= value[1]
    )
    if not ok:
        raise ConfigError(
            f"{model.name}: {name}={value!r}; expected (s_min, s_max) with 0 < s_min <= s_max"
        )


def _k_candidates(name: str, value, model) -> None:
    # read only when BIC chooses K (select_k is declared, so checked, before it)
    if model.select_k == "bic":
        if not value:
            raise ConfigError(f"{model.name}: {name} is empty; give at least one K")
        for k in value:
            Integer(1).check(name, k, model)


#: GMR's hyper-parameters (see `GMR`), the one home of each default and check: the SUDS,
#: momentum, Finsler and online learners take theirs from here.
GMR_PARAMETERS: dict[str, Param] = {
    "n_components": Param(16, Integer(1)),
    "reg_covar": Param(1e-3, Real(0.0, strict=True)),
    "max_iter": Param(60, Integer(1)),
    "tol": Param(1e-3, Real(0.0)),
    "augment": Param("homogeneous", Options(("homogeneous", "dilation", "none"))),
    "augment_range": Param((0.5, 2.0), Rule(_augment_range)),
    "augment_copies": Param(1, Integer(0)),
    "augment_weight": Param(0.5, Real(0.0)),
    "augment_power": Param(1.0, Real(0.0)),
    "speed_floor": Param(0.1, Real(0.0, strict=True)),
    "branching": Param("none", Options(("history", "filter", "none"))),
    "branch_mix": Param(0.1, Real(0.0, high=1)),
    "branch_memory": Param(1.0, Real(0.0, strict=True)),
    "select_k": Param("none", Options(("none", "bic"))),
    "k_candidates": Param((4, 8, 12, 16), Rule(_k_candidates)),
    "random_state": Param(0, Integer(0)),
}


class GMR(Learner):
    """A-GBR of v_b on (r_a, dr_a/dt) (see the module docstring for the design).

    Parameters
    ----------
    n_components : int, default 16
        Number of Gaussian components K.
    reg_covar : float, default 1e-3
        Added to each covariance diagonal (standardised units).
    max_iter : int, default 60
        EM iteration limit.
    tol : float, default 1e-3
        EM stops when the mean log-likelihood per sample improves by less than this.
    augment : {"homogeneous", "dilation", "none"}, default "homogeneous"
    augment_range : tuple of two floats, default (0.5, 2.0)
        Range of dilation factors s (log-uniform).
    augment_copies : int, default 1
        Dilated copies per training sample.
    augment_weight : float, default 0.5
        EM sample weight of each dilated copy (originals weigh 1).
    augment_power : float, default 1.0
        alpha of "homogeneous": rates are divided by rho^alpha (1 = rate-independent).
    speed_floor : float, default 0.1
        f0 of "homogeneous", as a fraction of the training median |dr_a/dt|.
    branching : {"none", "filter", "history"}, default "none"
    branch_mix : float, default 0.1
        Weight of the priors blended into the learned branch transition matrix.
    branch_memory : float, default 1.0
        Arc length (rad of actuated-shape travel) looked back by "history".
    select_k : {"none", "bic"}, default "none"
    k_candidates : tuple of int, default (4, 8, 12, 16)
        Candidates for K when select_k="bic".
    random_state : int, default 0
        Seed of the k-means++ initialisation and of the dilation factors.

    Attributes
    ----------
    priors_ (K,), means_ (K, D), covariances_ (K, D, D): the mixture in standardised
    units over the inputs `columns_in_` (then hist_1..hist_m with branching="history")
    and the outputs `columns_out_`, rates divided by rho^alpha; `center_`, `scale_` (D,)
    the standardisation; `speed_floor_` (rad/s); `transition_` (K, K) the branch
    transition matrix (None unless branching="filter"); `rp_bounds_` (2, k) rollout
    limits (SUDS); `n_iter_`, `converged_`, `n_components_` (K actually used), `bic_`.
    """

    name = "GMR"
    _hyper_parameters = GMR_PARAMETERS

    # -- columns -------------------------------------------------------------------------
    def _columns(self, samples):
        """(input columns, output columns, rp columns, drp columns)."""
        ra, dra = actuated_columns(samples)
        return ra + dra, list(VB_COLUMNS), [], []

    # -- fit -----------------------------------------------------------------------------
    def fit(self, samples: pd.DataFrame, y=None):
        self._validate()
        cin, cout, rp_cols, drp_cols = self._columns(samples)
        require_columns(samples, ("trial_id", "t", *cin, *cout), self.name)
        self.columns_in_, self.columns_out_ = cin, cout
        self.rp_columns_, self.drp_columns_ = rp_cols, drp_cols
        self.ra_columns_, self.dra_columns_ = actuated_columns(samples)
        rng = np.random.default_rng(self.random_state)
        speed = np.linalg.norm(as_array(samples, self.dra_columns_, self.name), axis=1)
        # a robot that mostly stands still has median speed 0: fall back to the mean, then 1
        typical = float(np.median(speed)) or float(np.mean(speed)) or 1.0
        self.speed_floor_ = self.speed_floor * typical
        Xin, f = self._inputs(samples)
        Z = np.hstack([Xin, as_array(samples, cout, self.name) / f[:, None]])
        hist = [f"hist_{i + 1}" for i in range(len(self.ra_columns_))]
        names = cin + (hist if self.branching == "history" else []) + cout
        rate = np.array([c.startswith("d") or c in VB_COLUMNS for c in names])
        self.center_ = Z.mean(axis=0)
        self.scale_ = np.where(Z.std(axis=0) > 0, Z.std(axis=0), 1.0)
        data, weights = [Z], [np.ones(len(Z))]
        if self.augment == "dilation" and self.augment_copies > 0 and self.augment_weight > 0:
            lo, hi = np.log(self.augment_range[0]), np.log(self.augment_range[1])
            for _ in range(self.augment_copies):
                s = np.exp(rng.uniform(lo, hi, size=len(Z)))
                copy = Z.copy()
                copy[:, rate] *= s[:, None]
                data.append(copy)
                weights.append(np.full(len(Z), float(self.augment_weight)))
        X = (np.vstack(data) - self.center_) / self.scale_
        w = np.concatenate(weights)
        ks = [self.n_components] if self.select_k == "none" else list(self.k_candidates)
        best, best_bic = None, np.inf
        for k in ks:
            # each K has its own stream, so the K that BIC picks is the fixed-K model
            em_rng = np.random.default_rng([self.random_state, k])
            mix = fit_mixture(X, k, w, self.max_iter, self.tol, self.reg_covar, em_rng)
            bic = -2 * mix.log_likelihood * w.sum() + mix.n_parameters() * np.log(w.sum())
            if bic < best_bic:
                best, best_bic = mix, bic
        self.priors_, self.means_, self.covariances_ = best.priors, best.means, best.covariances
        self.n_iter_, self.converged_ = best.n_iter, best.converged
        self.n_components_ = len(best.priors)
        self.bic_ = best_bic
        d = Xin.shape[1]
        self._cond = Conditional.of(
            self.priors_, self.means_, self.covariances_, np.arange(d), np.arange(d, Z.shape[1])
        )
        self.transition_ = None
        if self.branching == "filter":
            # Branch transitions from consecutive original samples of the same trial.
            K = self.n_components_
            ts = TimeSeries.of(samples)
            g = responsibilities(X[: len(Z)][ts.order], best)
            pairs = ~ts.first[1:]
            counts = g[:-1][pairs].T @ g[1:][pairs] if pairs.any() else np.zeros((K, K))
            rows = counts.sum(axis=1, keepdims=True)
            T = np.where(rows > 0, counts / np.where(rows > 0, rows, 1.0), self.priors_[None])
            self.transition_ = (1 - self.branch_mix) * T + self.branch_mix * self.priors_[None]
        self.n_features_in_ = d
        if rp_cols:
            self.rp_bounds_ = rollout_bounds(as_array(samples, rp_cols, self.name))
        return self

    def _inputs(self, samples):
        """Model inputs (n, d) in the caller's order and the rate divisor f (n,).

        Columns `columns_in_` with dr_a/dt divided by f (see `_homogeneity`), then the
        history features when branching="history".
        """
        X = as_array(samples, self.columns_in_, self.name)
        f = self._homogeneity(samples)
        X[:, [c in self.dra_columns_ for c in self.columns_in_]] /= f[:, None]
        if self.branching == "history":
            X = np.hstack([X, history_features(samples, self.branch_memory, self.ra_columns_)])
        return X, f

    def _homogeneity(self, samples) -> np.ndarray:
        """rho^alpha per sample, shape (n,): what rates are divided by ("homogeneous").

        rho = sqrt(|dr_a/dt|^2 + speed_floor_^2) in rad/s; all ones for other augments.
        """
        if self.augment != "homogeneous" or self.augment_power == 0:
            return np.ones(len(samples))
        dra = as_array(samples, self.dra_columns_, self.name)
        rho = np.sqrt((dra * dra).sum(axis=1) + self.speed_floor_**2)
        return rho**self.augment_power

    # -- predict -------------------------------------------------------------------------
    def _gates(self, Xs, ts):
        """Branch/gate weights (n, K) for standardised inputs in sorted order."""
        lg = self._cond.log_gate(Xs)
        if self.branching == "filter":
            return forward_filter(
                lg - np.log(self.priors_), self.transition_, self.priors_, ts.first
            )
        h = exp_inplace(lg - row_max(lg)[:, None])
        h /= h.sum(axis=1, keepdims=True)
        return h

    def _predict_measured(self, samples):
        Xin, f = self._inputs(samples)
        d = Xin.shape[1]
        ts = TimeSeries.of(samples)
        Xs = ((Xin - self.center_[:d]) / self.scale_[:d])[ts.order]
        h = self._gates(Xs, ts)
        ys = np.einsum("nk,nkq->nq", h, self._cond.local_means(Xs))
        return ts.unsort(ys * self.scale_[d:] + self.center_[d:]) * f[:, None]

    def predict(self, samples: pd.DataFrame) -> pd.DataFrame:
        """Predicted vx, vy (mm/s), wz (rad/s) [, drp_1..drp_k], same index as `samples`."""
        return self._output_frame(self.predict_array(samples), samples)

    def predict_array(self, samples: pd.DataFrame | Columns) -> np.ndarray:
        self._check_fitted()
        require_columns(samples, ("trial_id", "t", *self.columns_in_), self.name)
        return self._predict_measured(samples)


class GMRSuds(GMR):
    """A-GBR of (v_b, dr_p/dt) on (r_a, r_p, dr_a/dt). Parameters of `GMR` plus

    mode : {"measured", "rollout"}, default "measured"
        "measured" uses the test trial's r_p; "rollout" integrates r_p from each
        trial's first sample with the learned dr_p/dt.
    """

    name = "GMR+SUDS"
    suds = True
    _hyper_parameters = GMR_PARAMETERS | SUDS_PARAMETERS

    def _columns(self, samples):
        rp, drp = required_passive_columns(samples, self.name)
        ra, dra = actuated_columns(samples)
        return ra + rp + dra, list(VB_COLUMNS) + drp, rp, drp

    def predict_array(self, samples: pd.DataFrame | Columns) -> np.ndarray:
        self._check_fitted()
        check_mode(self.mode, self.name)
        require_columns(samples, ("trial_id", "t", *self.columns_in_), self.name)
        if self.mode == "measured":
            return self._predict_measured(samples)
        return self._predict_rollout(samples)[0]

    def rollout(self, samples: pd.DataFrame) -> pd.DataFrame:
        """r_p integrated from each trial's first sample, columns rp_1..rp_k, input's index.

        Uses r_a, dr_a/dt of every sample and r_p of each trial's first sample only.
        """
        self._check_fitted()
        require_columns(samples, ("trial_id", "t", *self.columns_in_), self.name)
        return pd.DataFrame(
            self._predict_rollout(samples)[1], index=samples.index, columns=self.rp_columns_
        )

    def _predict_rollout(self, samples):
        """(outputs (n, 3 + k), rolled-out r_p (n, k)) in the caller's order."""
        k = len(self.rp_columns_)
        Xin, f = self._inputs(samples)
        d = Xin.shape[1]
        ts = TimeSeries.of(samples)
        Xs = ((Xin - self.center_[:d]) / self.scale_[:d])[ts.order]
        fs = f[ts.order]
        # r_p occupies inputs m..m+k (after the m of r_a) and outputs 3..3+k; in
        # standardised units one Euler step is rp_s += dt * drp_s * scale_out / scale_in.
        rp_in = slice(len(self.ra_columns_), len(self.ra_columns_) + k)
        gain = self.scale_[d + 3 : d + 3 + k] / self.scale_[rp_in]
        off = self.center_[d + 3 : d + 3 + k] / self.scale_[rp_in]
        lo = (self.rp_bounds_[0] - self.center_[rp_in]) / self.scale_[rp_in]
        hi = (self.rp_bounds_[1] - self.center_[rp_in]) / self.scale_[rp_in]
        c = self._cond
        P, mu_in, reg, mu_out = c.prec_in, c.mean_in, c.reg, c.mean_out
        K, q = mu_out.shape
        n = len(Xs)
        # Only r_p (inputs m..m+k) changes along the rollout, so everything else of the
        # whitened inputs and of the local means is computed for all samples at once;
        # a step is then two small matrix products: yk = Y0_t + r_p W, m = M0_t + r_p R.
        rp_idx = np.arange(rp_in.start, rp_in.stop)
        known = Xs.copy()
        known[:, rp_idx] = 0.0
        Y0 = np.einsum("nd,kde->nke", known, P) - np.einsum("kd,kde->ke", mu_in, P)[None]
        W = P[:, rp_idx, :].transpose(1, 0, 2).reshape(k, -1)  # (k, K * d)
        M0 = (
            mu_out[None]
            + np.einsum("kqd,nd->nkq", reg, known)
            - np.einsum("kqd,kd->kq", reg, mu_in)[None]
        )
        R = reg[:, :, rp_idx].transpose(2, 0, 1).reshape(k, -1)  # (k, K * q)
        filt = self.branching == "filter"
        T, pri = self.transition_, self.priors_
        # The loop runs once a sample, and the gait designer rolls out thousands of gaits:
        # its scalars come from lists, its reductions are the ufuncs ndarray.sum and .max
        # call and its clip the method np.clip calls, without the Python wrappers. Same
        # arithmetic.
        first, dt, fl = ts.first.tolist(), ts.dt.tolist(), fs.tolist()
        add, largest = np.add.reduce, np.maximum.reduce
        out = np.empty((n, q))
        rp = np.empty((n, k))
        a = pri
        x = Xs[0, rp_idx].copy()
        for t in range(n):
            if first[t]:
                x = Xs[t, rp_idx].copy()
            else:
                x = (x + dt[t] * fl[t - 1] * (gain * out[t - 1, 3 : 3 + k] + off)).clip(lo, hi)
            yk = Y0[t] + (x @ W).reshape(K, -1)
            lg = c.log_norm - 0.5 * add(yk * yk, 1)
            e = np.exp(lg - largest(lg))
            if filt:
                e = e / pri
                a = e * (pri if first[t] else a @ T)
            else:
                a = e
            s = add(a)
            a = a / s if s > 0 else pri
            out[t] = a @ (M0[t] + (x @ R).reshape(K, q))
            rp[t] = x
        rp = rp * self.scale_[rp_in] + self.center_[rp_in]
        return ts.unsort(out * self.scale_[d:] + self.center_[d:]) * f[:, None], ts.unsort(rp)
