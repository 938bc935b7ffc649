"""Gaussian mixtures: weighted EM (vectorised numpy) and Gaussian mixture regression.

Everything works on standardised data; callers scale. Shapes: X (n_samples, n_features),
weights (n_samples,), priors (K,), means (K, D), covariances (K, D, D).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from suds_exp.models.base import ModelError

_LOG_2PI = np.log(2.0 * np.pi)
# exp(x) is exactly +0.0 for every double x below this (exp(-745.14) already is)
_EXP_ZERO_BELOW = -746.0
# below this exp(x) is subnormal or zero, where numpy's vectorised exp is some 30x slower
_EXP_SUBNORMAL = -708.0


def exp_inplace(a: np.ndarray) -> np.ndarray:
    """np.exp(a) written into `a` (any shape), bit for bit np.exp's values, fast also
    when many entries lie far below -708.

    Log-probabilities shifted by their maximum (EM responsibilities, gates of separated
    components) are often below -745, where the exponential underflows to 0 but numpy
    leaves its vectorised path; those entries are set to 0 directly.
    """
    if a.size and a.min() < _EXP_SUBNORMAL:
        zero = a < _EXP_ZERO_BELOW
        a[zero] = 0.0
        np.exp(a, out=a)
        a[zero] = 0.0
        return a
    return np.exp(a, out=a)


@dataclass
class Mixture:
    """A fitted Gaussian mixture: priors (K,), means (K, D), covariances (K, D, D)."""

    priors: np.ndarray
    means: np.ndarray
    covariances: np.ndarray
    n_iter: int = 0
    converged: bool = False
    log_likelihood: float = np.nan  # weighted mean log-likelihood per sample

    def n_parameters(self) -> int:
        K, D = self.means.shape
        return K * (D + D * (D + 1) // 2) + K - 1


def _cholesky(cov: np.ndarray) -> np.ndarray:
    """Lower Cholesky factors of covariances (K, D, D); raises ModelError if one is not
    positive definite."""
    try:
        L = np.linalg.cholesky(cov)
    except np.linalg.LinAlgError as exc:
        raise ModelError(
            "Gaussian mixture: a component covariance is not positive definite; "
            "decrease n_components or increase reg_covar"
        ) from exc
    return L


def _prec_chol(cov: np.ndarray) -> np.ndarray:
    """Upper factors P with P^T P = inv(cov), shape (K, D, D); raises ModelError."""
    L = _cholesky(cov)
    eye = np.broadcast_to(np.eye(cov.shape[-1]), cov.shape)
    return np.swapaxes(np.linalg.solve(L, eye), -1, -2)


def log_gaussians(X: np.ndarray, means: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """log N(x_n | mean_k, cov_k), shape (n_samples, K)."""
    P = _prec_chol(cov)
    logdet = np.log(np.diagonal(P, axis1=1, axis2=2)).sum(axis=1)
    # (x - m) P = x P - m P: one batched matmul over the components
    y = np.matmul(X[None, :, :], P) - np.einsum("kd,kde->ke", means, P)[:, None, :]
    maha = np.einsum("knd,knd->nk", y, y)
    return -0.5 * (X.shape[1] * _LOG_2PI + maha) + logdet


def row_max(a: np.ndarray) -> np.ndarray:
    """a.max(axis=1) of a (n_samples, K) array, same values, about 4x faster.

    numpy reduces a short last axis row by row; the transposed copy makes it one
    elementwise maximum across K contiguous rows (max is exact, so the bits agree).
    """
    return a.T.copy().max(axis=0)


def _logsumexp(a: np.ndarray) -> np.ndarray:
    """log sum_k exp(a_nk), shape (n_samples,), for a of shape (n_samples, K).

    The same operations in the same order as the textbook form (max, shift, exp, sum,
    log, add back), done in place: the bits are those of that form.
    """
    m = row_max(a)
    e = exp_inplace(a - m[:, None])
    s = e.sum(axis=1)
    np.log(s, out=s)
    s += m
    return s


def _draw(weights: np.ndarray, rng) -> int:
    """One index drawn with probability proportional to `weights` (n,), non-negative."""
    c = np.cumsum(weights)
    return int(min(np.searchsorted(c, rng.uniform() * c[-1], side="right"), len(c) - 1))


def kmeans_pp(X, w, K, rng, n_lloyd: int = 5) -> np.ndarray:
    """Hard labels (n_samples,) from weighted k-means++ seeding and a few Lloyd steps."""
    n = len(X)
    x2 = np.einsum("nd,nd->n", X, X)
    centres = np.empty((K, X.shape[1]))
    centres[0] = X[_draw(w, rng)]
    d2 = np.maximum(x2 - 2.0 * (X @ centres[0]) + centres[0] @ centres[0], 0.0)
    for k in range(1, K):
        q = w * d2
        centres[k] = X[_draw(q if q.sum() > 0 else w, rng)]
        dk = x2 - 2.0 * (X @ centres[k]) + centres[k] @ centres[k]
        np.minimum(d2, np.maximum(dk, 0.0), out=d2)
    Xw = X * w[:, None]
    rows = np.arange(n)
    for _ in range(n_lloyd):
        labels = ((centres * centres).sum(1)[None] - 2.0 * (X @ centres.T)).argmin(1)
        onehot = np.zeros((n, K))
        onehot[rows, labels] = 1.0
        wk = onehot.T @ w
        ok = wk > 0
        centres[ok] = (onehot.T @ Xw)[ok] / wk[ok, None]
    return ((centres * centres).sum(1)[None] - 2.0 * (X @ centres.T)).argmin(1)


class _Moments:
    """Second-moment features x_i x_j (i <= j) of a fixed data set, (n_samples, T).

    With them both EM steps are single matrix products: the Mahalanobis distances are
    X2 @ vec(inv(cov_k)) - 2 X @ inv(cov_k) mean_k + const, and the weighted covariances
    are resp^T X2 / n_k - mean_k mean_k^T. On standardised data the cancellation in the
    latter costs a few digits at most, well inside the regularisation.
    """

    def __init__(self, X: np.ndarray):
        D = X.shape[1]
        self.iu = np.triu_indices(D)
        self.X = X
        self.X2 = X[:, self.iu[0]] * X[:, self.iu[1]]
        self.offdiag = np.where(self.iu[0] == self.iu[1], 1.0, 2.0)

    def log_gaussians(self, means, cov) -> np.ndarray:
        D = means.shape[1]
        L = _cholesky(cov)
        logdet = np.log(np.diagonal(L, axis1=1, axis2=2)).sum(axis=1)
        prec = np.linalg.inv(cov)
        lam = prec[:, self.iu[0], self.iu[1]] * self.offdiag
        b = np.einsum("kij,kj->ki", prec, means)
        c = (means * b).sum(1)
        # -0.5 (D log 2 pi + max(X2 lam - 2 X b + c, 0)) - logdet, operation by operation
        # in place (the EM's inner loop: each temporary of (n_samples, K) costs as much
        # as the arithmetic)
        maha = self.X2 @ lam.T
        xb = self.X @ b.T
        xb *= 2.0
        maha -= xb
        maha += c
        np.maximum(maha, 0.0, out=maha)
        maha += D * _LOG_2PI
        maha *= -0.5
        maha -= logdet
        return maha

    def m_step(self, rw, reg_covar):
        """Priors, means, covariances from weighted responsibilities rw (n_samples, K)."""
        nk = rw.sum(0) + 10 * np.finfo(float).eps
        means = (rw.T @ self.X) / nk[:, None]
        second = (rw.T @ self.X2) / nk[:, None]
        K, D = means.shape
        cov = np.empty((K, D, D))
        i, j = self.iu
        cov[:, i, j] = second - means[:, i] * means[:, j]
        cov[:, j, i] = cov[:, i, j]
        cov += reg_covar * np.eye(D)[None]
        return nk / nk.sum(), means, cov


def fit_mixture(
    X: np.ndarray,
    n_components: int,
    weights: np.ndarray | None = None,
    max_iter: int = 100,
    tol: float = 1e-3,
    reg_covar: float = 1e-4,
    rng: np.random.Generator | None = None,
) -> Mixture:
    """Weighted EM for a full-covariance Gaussian mixture.

    X: (n_samples, D), already standardised; weights: (n_samples,) non-negative sample
    weights (default 1). Initialised from weighted k-means++ with a few Lloyd steps;
    stops when the weighted mean log-likelihood improves by less than `tol` or after
    `max_iter` iterations. `reg_covar` is added to every covariance diagonal.
    """
    rng = rng if rng is not None else np.random.default_rng(0)
    n = len(X)
    if n < n_components:
        raise ModelError(
            f"Gaussian mixture: {n} samples cannot fit n_components={n_components}; "
            "give more data or fewer components"
        )
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
    # multiplying by a weight of exactly 1 changes nothing: skip it when all are 1
    unit = bool((w == 1.0).all())
    mom = _Moments(X)
    labels = kmeans_pp(X, w, n_components, rng)
    resp = np.zeros((n, n_components))
    resp[np.arange(n), labels] = 1.0
    priors, means, cov = mom.m_step(resp * w[:, None], reg_covar)
    wsum = w.sum()
    ll_old = -np.inf
    converged = False
    it = 0
    while it < max_iter:
        it += 1
        logp = mom.log_gaussians(means, cov)
        logp += np.log(priors)
        norm = _logsumexp(logp)
        ll = float(w @ norm / wsum)
        # resp = exp(logp - norm), in place
        logp -= norm[:, None]
        resp = exp_inplace(logp)
        priors, means, cov = mom.m_step(resp if unit else resp * w[:, None], reg_covar)
        if abs(ll - ll_old) < tol:
            converged = True
            break
        ll_old = ll
    return Mixture(priors, means, cov, it, converged, ll)


def responsibilities(X: np.ndarray, mix: Mixture) -> np.ndarray:
    """Posterior component probabilities on the full joint space, (n_samples, K)."""
    logp = log_gaussians(X, mix.means, mix.covariances) + np.log(mix.priors)
    logp -= _logsumexp(logp)[:, None]
    return exp_inplace(logp)


@dataclass
class Conditional:
    """p(y | x) pieces of a mixture for inputs `in_idx` and outputs `out_idx`.

    reg (K, q, d): regression matrices cov_yx cov_xx^-1; mean_in (K, d); mean_out (K, q);
    prec_in (K, d, d) upper precision factors of cov_xx; log_norm (K,) = log prior +
    log normaliser of the input marginal.
    """

    reg: np.ndarray
    mean_in: np.ndarray
    mean_out: np.ndarray
    prec_in: np.ndarray
    log_norm: np.ndarray

    @classmethod
    def of(cls, priors, means, covariances, in_idx, out_idx) -> Conditional:
        in_idx, out_idx = np.asarray(in_idx), np.asarray(out_idx)
        cxx = covariances[:, in_idx][:, :, in_idx]
        cyx = covariances[:, out_idx][:, :, in_idx]
        reg = np.swapaxes(np.linalg.solve(cxx, np.swapaxes(cyx, 1, 2)), 1, 2)
        P = _prec_chol(cxx)
        logdet = np.log(np.diagonal(P, axis1=1, axis2=2)).sum(axis=1)
        log_norm = np.log(priors) + logdet - 0.5 * len(in_idx) * _LOG_2PI
        return cls(reg, means[:, in_idx], means[:, out_idx], P, log_norm)

    def log_gate(self, X: np.ndarray) -> np.ndarray:
        """log prior_k N(x | mean_in_k, cov_xx_k), shape (n_samples, K)."""
        y = (
            np.matmul(X[None], self.prec_in)
            - np.einsum("kd,kde->ke", self.mean_in, self.prec_in)[:, None]
        )
        return self.log_norm - 0.5 * np.einsum("knd,knd->nk", y, y)

    def local_means(self, X: np.ndarray) -> np.ndarray:
        """Each component's conditional mean E[y | x, k], shape (n_samples, K, q)."""
        diff = X[:, None, :] - self.mean_in[None]
        return self.mean_out[None] + np.einsum("kqd,nkd->nkq", self.reg, diff)

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Responsibility-weighted conditional mean E[y | x], shape (n_samples, q)."""
        g = self.log_gate(X)
        h = exp_inplace(g - row_max(g)[:, None])
        h /= h.sum(axis=1, keepdims=True)
        return np.einsum("nk,nkq->nq", h, self.local_means(X))


def conditional_mean(priors, means, covariances, in_idx, X) -> np.ndarray:
    """E[y | x] of a Gaussian mixture (Gaussian mixture regression).

    priors (K,), means (K, D), covariances (K, D, D); in_idx: the conditioned dimensions
    (d,); X (n_samples, d). The outputs are the remaining dimensions in increasing order;
    returns (n_samples, D - d). Same quantity as `gmr.GMM(...).predict(in_idx, X)`.
    """
    in_idx = np.asarray(in_idx, dtype=int)
    out_idx = np.setdiff1d(np.arange(means.shape[1]), in_idx)
    cond = Conditional.of(
        np.asarray(priors, float),
        np.asarray(means, float),
        np.asarray(covariances, float),
        in_idx,
        out_idx,
    )
    return cond.predict(np.asarray(X, dtype=float))
