"""GMR+P and GMR+SUDS+P: GMR with a low-dimensional momentum state (the paper's Future
Work, "systems with low-dimensional momentum").

Model. A body whose momentum matters does not move with the quasi-static velocity
g(r, dr_a/dt) that the reconstruction equation gives; its body velocity lags it. With
drag linear in the velocity error, each body-velocity component j in {vx, vy, wz} relaxes
towards its quasi-static value with a time constant tau_j,

    dv_j/dt = (g_j(r, dr_a/dt) - v_j) / tau_j,

so the momentum state p = v - g has dimension the number of components with tau_j > 0
(0 to 3, chosen from the data: `n_momentum_`). tau_j = 0 is the paper's principally
kinematic system, v = g.

Fit (from samples alone), in two passes.
1. Time constants. The mixture of `GMR` (`GMRSuds`) is fitted to the measured velocity
   and its gates h_k(x) kept; a map with those gates is linear in the local affine
   coefficients, g(x) = Phi(x) theta with Phi = f(x) [h_k(x), h_k(x) x_std] (f the
   homogeneity divisor of GMR's "homogeneous" augmentation, x_std the standardised
   inputs). The lag is a linear filter L_tau, so v ~ L_tau(Phi) theta: for each tau,
   theta is a ridge least-squares fit (shrunk towards GMR's own coefficients), and tau_j
   minimises the training residual of component j (a grid, then Brent's method between
   the grid neighbours of the best). A lag is kept only if it pays for its parameter by
   BIC and cuts the training mean squared error by `lag_min_gain`. No derivative of the
   measured velocity is taken, so its noise is not amplified.
   `n_momentum` (1-3) caps how many components keep a lag: those with the largest tau_j.
2. The quasi-static map. With a lag, GMR is fitted again, to v + (g - L_tau g) of pass 1
   (the measured velocity plus the lag pass 1 explains). Without one, GMR+P is GMR.

Prediction (the paper's protocol): shape in, velocity out. The state is rolled forward
from the shape alone within each trial (each gap-free run of `TimeSeries`); its start is
the end of the run's first gait cycle filtered from rest at the quasi-static value (a
periodic gait's state repeats each cycle), so no measured velocity is ever read.
The filter is the exact discretisation of the relaxation at the run's median sample step.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.optimize import minimize_scalar
from scipy.signal import lfilter

from suds_exp.errors import ConfigError, ModelError
from suds_exp.models.base import (
    Columns,
    TimeSeries,
    as_array,
    require_columns,
)
from suds_exp.models.gmr import GMR, GMR_PARAMETERS, GMRSuds
from suds_exp.models.params import Integer, Param, Real, Rule
from suds_exp.models.suds_variant import SUDS_PARAMETERS
from suds_exp.robot import VB_COLUMNS

#: Most body-velocity components that can carry momentum (vx, vy, wz).
MAX_MOMENTUM = len(VB_COLUMNS)
_TAU_GRID = 12


def lag_filter(values: np.ndarray, ts: TimeSeries, tau: float, phase=None) -> np.ndarray:
    """``values`` (n, p) in `ts` sorted order relaxed with time constant ``tau`` (s):
    y' = (x - y) / tau within each run of ``ts``; the same array when tau = 0.

    A run starts at its first cycle's end, filtered from y = x at its first sample:
    ``phase`` (n,) rad in sorted order marks the cycle (None: the run starts at rest,
    y = x).
    """
    if tau <= 0:
        return values
    out = np.empty_like(values)
    for a, b in zip(ts.starts[:-1], ts.starts[1:], strict=True):
        steps = ts.dt[a + 1 : b]
        dt = float(np.median(steps)) if steps.size else 0.0
        if dt <= 0:
            out[a:b] = values[a:b]
            continue
        alpha = -np.expm1(-dt / tau)
        warm = 0
        if phase is not None:
            # a cycle is 2 pi of phase travelled either way (a gait may run backwards);
            # a run shorter than a cycle warms up on all of itself
            done = np.flatnonzero(np.abs(phase[a:b] - phase[a]) >= 2 * np.pi)
            warm = int(done[0]) if done.size else b - a
        x = values[a:b] if warm == 0 else np.concatenate([values[a : a + warm], values[a:b]])
        zi = (1 - alpha) * x[:1]
        y, _ = lfilter([alpha], [1.0, alpha - 1.0], x, axis=0, zi=zi)
        out[a:b] = y[warm:]
    return out


#: What a momentum learner adds to its GMR's hyper-parameters (see `GMRMomentum`).
MOMENTUM_PARAMETERS: dict[str, Param] = {
    "n_momentum": Param(
        MAX_MOMENTUM,
        Integer(1, MAX_MOMENTUM, why="body-velocity components that may carry momentum"),
    ),
    "tau_max": Param(2.0, Real(0.0, strict=True)),
    "momentum_ridge": Param(1e-3, Real(0.0)),
    "lag_min_gain": Param(0.1, Real(0.0, high=1, high_open=True)),
    "tau": Param(None, Rule(lambda name, value, model: model._fixed_tau())),
}


class _Momentum:
    """What GMR+P and GMR+SUDS+P share; mixed in before `GMR` / `GMRSuds`."""

    def _fixed_tau(self) -> np.ndarray | None:
        """The given time constants (3,) in s, or None when they are to be estimated."""
        if self.tau is None:
            return None
        value = self.tau
        values = list(value) if isinstance(value, tuple | list) else [value] * MAX_MOMENTUM
        ok = len(values) == MAX_MOMENTUM and all(
            isinstance(v, int | float | np.floating | np.integer)
            and not isinstance(v, bool)
            and 0 <= v < np.inf
            for v in values
        )
        if not ok:
            raise ConfigError(
                f"{self.name}: tau={value!r}; expected None (estimate), a time constant "
                "in s >= 0, or one for each of vx, vy, wz"
            )
        return np.array(values, dtype=float)

    # -- features --------------------------------------------------------------------
    def _design(self, samples, inputs=None):
        """(Phi (n, K (1 + d)) in sorted order, TimeSeries, phase in sorted order or None).

        ``inputs``: the model inputs and rate divisor `(Xin, f)` when the caller has them
        (a rollout's r_p), else read from ``samples``.
        """
        Xin, f = self._inputs(samples) if inputs is None else inputs
        d = Xin.shape[1]
        ts = TimeSeries.of(samples)
        Xs = ((Xin - self.center_[:d]) / self.scale_[:d])[ts.order]
        h = self._gates(Xs, ts)
        K = h.shape[1]
        phi = np.empty((len(Xs), K * (1 + d)))
        phi[:, :K] = h
        phi[:, K:] = (h[:, :, None] * Xs[:, None, :]).reshape(len(Xs), K * d)
        phi *= f[ts.order][:, None]
        phase = None
        if "phase" in samples:
            phase = np.asarray(samples["phase"], dtype=float)[ts.order]
        return phi, ts, phase

    def _gmr_coefficients(self, d: int) -> np.ndarray:
        """GMR's own conditional mean in the basis of `_design`: (K (1 + d), 3) for vx,
        vy, wz, so that Phi @ theta is GMR's prediction."""
        c = self._cond
        K = len(self.priors_)
        sl = slice(d, d + MAX_MOMENTUM)
        scale, center = self.scale_[sl], self.center_[sl]
        reg = c.reg[:, :MAX_MOMENTUM, :]  # (K, 3, d)
        mean_out = c.mean_out[:, :MAX_MOMENTUM]
        intercept = mean_out - np.einsum("kqd,kd->kq", reg, c.mean_in)
        theta = np.empty((K * (1 + d), MAX_MOMENTUM))
        theta[:K] = center + scale * intercept
        theta[K:] = (scale[None, :, None] * reg).transpose(0, 2, 1).reshape(K * d, -1)
        return theta

    # -- fit -------------------------------------------------------------------------
    def fit(self, samples: pd.DataFrame, y=None):
        self._validate()
        require_columns(samples, ("trial_id", "t", *VB_COLUMNS), self.name)
        v_all = as_array(samples, VB_COLUMNS, self.name)
        if not np.any(v_all):
            raise ModelError(
                f"{self.name}: the samples' body velocity (vx, vy, wz) is zero everywhere; "
                "a momentum state is learned from measured body velocity"
            )
        super().fit(samples)
        phi, ts, phase = self._design(samples)
        d = self.n_features_in_
        theta0 = self._gmr_coefficients(d)
        v = v_all[ts.order]
        gram_scale = float(np.mean(np.einsum("np,np->p", phi, phi))) or 1.0
        lam = self.momentum_ridge * gram_scale
        eye = np.eye(phi.shape[1])

        def solve(tau):
            F = lag_filter(phi, ts, tau, phase)
            resid0 = v - F @ theta0
            delta = np.linalg.solve(F.T @ F + lam * eye, F.T @ resid0)
            theta = theta0 + delta
            return theta, np.mean((v - F @ theta) ** 2, axis=0)

        steps = ts.dt[ts.dt > 0]
        dt = float(np.median(steps)) if steps.size else 0.0
        lo = max(dt, 1e-3)
        grid = np.concatenate([[0.0], np.geomspace(lo, max(self.tau_max, lo), _TAU_GRID)])
        fixed = self._fixed_tau()
        if fixed is None:
            errors = np.array([solve(tau)[1] for tau in grid])  # (n_grid, 3)
        tau = np.zeros(MAX_MOMENTUM)
        for j in range(MAX_MOMENTUM if fixed is None else 0):
            i = int(np.argmin(errors[:, j]))
            if i == 0:
                continue
            a, b = grid[i - 1], grid[min(i + 1, len(grid) - 1)]
            best = minimize_scalar(
                lambda s, j=j: solve(s)[1][j],
                bounds=(a, b),
                method="bounded",
                options={"xatol": 0.01 * grid[i]},
            )
            value, err = (best.x, best.fun) if best.fun < errors[i, j] else (grid[i], errors[i, j])
            # A lag is kept only if it pays for its parameter (BIC) and cuts the error by
            # `lag_min_gain`: a GMR map's misfit correlates along the gait, and a few
            # per cent of it a short lag always absorbs (measured: 4 % on the lag-free
            # synthetic swimmer, 33 % or more with a 0.05 s lag).
            gain = 1.0 - err / errors[0, j]
            if len(v) * np.log(errors[0, j] / err) > np.log(len(v)) and gain >= self.lag_min_gain:
                tau[j] = value
        if fixed is not None:
            tau = fixed.copy()
        # components beyond n_momentum (those with the shortest lags) are quasi-static
        keep = np.argsort(-tau, kind="stable")[: self.n_momentum]
        tau[np.setdiff1d(np.arange(MAX_MOMENTUM), keep)] = 0.0
        self.tau_ = tau
        self.n_momentum_ = int(np.count_nonzero(tau))
        if self.n_momentum_:
            # The quasi-static velocity is the measured one plus the lag the surrogate
            # explains (g - L_tau g): no derivative of the noisy measurement. GMR is then
            # fitted to it as to any velocity, so with no lag GMR+P is GMR.
            lagged = np.empty_like(v)
            quasi = np.empty_like(v)
            for value in np.unique(tau):
                cols = np.flatnonzero(tau == value)
                theta = solve(value)[0][:, cols]
                quasi[:, cols] = phi @ theta
                lagged[:, cols] = lag_filter(phi, ts, value, phase) @ theta
            target = ts.unsort(v + quasi - lagged)
            frame = samples.assign(**{c: target[:, i] for i, c in enumerate(VB_COLUMNS)})
            super().fit(frame)
        return self

    @property
    def time_constant_(self) -> float:
        """The longest learned time constant, s (0: no momentum)."""
        return float(np.max(self.tau_))

    # -- predict ---------------------------------------------------------------------
    def _momentum_velocity(self, samples, inputs=None) -> np.ndarray:
        """vx, vy, wz (n, 3) rolled forward from the shape alone, caller's order."""
        Xin, f = self._inputs(samples) if inputs is None else inputs
        d = Xin.shape[1]
        ts = TimeSeries.of(samples)
        Xs = ((Xin - self.center_[:d]) / self.scale_[:d])[ts.order]
        h = self._gates(Xs, ts)
        ys = np.einsum("nk,nkq->nq", h, self._cond.local_means(Xs)[:, :, :MAX_MOMENTUM])
        quasi = ys * self.scale_[d : d + MAX_MOMENTUM] + self.center_[d : d + MAX_MOMENTUM]
        quasi *= f[ts.order][:, None]
        phase = np.asarray(samples["phase"], dtype=float)[ts.order] if "phase" in samples else None
        out = np.empty_like(quasi)
        for value in np.unique(self.tau_):
            cols = np.flatnonzero(self.tau_ == value)
            out[:, cols] = lag_filter(quasi[:, cols], ts, value, phase)
        return ts.unsort(out)


class GMRMomentum(_Momentum, GMR):
    """GMR with a momentum state: body velocity relaxing to a learned quasi-static GMR map
    with learned time constants (see the module docstring). Parameters of `GMR` plus

    n_momentum : int from 1 to 3, default 3
        Most body-velocity components that may carry momentum; each gets its own time
        constant, and those the data give no lag stay quasi-static.
    tau_max : float, default 2.0
        Longest time constant searched, s.
    momentum_ridge : float, default 1e-3
        Ridge weight of pass 1's fit towards GMR's own coefficients, relative to the
        mean squared feature.
    lag_min_gain : float in [0, 1), default 0.1
        Fraction of a component's training mean squared error a lag must remove to be
        kept.
    tau : None, float or three floats, default None
        None: the time constants are estimated from the training samples. A number (s)
        or one per vx, vy, wz: fixed, e.g. the estimate of `momentum_information` on
        data at several speeds. A strictly periodic gait at one speed cannot tell a lag
        from a different quasi-static map (a lag of a periodic signal is another
        periodic signal), so a training set of one condition rarely identifies tau.

    Attributes (besides GMR's): ``tau_`` (3,) time constants of vx, vy, wz in s (0: no
    lag); ``n_momentum_`` the momentum dimension the data chose; ``momentum_coef_``
    (K (1 + d), 3) the quasi-static map's coefficients; ``time_constant_`` the longest
    tau, s.
    """

    name = "GMR+P"
    _hyper_parameters = GMR_PARAMETERS | MOMENTUM_PARAMETERS

    def predict_array(self, samples: pd.DataFrame | Columns) -> np.ndarray:
        self._check_fitted()
        require_columns(samples, ("trial_id", "t", *self.columns_in_), self.name)
        return self._momentum_velocity(samples)


class GMRSudsMomentum(_Momentum, GMRSuds):
    """GMR+SUDS with a momentum state on its body velocity (see `GMRMomentum`); dr_p/dt
    is GMR+SUDS's, and in ``mode="rollout"`` the quasi-static map reads the rolled-out
    r_p. Parameters of `GMRSuds` plus those of `GMRMomentum`."""

    name = "GMR+SUDS+P"
    _hyper_parameters = GMR_PARAMETERS | SUDS_PARAMETERS | MOMENTUM_PARAMETERS

    def predict_array(self, samples: pd.DataFrame | Columns) -> np.ndarray:
        out = super().predict_array(samples)  # checks; dr_p/dt (and r_p) of GMR+SUDS
        inputs = None
        if self.mode == "rollout":
            rp = self._predict_rollout(samples)[1]
            frame = samples.frame() if isinstance(samples, Columns) else samples
            frame = frame.assign(**{c: rp[:, i] for i, c in enumerate(self.rp_columns_)})
            inputs = self._inputs(frame)
        out[:, :MAX_MOMENTUM] = self._momentum_velocity(samples, inputs)
        return out
