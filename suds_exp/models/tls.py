"""Phase-based total least squares: TLS (Bittner, Hatton, Revzen 2018) and TLS+SUDS.

Model (per phase bin k, Bittner et al. 2018 eq. for v_b)::

    v_b ~ C^k + B^k delta + A^k delta_dot_a + dA^k (delta x delta_dot_a)

- r_bar(phase): mean gait, Fourier series of order `gait_order` fitted to r by least
  squares; delta = r - r_bar(phase); delta_dot_a = dr_a/dt - r_bar_a'(phase) dphase/dt,
  with dphase/dt estimated from the unwrapped phase column within each trial.
- TLS uses r = r_a. TLS+SUDS (Bittner et al. 2022) uses r = (r_a, r_p) and fits the
  passive dynamics dr_p/dt = C(r) dr_a/dt + D(r) alongside, linearised the same way
  (same regressors, outputs (v_b, dr_p/dt) in one total least squares per bin). Only
  dr_a/dt enters the right-hand side: SUDS makes dr_p/dt unnecessary there.
- The outputs' phase mean (Fourier order `gait_order`) is removed first and added back
  at prediction, so a bin only carries the residual.
- Each bin is a window of the phase circle (`n_bins` centres, window `bin_width` bins
  wide) with the phase offset from the centre as one more regressor (dropped after the
  fit); a bin holding fewer than `min_bin_factor` x (regressors + 2) samples takes that
  many phase-nearest samples instead, so few-cycle training stays defined.
- Total least squares (errors in variables): centre [X y] on the bin means, scale the
  columns by the gait's whole excursion (std over the training data of r, of dr_a/dt,
  their products for the bilinear terms, and of each output), take the SVD solution per
  output (`tls_solve`). Regressor directions whose spread inside the bin is below
  `min_spread` of that excursion are dropped (with one or two cycles delta is almost
  constant per bin, and fitting it would extrapolate wildly), and so are directions
  with no more spread than the noise (`tls_gap`): TLS explodes on those, e.g. r_p
  following r_a almost exactly. An optional `ridge` shrinks the rest.
- The bin coefficients (C, B, A, dA) are interpolated over phase by a Fourier series of
  order `coef_order` fitted to the bin centres.

Rollout (TLS+SUDS, mode="rollout"): at fixed phase and r_a the fitted dr_p/dt is affine
in r_p, dr_p/dt = a_t + M_t r_p, so r_p is integrated from each trial's first measured
value by the trapezoidal rule (A-stable, second order), clipped to the training range
widened by a tenth of its width: the test trial's r_p is used only at its first sample.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from suds_exp.errors import ConfigError
from suds_exp.models import fourier
from suds_exp.models.base import (
    Learner,
    ModelError,
    TimeSeries,
    actuated_columns,
    as_array,
    phase_rate,
    require_columns,
    rollout_bounds,
)
from suds_exp.models.params import Integer, Param, Real
from suds_exp.models.suds_variant import SUDS_PARAMETERS, check_mode, required_passive_columns
from suds_exp.robot import VB_COLUMNS

_TWO_PI = 2.0 * np.pi


def tls_solve(
    X: np.ndarray,
    Y: np.ndarray,
    gap: float = 2.0,
    scale_x: np.ndarray | None = None,
    scale_y: np.ndarray | None = None,
    min_spread: float = 0.0,
    ridge: float = 0.0,
):
    """Total least squares Y ~ c + X B from the SVD of the centred, column-scaled data.

    X: (n, p); Y: (n, q); each output is solved on its own after dividing every column
    of X and y by a scale: `scale_x` (p,), `scale_y` (q,) when given (TLS uses the
    spread over all training data, so that a regressor that barely moves inside one bin
    stays small instead of being blown up to unit variance), else the column's own
    standard deviation. Directions of the scaled regressors whose RMS spread is below
    `min_spread` are not identifiable from these samples and are dropped. With
    Xs = U S V^T (principal components of the regressors) and sigma the smallest singular
    value of [Xs ys], the TLS solution is
    b = V (S^2 - sigma^2 I)^-1 S U^T ys, the closed form of the SVD solution of [Xs ys].
    TLS is undefined (and explodes) when a regressor direction carries no more spread
    than the noise, as with r_p following r_a almost exactly; such directions
    (S_i^2 <= gap * sigma^2, recomputing sigma on the directions kept) are truncated,
    which bounds the TLS de-attenuation of any kept direction by 1 / (1 - 1 / gap).
    `ridge` (scaled units, per sample) adds ridge * n to S^2 - sigma^2. Columns with zero
    spread get coefficient 0.

    Returns (c of shape (q,), B of shape (p, q), number of regressor directions kept,
    summed over outputs).
    """
    n, p = X.shape
    q = Y.shape[1]
    xm, ym = X.mean(axis=0), Y.mean(axis=0)
    Xc, Yc = X - xm, Y - ym
    sx = Xc.std(axis=0) if scale_x is None else np.asarray(scale_x, dtype=float)
    sy = Yc.std(axis=0) if scale_y is None else np.asarray(scale_y, dtype=float)
    live = (Xc.std(axis=0) > 1e-12 * max(1.0, float(np.abs(X).max(initial=0.0)))) & (sx > 0)
    sy = np.where(sy > 0, sy, 1.0)
    B = np.zeros((p, q))
    n_kept = 0
    if not live.any():
        return ym, B, n_kept
    Xs = Xc[:, live] / sx[live]
    U, S, Vt = np.linalg.svd(Xs, full_matrices=False)
    Ys = Yc / sy
    proj = U.T @ Ys  # (r, q): each output in principal-component coordinates
    resid2 = np.maximum((Ys * Ys).sum(axis=0) - (proj * proj).sum(axis=0), 0.0)
    for j in range(q):
        keep = (S > 1e-12 * S[0]) & (S > min_spread * np.sqrt(n))
        for _ in range(4):
            # smallest singular value of [U_k S_k, ys]: the smallest root of the secular
            # equation, found from the small (k+1) x (k+1) Gram matrix.
            k = int(keep.sum())
            if k == 0:
                break
            G = np.empty((k + 1, k + 1))
            G[:k, :k] = np.diag(S[keep] ** 2)
            G[:k, k] = G[k, :k] = S[keep] * proj[keep, j]
            G[k, k] = (proj[keep, j] ** 2).sum() + resid2[j] + (proj[~keep, j] ** 2).sum()
            sig2 = max(float(np.linalg.eigvalsh(G)[0]), 0.0)
            new = keep & (S**2 > gap * sig2)
            if (new == keep).all():
                break
            keep = new
        if keep.any():
            bpc = S[keep] * proj[keep, j] / (S[keep] ** 2 - sig2 + ridge * n)
            B[live, j] = (Vt[keep].T @ bpc) / sx[live] * sy[j]
            n_kept += int(keep.sum())
    return ym - xm @ B, B, n_kept


def bin_rows(wrapped: np.ndarray, centre: float, half: float, need_n: int):
    """A phase bin's samples: ``off`` (n,), every sample's phase offset from ``centre``
    (rad, in (-pi, pi]), and ``idx``, the samples within ``half`` of it, or the ``need_n``
    nearest when fewer are (all of them if there are fewer samples)."""
    off = np.angle(np.exp(1j * (wrapped - centre)))
    d = np.abs(off)
    idx = np.flatnonzero(d <= half)
    if len(idx) < need_n:
        k = min(need_n, len(d))
        idx = np.argpartition(d, k - 1)[:k]
    return off, idx


def _features(delta: np.ndarray, ddot: np.ndarray) -> np.ndarray:
    """Regressors [delta, delta_dot_a, delta x delta_dot_a], shape (n, m + a + m*a)."""
    prod = (delta[:, :, None] * ddot[:, None, :]).reshape(len(delta), -1)
    return np.hstack([delta, ddot, prod])


class TLS(Learner):
    """Phase-binned total least squares motility map (see the module docstring).

    Parameters
    ----------
    n_bins : int, default 16
        Number of phase bins (centres evenly spaced on [0, 2 pi)).
    bin_width : float, default 1.5
        Width of each bin's phase window, in units of the bin spacing (1 = disjoint).
    gait_order : int, default `fourier.PHASE_ORDER` (10)
        Fourier order of the mean gait r_bar(phase) and of the outputs' phase mean (the
        same default as phase-only, which is this model's constant term).
    coef_order : int, default 3
        Fourier order used to interpolate the bin coefficients over phase;
        2 * coef_order + 1 must not exceed n_bins.
    min_bin_factor : float, default 2.0
        A bin uses at least this many times (regressors + 2) samples.
    tls_gap : float, default 2.0
        Regressor directions whose squared singular value is not above tls_gap times the
        TLS noise level are truncated (> 1; large values approach principal-component
        regression, values near 1 plain TLS).
    min_spread : float, default 0.05
        Regressor directions whose RMS spread inside a bin is below this fraction of the
        gait's excursion are dropped (not identifiable from the bin).
    ridge : float, default 0.0
        Ridge shrinkage of the TLS solve, in scaled units per sample.

    Attributes
    ----------
    gait_coef_ : array of shape (2 * gait_order + 1, n_r)
        Mean gait r_bar(phase) Fourier coefficients (rad for r_a, r_p units for r_p).
    coef_ : array of shape (2 * coef_order + 1, 1 + n_regressors, n_outputs)
        Fourier coefficients over phase of [C; B; A; dA] per output (C without the
        phase mean).
    mean_coef_ : array of shape (2 * gait_order + 1, n_outputs)
        Fourier coefficients of the outputs' phase mean.
    bin_coef_ : array of shape (n_bins, 1 + n_regressors, n_outputs)
        The raw per-bin TLS coefficients.
    kept_fraction_ : float
        Fraction of regressor directions kept by the TLS solves (see `tls_solve`), over
        bins and outputs; well below 1 means nearly collinear regressors.
    """

    name = "TLS"
    _hyper_parameters = {
        "n_bins": Param(16, Integer(1)),
        "bin_width": Param(1.5, Real(0.0, strict=True)),
        "gait_order": Param(fourier.PHASE_ORDER, Integer(0)),
        "coef_order": Param(3, Integer(0)),
        "min_bin_factor": Param(2.0, Real(1.0)),
        "tls_gap": Param(2.0, Real(1.0, strict=True)),
        "min_spread": Param(0.05, Real(0.0)),
        "ridge": Param(0.0, Real(0.0)),
    }

    # -- columns -------------------------------------------------------------------
    def _shape_columns(self, samples):
        return [], []

    def _output_columns(self):
        return list(VB_COLUMNS)

    def _validate(self):
        super()._validate()
        nb, co = int(self.n_bins), int(self.coef_order)
        if 2 * co + 1 > nb:
            raise ConfigError(
                f"{self.name}: coef_order={co} needs n_bins >= {2 * co + 1}, got n_bins={nb}"
            )

    # -- shared pieces -----------------------------------------------------------------
    def _offsets(self, samples, r, dra, F):
        """delta (n, n_r) and delta_dot_a (n, m) from the mean gait; F (n, 2 gait_order
        + 1) the Fourier basis at the samples' phases."""
        rbar = F @ self.gait_coef_
        m = len(self.ra_columns_)
        drbar_a = fourier.derivative_of_basis(F) @ self.gait_coef_[:, :m]
        return r - rbar, dra - drbar_a * phase_rate(samples)[:, None]

    def _coef_at(self, phase):
        """Coefficients at each sample's phase, shape (n, 1 + n_regressors, n_outputs)."""
        F = fourier.basis(phase, self.coef_order)
        return np.einsum("nf,fpq->npq", F, self.coef_)

    def coefficients(self, phase) -> dict[str, np.ndarray]:
        """The fitted model's terms at the given phases (rad, array of shape (n,)).

        Returns a dict of arrays: `C` (n, q); `B` (n, q, n_r) with B[:, i, j] = d out_i /
        d delta_j; `A` (n, q, m) with A[:, i, j] = d out_i / d delta_dot_a_j (the
        connection, e.g. mm/rad for vx); `dA` (n, q, m, n_r) with dA[:, i, j, l] =
        d A[i, j] / d r_l; `r_bar` (n, n_r). q runs over vx, vy, wz (then dr_p/dt).
        """
        self._check_fitted()
        phase = np.asarray(phase, dtype=float).ravel()
        th = self._coef_at(phase)
        m, a = self.gait_coef_.shape[1], len(self.dra_columns_)
        C = th[:, 0, :] + fourier.basis(phase, self.gait_order) @ self.mean_coef_
        B = th[:, 1 : 1 + m, :].transpose(0, 2, 1)
        A = th[:, 1 + m : 1 + m + a, :].transpose(0, 2, 1)
        dA = th[:, 1 + m + a :, :].reshape(len(phase), m, a, -1).transpose(0, 3, 2, 1)
        rbar = fourier.basis(phase, self.gait_order) @ self.gait_coef_
        return {"C": C, "B": B, "A": A, "dA": dA, "r_bar": rbar}

    def fit(self, samples: pd.DataFrame, y=None):
        self._validate()
        rp_cols, drp_cols = self._shape_columns(samples)
        ra_cols, dra_cols = actuated_columns(samples)
        out_cols = self._output_columns() + drp_cols
        need = ("trial_id", "t", "phase", *ra_cols, *dra_cols, *rp_cols, *out_cols)
        require_columns(samples, need, self.name)
        r = as_array(samples, ra_cols + rp_cols, self.name)
        dra = as_array(samples, dra_cols, self.name)
        Y = as_array(samples, out_cols, self.name)
        phase = samples["phase"].to_numpy(dtype=float)
        self.rp_columns_, self.drp_columns_ = rp_cols, drp_cols
        self.ra_columns_, self.dra_columns_ = ra_cols, dra_cols

        F = fourier.basis(phase, self.gait_order)  # built once, used four times
        self.gait_coef_ = fourier.fit_basis(F, r)
        # The phase mean of the outputs (order gait_order) is taken out before binning,
        # so a bin's window only has to carry the residual's drift, not C's curvature.
        self.mean_coef_ = fourier.fit_basis(F, Y)
        sy = Y.std(axis=0)  # outputs, like the regressors, scaled by their whole excursion
        Y = Y - F @ self.mean_coef_
        delta, ddot = self._offsets(samples, r, dra, F)
        X = _features(delta, ddot)
        n, p = X.shape
        q = Y.shape[1]
        need_n = int(np.ceil(self.min_bin_factor * (p + 2)))
        if n < p + 3:
            raise ModelError(
                f"{self.name}: {n} training samples cannot fit {p} regressors and {q} outputs; "
                f"give at least {p + 3} samples"
            )
        centres = np.arange(self.n_bins) * (_TWO_PI / self.n_bins)
        half = 0.5 * self.bin_width * _TWO_PI / self.n_bins
        wrapped = np.mod(phase, _TWO_PI)
        # Regressors are scaled by the gait's own excursion (std of r and of dr_a/dt over
        # the training data), not by their spread: delta is tiny when few cycles are
        # seen, and inflating it to unit variance would hide that it is unidentifiable.
        s_r = np.where(r.std(axis=0) > 0, r.std(axis=0), 1.0)
        s_d = np.where(dra.std(axis=0) > 0, dra.std(axis=0), 1.0)
        sx = np.concatenate([s_r, s_d, np.outer(s_r, s_d).ravel()])
        bin_coef = np.empty((self.n_bins, p + 1, q))
        n_kept = 0
        for b, c in enumerate(centres):
            off, idx = bin_rows(wrapped, c, half, need_n)
            # The phase offset inside the window is a regressor too, so the drift of C
            # across the window is not mistaken for noise; it is dropped afterwards
            # (the bin's coefficients are those at the centre, offset 0). A single bin
            # spans the whole circle, where an offset is meaningless.
            if self.n_bins > 1:
                Xb = np.column_stack([X[idx], off[idx]])
                sxb = np.append(sx, off[idx].std())
                c0, Bm, kept = tls_solve(
                    Xb, Y[idx], self.tls_gap, sxb, sy, self.min_spread, self.ridge
                )
                Bm = Bm[:-1]
            else:
                c0, Bm, kept = tls_solve(
                    X[idx], Y[idx], self.tls_gap, sx, sy, self.min_spread, self.ridge
                )
            bin_coef[b, 0], bin_coef[b, 1:] = c0, Bm
            n_kept += kept
        self.bin_coef_ = bin_coef
        self.kept_fraction_ = n_kept / (self.n_bins * q * (p + (self.n_bins > 1)))
        if rp_cols:
            self.rp_bounds_ = rollout_bounds(r[:, len(ra_cols) :])
        W = fourier.fit(centres, bin_coef.reshape(self.n_bins, -1), self.coef_order)
        self.coef_ = W.reshape(-1, p + 1, q)
        self.n_features_in_ = p
        return self

    def _shape_arrays(self, samples):
        """r = (r_a, r_p) (n, m + k) and dr_a/dt (n, m) of the fitted columns."""
        ra, dra = self.ra_columns_, self.dra_columns_
        need = ("trial_id", "t", "phase", *ra, *dra, *self.rp_columns_)
        require_columns(samples, need, self.name)
        r = as_array(samples, ra + self.rp_columns_, self.name)
        return r, as_array(samples, dra, self.name)

    def _phase_terms(self, samples):
        """What a prediction needs of the samples' phases alone: (the Fourier basis
        (n, 2 gait_order + 1), the coefficients there (n, 1 + n_regressors, n_outputs))."""
        phase = samples["phase"].to_numpy(dtype=float)
        return fourier.basis(phase, self.gait_order), self._coef_at(phase)

    def _predict_measured(self, samples, r, dra, terms=None):
        F, th = self._phase_terms(samples) if terms is None else terms
        delta, ddot = self._offsets(samples, r, dra, F)
        X1 = np.hstack([np.ones((len(r), 1)), _features(delta, ddot)])
        mean = F @ self.mean_coef_
        return mean + np.einsum("np,npq->nq", X1, th)

    def predict(self, samples: pd.DataFrame) -> pd.DataFrame:
        """Predicted vx, vy (mm/s), wz (rad/s) [, drp_1..drp_k], same index as `samples`."""
        self._check_fitted()
        r, dra = self._shape_arrays(samples)
        return self._output_frame(self._predict_measured(samples, r, dra), samples)


class TLSSuds(TLS):
    """TLS with r = (r_a, r_p) and passive dynamics dr_p/dt = C(r) dr_a/dt + D(r).

    Parameters are those of `TLS` plus

    mode : {"measured", "rollout"}, default "measured"
        "measured" uses the test trial's r_p at every sample; "rollout" integrates r_p
        from each trial's first sample with the learned passive dynamics.

    Requires at least one `rp_i` column; k = number of `rp_1..rp_k` columns present.
    """

    name = "TLS+SUDS"
    suds = True
    _hyper_parameters = TLS._hyper_parameters | SUDS_PARAMETERS

    def _shape_columns(self, samples):
        rp, drp = required_passive_columns(samples, self.name)
        return rp, drp

    def predict(self, samples: pd.DataFrame) -> pd.DataFrame:
        """Predicted vx, vy, wz and drp_1..drp_k; rollout mode integrates r_p per trial."""
        self._check_fitted()
        check_mode(self.mode, self.name)
        if self.mode == "measured":
            return super().predict(samples)
        r, dra = self._shape_arrays(samples)
        r = r.copy()
        r[:, len(self.ra_columns_) :] = self._rollout(samples, r, dra)
        return self._output_frame(self._predict_measured(samples, r, dra), samples)

    def rollout(self, samples: pd.DataFrame) -> pd.DataFrame:
        """r_p integrated from each trial's first sample, columns rp_1..rp_k, input's index.

        Uses phase, r_a, dr_a/dt of every sample and r_p of each trial's first sample only.
        """
        self._check_fitted()
        r, dra = self._shape_arrays(samples)
        return pd.DataFrame(
            self._rollout(samples, r, dra), index=samples.index, columns=self.rp_columns_
        )

    def _rollout(self, samples, r, dra):
        """r_p integrated from each trial's first sample, shape (n, k), caller's order."""
        k = len(self.rp_columns_)
        n, m = len(r), len(self.ra_columns_)
        r0 = r.copy()
        r0[:, m:] = 0.0
        terms = self._phase_terms(samples)
        base = self._predict_measured(samples, r0, dra, terms)[:, 3:]  # dr_p/dt at r_p = 0
        # Columns of M: response of dr_p/dt to a unit r_p_i, got by linearity in r_p.
        M = np.empty((n, k, k))
        for i in range(k):
            ri = r0.copy()
            ri[:, m + i] = 1.0
            M[:, :, i] = self._predict_measured(samples, ri, dra, terms)[:, 3:] - base
        ts = TimeSeries.of(samples)
        o = ts.order
        a, M, dt = base[o], M[o], ts.dt
        eye = np.eye(k)
        h = 0.5 * dt[:, None, None]
        lhs_inv = np.linalg.inv(eye - h * M)
        M_prev = np.concatenate([M[:1], M[:-1]])
        a_prev = np.concatenate([a[:1], a[:-1]])
        P = lhs_inv @ (eye + h * M_prev)
        c = np.einsum("nij,nj->ni", lhs_inv, h[:, :, 0] * (a + a_prev))
        rp_meas = r[o, m:]
        out = np.empty((n, k))
        first = ts.first
        lo, hi = self.rp_bounds_
        x = rp_meas[0]
        for i in range(n):
            x = rp_meas[i] if first[i] else np.clip(P[i] @ x + c[i], lo, hi)
            out[i] = x
        return ts.unsort(out)
