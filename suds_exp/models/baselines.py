"""Regressors of the survey that scikit-learn has only as parts: kernel ridge on Nystroem
features (`KRR`), the posterior mean of a Gaussian process with an RBF kernel restricted
to `n_components` landmarks (a sparse/approximate GP), O(n m^2) instead of O(n^3)."""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.kernel_approximation import Nystroem
from sklearn.linear_model import Ridge


class NystroemKRR(RegressorMixin, BaseEstimator):
    """Kernel ridge regression with an RBF kernel on `n_components` Nystroem landmarks.

    Parameters
    ----------
    n_components : int, default 300
        Landmarks (training samples drawn at random); fewer when there are fewer samples.
    gamma : float or None, default None
        RBF width exp(-gamma |x - x'|^2); None = 1 / n_features (standardised inputs).
    alpha : float, default 1e-3
        Ridge penalty (the GP's noise variance relative to the signal's).
    random_state : int or None, default None
        Seed of the landmark draw.
    """

    def __init__(self, n_components=300, gamma=None, alpha=1e-3, random_state=None):
        self.n_components = n_components
        self.gamma = gamma
        self.alpha = alpha
        self.random_state = random_state

    def fit(self, X, y):
        X = np.asarray(X, dtype=float)
        gamma = 1.0 / X.shape[1] if self.gamma is None else self.gamma
        self.features_ = Nystroem(
            kernel="rbf",
            gamma=gamma,
            n_components=min(int(self.n_components), len(X)),
            random_state=self.random_state,
        ).fit(X)
        self.ridge_ = Ridge(alpha=self.alpha).fit(self.features_.transform(X), y)
        self.n_features_in_ = X.shape[1]
        return self

    def predict(self, X):
        return self.ridge_.predict(self.features_.transform(np.asarray(X, dtype=float)))
