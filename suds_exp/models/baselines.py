"""The survey's named scikit-learn baselines (`BASELINES`: MLP, GBT, kNN, KRR, each also
with +SUDS) and the regressor scikit-learn has only as parts: kernel ridge on Nystroem
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


# -- the named baselines ----------------------------------------------------------------
def _mlp():
    from sklearn.neural_network import MLPRegressor

    return MLPRegressor


def _gbt():
    from sklearn.ensemble import HistGradientBoostingRegressor

    return HistGradientBoostingRegressor


def _knn():
    from sklearn.neighbors import KNeighborsRegressor

    return KNeighborsRegressor


def _krr():
    return NystroemKRR


#: name -> (class factory, default parameters); each also exists with +SUDS.
BASELINES: dict[str, tuple] = {
    # One network for all outputs (3, or 7 with +SUDS): two hidden layers of 64 tanh
    # units, L2 1e-4, float32 as neural-network libraries train, fitted by L-BFGS for at
    # most 200 iterations (scikit-learn's default budget). scikit-learn's MLPRegressor
    # docs: Adam "works pretty well on relatively large datasets (thousands of training
    # samples or more) ... For small datasets, however, 'lbfgs' can converge faster and
    # perform better"; a campaign trains on 100-4800 samples. Measured against the
    # former Adam default (lr 1e-3, early stopping on 10 %) by benchmarks/models.py
    # section 4 (30 training cycles, seeds 0 and 1; README, Speed of the survey
    # learners): MLP+SUDS half the CPU (1.01 vs 2.06 s), the same held-out error on its
    # training condition and lower on three others; the MLP lower error on all four but
    # twice the CPU (0.98 vs 0.52 s). L-BFGS has no early stopping (scikit-learn ignores
    # it for that solver): its 200-iteration budget (scikit-learn's default) is the rule.
    "MLP": (
        _mlp,
        {
            "hidden_layer_sizes": (64, 64),
            "activation": "tanh",
            "alpha": 1e-4,
            "solver": "lbfgs",
            "max_iter": 200,
            "dtype": "float32",
        },
    ),
    # Histogram gradient-boosted trees, one model per output, early stopping on 10 %.
    "GBT": (
        _gbt,
        {"max_iter": 200, "learning_rate": 0.1, "max_leaf_nodes": 31, "early_stopping": True},
    ),
    # Distance-weighted mean of the 10 nearest training samples (standardised inputs).
    "kNN": (_knn, {"n_neighbors": 10, "weights": "distance"}),
    # Kernel ridge / GP posterior mean with an RBF kernel on 300 Nystroem landmarks.
    "KRR": (_krr, {}),
}


#: The baselines' settings that a faster one could change, as the seed-tolerance survey
#: judged them (`benchmarks/studies/survey_tolerance.py`, docs/results/speed.md): every
#: faster setting tried fell outside the baselines' own seed-to-seed spread, so the defaults
#: are these. Written out apart from the defaults: the survey's reference must not move
#: with them, and a test fails when a default leaves the judged recipe.
JUDGED_RECIPES = {
    "MLP": {"hidden_layer_sizes": [64, 64], "max_iter": 200, "tol": 1e-4},
    "GBT": {
        "max_iter": 200,
        "learning_rate": 0.1,
        "max_leaf_nodes": 31,
        "max_bins": 255,
        "n_iter_no_change": 10,
    },
    "KRR": {"n_components": 300},
}
