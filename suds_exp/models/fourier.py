"""Real Fourier series in phase: basis, its phase derivative, least-squares fit."""

from __future__ import annotations

import numpy as np

#: Fourier order of the phase means shared by phase-only and TLS (its mean gait and the
#: outputs' phase mean): the paper defines phase-only as TLS's phase-dependent constant
#: term, so the two must resolve the cycle equally finely. 10 is where phase-only's
#: held-out error stops falling on the simulated robot (same-condition pairs, 30 training
#: cycles; vx of this symmetric swimmer has only even harmonics, which the flippers'
#: stops push up to the 8th-10th; see the README, "The phase-only baseline").
PHASE_ORDER = 10


def basis(phase: np.ndarray, order: int) -> np.ndarray:
    """Fourier basis [1, cos p, sin p, ..., cos(m p), sin(m p)].

    phase: array of shape (n,), rad. Returns an array of shape (n, 2 * order + 1).
    """
    phase = np.asarray(phase, dtype=float)
    m = np.arange(1, order + 1)
    arg = phase[:, None] * m[None, :]
    out = np.empty((len(phase), 2 * order + 1))
    out[:, 0] = 1.0
    out[:, 1::2] = np.cos(arg)
    out[:, 2::2] = np.sin(arg)
    return out


def basis_derivative(phase: np.ndarray, order: int) -> np.ndarray:
    """d/d(phase) of `basis(phase, order)`, shape (n, 2 * order + 1), per rad."""
    return derivative_of_basis(basis(phase, order))


def derivative_of_basis(F: np.ndarray) -> np.ndarray:
    """d/d(phase) of a basis F = `basis(phase, order)` (n, 2 * order + 1), from its own
    sines and cosines (the same values as `basis_derivative`, without new ones)."""
    order = (F.shape[1] - 1) // 2
    m = np.arange(1, order + 1)
    out = np.zeros_like(F)
    out[:, 1::2] = -m * F[:, 2::2]
    out[:, 2::2] = m * F[:, 1::2]
    return out


def fit(phase: np.ndarray, values: np.ndarray, order: int, ridge: float = 1e-9) -> np.ndarray:
    """Least-squares Fourier coefficients of `values` over `phase`.

    phase: (n,) rad; values: (n, q). Returns W of shape (2 * order + 1, q) with
    values ~ basis(phase, order) @ W. `ridge` (relative to the mean diagonal of the
    normal matrix) keeps the solve defined when the phases do not cover the circle.
    """
    return fit_basis(basis(phase, order), values, ridge)


def fit_basis(F: np.ndarray, values: np.ndarray, ridge: float = 1e-9) -> np.ndarray:
    """`fit` on a basis F = `basis(phase, order)` already built (n, 2 * order + 1), so
    a learner fitting several quantities over one phase builds it once."""
    G = F.T @ F
    G[np.diag_indices_from(G)] += ridge * np.trace(G) / len(G)
    return np.linalg.solve(G, F.T @ np.asarray(values, dtype=float).reshape(len(F), -1))
