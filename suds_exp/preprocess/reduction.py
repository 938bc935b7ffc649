"""Passive coordinates beyond PCA: the reducer of a version (parameter ``reduction``).

The passive state is 12 numbers (mm, `shape.passive_state`); a reducer maps it to k
coordinates r_p and maps its rates to dr_p/dt. ``reduction`` chooses it:

- ``pca`` (default): `shape.PassivePCA`, linear, r_p in mm.
- ``kernel-pca``: kernel PCA with an RBF kernel (Schoelkopf, Smola & Mueller 1998),
  fitted by scikit-learn on `LANDMARKS` frames taken at an even stride over all the
  version's frames (a full kernel over the ~10^5 frames of a dataset would not fit in
  memory; consecutive frames at 100 Hz are near copies). Width: scikit-learn's "scale"
  heuristic, gamma = 1 / (12 var(x)). r_p is dimensionless.
- ``autoencoder``: a scikit-learn `MLPRegressor` trained to reproduce the centred
  12-vector (divided by its overall standard deviation, so the geometry of the mm
  coordinates is kept as PCA keeps it) through a bottleneck of k tanh units,
  12 -> `AE_HIDDEN` -> k -> `AE_HIDDEN` -> 12, Adam with early stopping on 10 %, seed
  `AE_SEED`; r_p is the bottleneck's activation, in (-1, 1). Trained on at most
  `AE_SAMPLES` frames at an even stride.

Rates. For a nonlinear map z = g(x), dz/dt = J_g(x) dx/dt: `transform_rate(rate, passive)`
evaluates the Jacobian of the encoder in closed form at the (smoothed) passive state and
applies it to the differentiated passive state, so dr_p/dt comes from the same
differentiator as for PCA (where J is the constant loading matrix).

Explained variance (``explained_variance_ratio_``): for kernel PCA, each coordinate's
eigenvalue over the trace of the centred kernel (its share of the variance in feature
space, the analogue of PCA's ratio); for the autoencoder one number, the share of the
12-vector's variance its decoder recovers from the k coordinates (they are not ordered).

The fitted state is stored as JSON in `prep_fits` like the PCA's: kind ``pca`` for PCA
(as always), kind ``reducer`` with the method as group for the others.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable

import numpy as np

from suds_exp.preprocess.shape import PassivePCA

REDUCTIONS = ("pca", "kernel-pca", "autoencoder")
#: Frames the kernel PCA is fitted on (its landmarks).
LANDMARKS = 1500
#: Width of the autoencoder's two hidden layers, frames it trains on, its seed.
AE_HIDDEN = 32
AE_SAMPLES = 20_000
AE_SEED = 0
#: Rows per block when a kernel against the landmarks is evaluated (memory bound).
_BLOCK = 4096


def _stride(x: np.ndarray, n: int) -> np.ndarray:
    """At most ``n`` rows of ``x`` at an even stride (all of them when fewer)."""
    if len(x) <= n:
        return x
    return x[np.linspace(0, len(x) - 1, n).round().astype(int)]


class _NonlinearReducer:
    """What the nonlinear reducers share: r_p and dr_p/dt both come from one map of the
    passive state, ``_map(passive, rate=None)``, the map itself or its Jacobian applied
    to ``rate``."""

    method: str

    def transform(self, passive: np.ndarray) -> np.ndarray:
        """r_p, array of shape (n_samples, k): dimensionless (kernel PCA), in (-1, 1)
        (autoencoder)."""
        return self._map(passive)

    def transform_rate(self, rate: np.ndarray, passive: np.ndarray | None = None) -> np.ndarray:
        """dr_p/dt (n_samples, k) 1/s: the map's Jacobian at ``passive`` (n, 12) mm applied
        to ``rate`` (n, 12) mm/s."""
        if passive is None:
            raise ValueError(f"{self.method}: the rate of r_p needs the passive state")
        return self._map(passive, rate)


class KernelPCAReducer(_NonlinearReducer):
    """RBF kernel PCA of the passive 12-vector, k coordinates (see the module docstring).

    Attributes (after `fit`): ``landmarks_`` (m, 12) mm, ``gamma_`` (1/mm^2),
    ``alphas_`` (m, k) eigenvectors divided by the square roots of their eigenvalues,
    ``k_rows_`` (m,) column means of the training kernel, ``k_all_`` its grand mean,
    ``explained_variance_ratio_`` (k,).
    """

    method = "kernel-pca"

    def __init__(self, n_components: int = 4, landmarks: int = LANDMARKS):
        self.n_components = n_components
        self.landmarks = landmarks

    def fit(self, passive: np.ndarray) -> KernelPCAReducer:
        """Fit on passive states, array of shape (n_samples, 12), mm."""
        from sklearn.decomposition import KernelPCA

        x = _stride(np.asarray(passive, dtype=float), self.landmarks)
        self.gamma_ = 1.0 / (x.shape[1] * float(x.var()))
        kpca = KernelPCA(
            n_components=self.n_components, kernel="rbf", gamma=self.gamma_, eigen_solver="dense"
        ).fit(x)
        lam = kpca.eigenvalues_
        self.landmarks_ = x
        self.alphas_ = kpca.eigenvectors_ / np.sqrt(np.clip(lam, 1e-300, None))
        kernel = self._kernel(x)
        self.k_rows_ = kernel.mean(axis=0)
        self.k_all_ = float(kernel.mean())
        centred_trace = float(np.trace(kernel) - 2 * self.k_rows_.sum() + len(x) * self.k_all_)
        self.explained_variance_ratio_ = lam / centred_trace
        return self

    def _kernel(self, x: np.ndarray) -> np.ndarray:
        d2 = (
            (x * x).sum(1)[:, None]
            + (self.landmarks_ * self.landmarks_).sum(1)[None, :]
            - 2.0 * x @ self.landmarks_.T
        )
        return np.exp(-self.gamma_ * np.clip(d2, 0.0, None))

    def _map(self, passive, rate=None):
        # in blocks of _BLOCK samples: the kernel against every landmark is (n, m)
        x = np.asarray(passive, dtype=float)
        v = None if rate is None else np.asarray(rate, dtype=float)
        out = np.empty((len(x), self.n_components))
        for s in range(0, len(x), _BLOCK):
            xb = x[s : s + _BLOCK]
            kb = self._kernel(xb)
            if v is None:
                centred = kb - kb.mean(1, keepdims=True) - self.k_rows_ + self.k_all_
            else:
                vb = v[s : s + _BLOCK]
                # d k(x, l)/dt = -2 gamma k(x, l) (x - l) . dx/dt
                g = (xb * vb).sum(1)[:, None] - vb @ self.landmarks_.T
                dk = -2.0 * self.gamma_ * kb * g
                centred = dk - dk.mean(1, keepdims=True)
            out[s : s + _BLOCK] = centred @ self.alphas_
        return out

    def to_dict(self) -> dict:
        return {
            "method": self.method,
            "n_components": self.n_components,
            "landmarks": self.landmarks_.tolist(),
            "gamma": self.gamma_,
            "alphas": self.alphas_.tolist(),
            "k_rows": self.k_rows_.tolist(),
            "k_all": self.k_all_,
            "explained_variance_ratio": self.explained_variance_ratio_.tolist(),
        }

    @classmethod
    def from_dict(cls, state: dict) -> KernelPCAReducer:
        r = cls(int(state["n_components"]), len(state["landmarks"]))
        r.landmarks_ = np.asarray(state["landmarks"], dtype=float)
        r.gamma_ = float(state["gamma"])
        r.alphas_ = np.asarray(state["alphas"], dtype=float)
        r.k_rows_ = np.asarray(state["k_rows"], dtype=float)
        r.k_all_ = float(state["k_all"])
        r.explained_variance_ratio_ = np.asarray(state["explained_variance_ratio"])
        return r


class AutoencoderReducer(_NonlinearReducer):
    """A scikit-learn MLP autoencoder of the passive 12-vector with a k-unit bottleneck.

    Attributes (after `fit`): ``mean_`` (12,) mm, ``scale_`` mm, ``weights_`` and
    ``biases_`` of the encoder's two layers (scikit-learn's ``coefs_[:2]``,
    ``intercepts_[:2]``), ``explained_variance_ratio_`` (1,) (reconstruction share).
    """

    method = "autoencoder"

    def __init__(self, n_components: int = 4, hidden: int = AE_HIDDEN, seed: int = AE_SEED):
        self.n_components = n_components
        self.hidden = hidden
        self.seed = seed

    def fit(self, passive: np.ndarray) -> AutoencoderReducer:
        """Fit on passive states, array of shape (n_samples, 12), mm."""
        from sklearn.exceptions import ConvergenceWarning
        from sklearn.neural_network import MLPRegressor

        x = np.asarray(passive, dtype=float)
        self.mean_ = x.mean(axis=0)
        self.scale_ = float(np.sqrt(((x - self.mean_) ** 2).mean())) or 1.0
        z = _stride((x - self.mean_) / self.scale_, AE_SAMPLES)
        net = MLPRegressor(
            hidden_layer_sizes=(self.hidden, self.n_components, self.hidden),
            activation="tanh",
            alpha=1e-4,
            max_iter=300,
            early_stopping=True,
            random_state=self.seed,
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            net.fit(z, z)
        self.weights_ = [np.asarray(w) for w in net.coefs_[:2]]
        self.biases_ = [np.asarray(b) for b in net.intercepts_[:2]]
        residual = z - net.predict(z)
        self.explained_variance_ratio_ = np.array([1.0 - (residual**2).sum() / (z**2).sum()])
        return self

    def _map(self, passive, rate=None):
        h = (np.asarray(passive, dtype=float) - self.mean_) / self.scale_
        dh = None if rate is None else np.asarray(rate, dtype=float) / self.scale_
        for w, b in zip(self.weights_, self.biases_, strict=True):
            h = np.tanh(h @ w + b)
            if dh is not None:
                dh = (1.0 - h * h) * (dh @ w)
        return h if dh is None else dh

    def to_dict(self) -> dict:
        return {
            "method": self.method,
            "n_components": self.n_components,
            "hidden": self.hidden,
            "seed": self.seed,
            "mean": self.mean_.tolist(),
            "scale": self.scale_,
            "weights": [w.tolist() for w in self.weights_],
            "biases": [b.tolist() for b in self.biases_],
            "explained_variance_ratio": self.explained_variance_ratio_.tolist(),
        }

    @classmethod
    def from_dict(cls, state: dict) -> AutoencoderReducer:
        r = cls(int(state["n_components"]), int(state["hidden"]), int(state["seed"]))
        r.mean_ = np.asarray(state["mean"], dtype=float)
        r.scale_ = float(state["scale"])
        r.weights_ = [np.asarray(w, dtype=float) for w in state["weights"]]
        r.biases_ = [np.asarray(b, dtype=float) for b in state["biases"]]
        r.explained_variance_ratio_ = np.asarray(state["explained_variance_ratio"])
        return r


_CLASSES = {"kernel-pca": KernelPCAReducer, "autoencoder": AutoencoderReducer}


def fit_kind(method: str) -> tuple[str, str]:
    """(kind, group) of a reducer's row in `prep_fits`: PCA keeps ("pca", "")."""
    return ("pca", "") if method == "pca" else ("reducer", method)


def passive_reducer(
    params: dict, fits: dict[tuple[str, str], str], passive: Callable[[], np.ndarray]
):
    """The version's reducer and, when it had to be fitted now, its `prep_fits` row.

    ``fits``: the version's stored states by (kind, group); ``passive``: returns the
    (smoothed) passive states to fit on, (n, 12) mm, called only when nothing is stored.
    Returns (reducer, None) or (reducer, (kind, group, state JSON)).
    """
    method = params.get("reduction", "pca")
    kind = fit_kind(method)
    if kind in fits:
        return reducer_from_state(*kind, fits[kind]), None
    cls = PassivePCA if method == "pca" else _CLASSES[method]
    reducer = cls(params["k"]).fit(passive())
    return reducer, (*kind, json.dumps(reducer.to_dict()))


def reducer_from_state(kind: str, group: str, state: str):
    """The reducer of a `prep_fits` row (kind ``pca``, or ``reducer`` with the method as
    group) from its JSON state."""
    d = json.loads(state)
    return PassivePCA.from_dict(d) if kind == "pca" else _CLASSES[group].from_dict(d)
