"""TLS+F: phase-binned total least squares of a map homogeneous of degree one in the
shape velocity, with separate maps for its positive and negative parts (Finsler contact).

With asymmetric friction the body moves differently when a joint opens and when it
closes (Hatton et al. 2025): v_b = A+(r) [dr_a/dt]+ + A-(r) [dr_a/dt]-, [x]+ = max(x, 0),
[x]- = min(x, 0), linear only when A+ = A-. TLS+F fits that map around the mean gait,
per phase bin k (the bins, windows and mean gait of `tls.TLS`)::

    v_b ~ sum_s (A_s^k + dA_s^k delta) [dr_a/dt]_s,    s in {+, -}

with delta = r_a - r_bar(phase). There is no constant and no delta-only term, so a body
whose shape stands still does not move and the prediction scales with the gait's speed:
TLS's phase-dependent constant C^k, fitted at the training speed, is what keeps TLS from
carrying its map to another gait frequency. `split=False` fits the same map linear in
dr_a/dt (A_+ = A_-), TLS+F's linear twin for an ablation.

Fit: the phase offset from the bin centre multiplies every rate regressor too (the drift
of A across the window; dropped after the fit, as in TLS), and each output is solved by
`tls.tls_solve` through the origin: the total least squares of the samples together with
their mirror image (-X, -y), whose means are zero, is the uncentred one. A bin keeps
separate maps only where they pay for their parameters: the same solve with A+ = A- (the
regressors of each pair summed) is preferred when its BIC is no larger, as it is where
the data pass the bin's shapes one way only or the map is linear there. A rate part that
never occurs inside a bin (a joint that only opens there) has no coefficient in it; its
coefficient there is interpolated from the neighbouring bins where it was seen.
Coefficients are interpolated linearly over phase between bin centres rather than by a
Fourier series, so an A_- known only where the joint closes is not smeared over the rest
of the cycle.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from suds_exp.models import fourier
from suds_exp.models.base import (
    ModelError,
    actuated_columns,
    as_array,
    require_columns,
)
from suds_exp.models.params import Options, Param
from suds_exp.models.tls import TLS, bin_rows, tls_solve
from suds_exp.robot import VB_COLUMNS

_TWO_PI = 2.0 * np.pi


def rate_parts(dra: np.ndarray, split: bool) -> np.ndarray:
    """([dr_a/dt]+, [dr_a/dt]-) side by side, shape (n, 2 m), or dr_a/dt itself."""
    return np.hstack([np.maximum(dra, 0.0), np.minimum(dra, 0.0)]) if split else dra


def finsler_features(delta: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Regressors [u, delta x u], shape (n, s + m s), every one of degree one in u."""
    prod = (delta[:, :, None] * u[:, None, :]).reshape(len(u), -1)
    return np.hstack([u, prod])


def _merge(X: np.ndarray, m: int, scale: bool = False) -> np.ndarray:
    """Split-rate regressors (n, q) -> the linear ones: every ([u_j]+, [u_j]-) pair summed
    (scales: the pair's first, equal by construction). The split columns come in groups
    of 2 m (u+ then u-), the linear ones in groups of m."""
    n, q = X.shape
    G = X.reshape(n, q // (2 * m), 2, m)
    return (G[:, :, 0] if scale else G[:, :, 0] + G[:, :, 1]).reshape(n, q // 2)


def _unmerge(B: np.ndarray, m: int, p: int) -> np.ndarray:
    """Linear coefficients (q / 2, 3) -> split ones (p, 3) with A+ = A-, first p rows."""
    h, o = B.shape
    G = B.reshape(h // m, 1, m, o)
    return np.concatenate([G, G], axis=1).reshape(2 * h, o)[:p]


def _periodic_interp(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """Linear interpolation on the phase circle; xp (k,) increasing in [0, 2 pi),
    fp (k, ...) values there; x (n,) any phases. Returns (n, ...)."""
    x = np.mod(x, _TWO_PI)
    xx = np.concatenate([xp[-1:] - _TWO_PI, xp, xp[:1] + _TWO_PI])
    ff = np.concatenate([fp[-1:], fp, fp[:1]])
    j = np.clip(np.searchsorted(xx, x, side="right") - 1, 0, len(xx) - 2)
    w = ((x - xx[j]) / (xx[j + 1] - xx[j])).reshape((-1,) + (1,) * (fp.ndim - 1))
    return (1 - w) * ff[j] + w * ff[j + 1]


class TLSFinsler(TLS):
    """Phase-binned TLS of v_b on the positive and negative parts of dr_a/dt (see the
    module docstring). Parameters of `TLS` (`gait_order` sets the mean gait's order;
    `coef_order` is unused: coefficients are interpolated linearly between bins), plus

    split : bool, default True
        Separate maps for [dr_a/dt]+ and [dr_a/dt]-; False gives one map linear in
        dr_a/dt (the linear twin).

    Attributes
    ----------
    gait_coef_ : array of shape (2 * gait_order + 1, m)
        Mean gait r_bar(phase) Fourier coefficients (rad).
    bin_coef_ : array of shape (n_bins, s + m s, 3)
        Per-bin coefficients [A_s; dA_s] of vx, vy, wz (s = 2 m parts with split, else
        m); a part unseen in a bin holds the value interpolated from its neighbours.
    seen_ : bool array of shape (n_bins, s + m s)
        Whether each coefficient was fitted in its bin (rather than interpolated).
    kept_fraction_ : float
        Fraction of regressor directions kept by the TLS solves.
    """

    name = "TLS+F"

    _hyper_parameters = TLS._hyper_parameters | {"split": Param(True, Options((True, False)))}

    def fit(self, samples: pd.DataFrame, y=None):
        self._validate()
        ra_cols, dra_cols = actuated_columns(samples)
        need = ("trial_id", "t", "phase", *ra_cols, *dra_cols, *VB_COLUMNS)
        require_columns(samples, need, self.name)
        r = as_array(samples, ra_cols, self.name)
        dra = as_array(samples, dra_cols, self.name)
        Y = as_array(samples, list(VB_COLUMNS), self.name)
        phase = samples["phase"].to_numpy(dtype=float)
        self.rp_columns_, self.drp_columns_ = [], []
        self.ra_columns_, self.dra_columns_ = ra_cols, dra_cols
        self.gait_coef_ = fourier.fit(phase, r, self.gait_order)
        delta = r - fourier.basis(phase, self.gait_order) @ self.gait_coef_
        u = rate_parts(dra, self.split)
        X = finsler_features(delta, u)
        n, p = X.shape
        s = u.shape[1]
        if n < p + 3:
            raise ModelError(
                f"{self.name}: {n} training samples cannot fit {p} regressors; "
                f"give at least {p + 3} samples"
            )
        # Regressors are scaled by the gait's own excursion, as in TLS.
        s_r = np.where(r.std(axis=0) > 0, r.std(axis=0), 1.0)
        s_u = np.tile(np.where(dra.std(axis=0) > 0, dra.std(axis=0), 1.0), s // len(dra_cols))
        sx = np.concatenate([s_u, np.outer(s_r, s_u).ravel()])
        sy = np.where(Y.std(axis=0) > 0, Y.std(axis=0), 1.0)
        need_n = int(np.ceil(self.min_bin_factor * (p + s + 2)))
        centres = np.arange(self.n_bins) * (_TWO_PI / self.n_bins)
        half = 0.5 * self.bin_width * _TWO_PI / self.n_bins
        wrapped = np.mod(phase, _TWO_PI)
        coef = np.zeros((self.n_bins, p, 3))
        seen = np.zeros((self.n_bins, p), dtype=bool)
        n_kept = n_dirs = 0
        for b, c in enumerate(centres):
            off, idx = bin_rows(wrapped, c, half, need_n)
            Xb, sxb = X[idx], sx
            if self.n_bins > 1:
                # A's drift across the window: offset x rate, of degree one in u too
                Xb = np.hstack([Xb, off[idx, None] * u[idx]])
                sxb = np.concatenate([sx, s_u * max(off[idx].std(), 1e-12)])
            # the mirror image makes the centred solve a solve through the origin
            _, B, kept = tls_solve(
                np.vstack([Xb, -Xb]),
                np.vstack([Y[idx], -Y[idx]]),
                self.tls_gap,
                sxb,
                sy,
                self.min_spread,
                self.ridge,
            )
            coef[b] = B[:p]
            seen[b] = np.sqrt((X[idx] ** 2).mean(axis=0)) > self.min_spread * sx
            if self.split:
                # the bin keeps separate maps only where they pay for their parameters
                # (BIC against A+ = A-, whose regressors are the sums of the split ones)
                Xl = _merge(Xb, len(dra_cols))
                _, Bl, _ = tls_solve(
                    np.vstack([Xl, -Xl]),
                    np.vstack([Y[idx], -Y[idx]]),
                    self.tls_gap,
                    _merge(sxb[None], len(dra_cols), scale=True)[0],
                    sy,
                    self.min_spread,
                    self.ridge,
                )
                nb = len(idx)
                rss_s = (((Y[idx] - Xb @ B) / sy) ** 2).sum()
                rss_l = (((Y[idx] - Xl @ Bl) / sy) ** 2).sum()
                k_s, k_l = 3 * Xb.shape[1], 3 * Xl.shape[1]
                bic_s = 3 * nb * np.log(rss_s / (3 * nb)) + k_s * np.log(3 * nb)
                bic_l = 3 * nb * np.log(rss_l / (3 * nb)) + k_l * np.log(3 * nb)
                if bic_l <= bic_s:
                    coef[b] = _unmerge(Bl, len(dra_cols), p)
                    seen[b] = True
            n_kept += kept
            n_dirs += 3 * Xb.shape[1]
        for j in range(p):
            if seen[:, j].any() and not seen[:, j].all():
                coef[~seen[:, j], j] = _periodic_interp(
                    centres[~seen[:, j]], centres[seen[:, j]], coef[seen[:, j], j]
                )
            elif not seen[:, j].any():
                coef[:, j] = 0.0
        self.bin_coef_, self.seen_ = coef, seen
        self.kept_fraction_ = n_kept / n_dirs
        self.n_features_in_ = p
        return self

    def _shape_arrays(self, samples):
        need = ("trial_id", "t", "phase", *self.ra_columns_, *self.dra_columns_)
        require_columns(samples, need, self.name)
        r = as_array(samples, self.ra_columns_, self.name)
        return r, as_array(samples, self.dra_columns_, self.name)

    def _predict_measured(self, samples, r, dra, terms=None):
        phase = samples["phase"].to_numpy(dtype=float)
        delta = r - fourier.basis(phase, self.gait_order) @ self.gait_coef_
        X = finsler_features(delta, rate_parts(dra, self.split))
        centres = np.arange(self.n_bins) * (_TWO_PI / self.n_bins)
        th = _periodic_interp(phase, centres, self.bin_coef_)
        return np.einsum("np,npq->nq", X, th)

    def coefficients(self, phase) -> dict[str, np.ndarray]:
        """The fitted map at the given phases (rad, shape (n,)): `A` (n, 3, s) with
        A[:, i, j] = d out_i / d u_j, u = ([dr_a/dt]+, [dr_a/dt]-) (or dr_a/dt when
        split=False; mm/rad for vx, vy), `dA` (n, 3, s, m) its change with delta, and
        `r_bar` (n, m)."""
        self._check_fitted()
        phase = np.asarray(phase, dtype=float).ravel()
        centres = np.arange(self.n_bins) * (_TWO_PI / self.n_bins)
        th = _periodic_interp(phase, centres, self.bin_coef_)
        m = len(self.ra_columns_)
        s = self.bin_coef_.shape[1] // (1 + m)
        A = th[:, :s, :].transpose(0, 2, 1)
        dA = th[:, s:, :].reshape(len(phase), m, s, 3).transpose(0, 3, 2, 1)
        rbar = fourier.basis(phase, self.gait_order) @ self.gait_coef_
        return {"A": A, "dA": dA, "r_bar": rbar}
