"""Any scikit-learn regressor as a learner: `sklearn:ClassName`, a dotted path, baselines.

`SklearnLearner(estimator)` gives a regressor the inputs of GMR, (r_a, dr_a/dt) -> v_b,
or with `suds=True` those of GMR+SUDS, (r_a, r_p, dr_a/dt) -> (v_b, dr_p/dt), with
rollout of r_p as GMR+SUDS does it (explicit Euler from each trial's first measured r_p,
clipped to the training range widened by a tenth of its width).

`homogeneous=True` is A-GBR's change of variables (see `gmr.py`): with
rho = sqrt(|dr_a/dt|^2 + f0^2) (f0 = `speed_floor` x the training median |dr_a/dt|) the
estimator learns (v_b, dr_p/dt) / rho from (r_a[, r_p], dr_a/dt / rho) and predictions
are multiplied back by rho, so any regressor becomes exactly rate-independent.

Names understood by `make_model`:

- `sklearn:ClassName` - a regressor of scikit-learn found by class name
  (`sklearn:MLPRegressor`), or `sklearn:package.module.Class` - any class with
  fit/predict importable by that dotted path; `+SUDS` appended gives the SUDS inputs.
- the named baselines of `baselines.BASELINES` (`MLP`, `MLP+SUDS`, `GBT`, `kNN`, `KRR`,
  each also with `+SUDS`), which are the same adapter with documented defaults.

Keyword arguments of `make_model` go to the adapter when they are one of
`ADAPTER_PARAMS`, else to the estimator (`estimator__KEY` forces the estimator). The
estimator's own `random_state` is the adapter's: a campaign leaves it None and the runner
seeds it from the job key. `recipe(model)` is the whole recipe as JSON-safe keyword
arguments (`sklearn_recipes.py`, with the names): `make_model(name, **recipe(model))`
builds the same learner again, and the campaign stores it so that a resumed campaign
compares exactly.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from sklearn.base import clone, is_classifier
from sklearn.exceptions import ConvergenceWarning
from sklearn.preprocessing import StandardScaler

from suds_exp.errors import ConfigError
from suds_exp.models.base import (
    Learner,
    ModelError,
    TimeSeries,
    actuated_columns,
    as_array,
    check_choice,
    check_float,
    passive_columns,
    require_columns,
    rollout_bounds,
)
from suds_exp.models.registry import SUDS_SUFFIX
from suds_exp.models.suds_variant import check_mode
from suds_exp.robot import VB_COLUMNS

PREFIX = "sklearn:"
#: Keyword arguments of `make_model` that configure the adapter, not the estimator.
ADAPTER_PARAMS = ("homogeneous", "speed_floor", "standardize", "mode", "random_state", "dtype")
#: Floating-point types the estimator may be given its arrays in.
DTYPES = ("float64", "float32")


def _fit_outputs(est, X: np.ndarray, Y: np.ndarray) -> list:
    """Fitted estimators: ``[est]`` fitted on the 2-D target when it takes one, else one
    clone per output column.

    One joint model is tried first whatever the estimator's tags say: scikit-learn's tags
    do not mark every regressor that takes a 2-D target (MLPRegressor 1.9 says
    single-output and takes 2-D y), and one network with q outputs is both what the
    field fits and q times cheaper than q networks. Regressors that take only 1-D y
    refuse a 2-D one in their input check ("y should be a 1d array"), before any work.
    """
    try:
        return [clone(est).fit(X, Y)]
    except ValueError:
        pass
    return [clone(est).fit(X, Y[:, j]) for j in range(Y.shape[1])]


class SklearnLearner(Learner):
    """A scikit-learn regressor on GMR's (or with ``suds`` GMR+SUDS's) inputs.

    Parameters
    ----------
    estimator : scikit-learn regressor, unfitted
        Cloned at every `fit`; it never sees the samples frame, only arrays.
    suds : bool, default False
        Inputs (r_a, r_p, dr_a/dt), outputs (v_b, dr_p/dt) as GMR+SUDS.
    homogeneous : bool, default False
        A-GBR's rate-homogeneous change of variables (module docstring).
    speed_floor : float, default 0.1
        f0 of `homogeneous`, as a fraction of the training median |dr_a/dt|.
    standardize : bool, default True
        Centre and scale every input and output column with the training mean and
        standard deviation (regressors with a penalty or a distance need it).
    mode : {"measured", "rollout"}, default "measured"
        SUDS only: use the test trial's r_p, or integrate it from each trial's start.
    random_state : int or None, default None
        Given to the estimator's ``random_state`` (when it has one) at fit; None leaves
        the estimator's own value.
    dtype : {"float64", "float32"}, default "float64"
        Type of the arrays the estimator sees (after scaling); predictions come back as
        float64. float32 is what neural-network libraries train in by default and halves
        the time of scikit-learn's MLP here (it keeps float32 weights for float32 data).

    Attributes
    ----------
    estimators_ : list of fitted clones (one, or one per output column when the estimator
    takes a single target); `columns_in_`, `columns_out_`; `x_scaler_`, `y_scaler_`
    (None without standardize); `speed_floor_` (rad/s); `rp_bounds_` (2, k) (SUDS).
    """

    def __init__(
        self,
        estimator=None,
        suds: bool = False,
        homogeneous: bool = False,
        speed_floor: float = 0.1,
        standardize: bool = True,
        mode: str = "measured",
        random_state=None,
        dtype: str = "float64",
    ):
        self.estimator = estimator
        self.suds = suds
        self.homogeneous = homogeneous
        self.speed_floor = speed_floor
        self.standardize = standardize
        self.mode = mode
        self.random_state = random_state
        self.dtype = dtype

    @property
    def name(self) -> str:
        cls = type(self.estimator).__name__ if self.estimator is not None else "None"
        return PREFIX + cls + (SUDS_SUFFIX if self.suds else "")

    def _validate(self):
        check_regressor(self.estimator, self.name)
        for key in ("suds", "homogeneous", "standardize"):
            if not isinstance(getattr(self, key), bool | np.bool_):
                raise ConfigError(
                    f"{self.name}: {key}={getattr(self, key)!r}; expected true or false"
                )
        check_float("speed_floor", self.speed_floor, 0.0, self.name, strict=True)
        check_mode(self.mode, self.name)
        check_choice("dtype", self.dtype, DTYPES, self.name)
        rs = self.random_state
        if rs is not None and (isinstance(rs, bool) or not isinstance(rs, int | np.integer)):
            raise ConfigError(f"{self.name}: random_state={rs!r}; expected an integer or None")

    def _columns(self, samples):
        ra, dra = actuated_columns(samples)
        if not ra:
            raise ModelError(f"{self.name}: samples frame has no ra_1.. columns (actuated shape)")
        rp, drp = passive_columns(samples) if self.suds else ([], [])
        if self.suds and not rp:
            raise ModelError(f"{self.name}: samples frame has no rp_1.. columns (passive shape)")
        return ra + rp + dra, list(VB_COLUMNS) + drp, rp, drp, dra

    def _rho(self, samples) -> np.ndarray:
        """What rates are divided by, shape (n,): rho with `homogeneous`, else ones."""
        if not self.homogeneous:
            return np.ones(len(samples))
        dra = as_array(samples, self.dra_columns_, self.name)
        return np.sqrt((dra * dra).sum(axis=1) + self.speed_floor_**2)

    def _inputs(self, samples):
        X = as_array(samples, self.columns_in_, self.name)
        f = self._rho(samples)
        X[:, [c in self.dra_columns_ for c in self.columns_in_]] /= f[:, None]
        return X, f

    def fit(self, samples: pd.DataFrame, y=None):
        self._validate()
        cin, cout, rp, drp, dra = self._columns(samples)
        require_columns(samples, ("trial_id", "t", *cin, *cout), self.name)
        self.columns_in_, self.columns_out_ = cin, cout
        self.rp_columns_, self.drp_columns_, self.dra_columns_ = rp, drp, dra
        speed = np.linalg.norm(as_array(samples, dra, self.name), axis=1)
        typical = float(np.median(speed)) or float(np.mean(speed)) or 1.0
        self.speed_floor_ = self.speed_floor * typical
        X, f = self._inputs(samples)
        Y = as_array(samples, cout, self.name) / f[:, None]
        self.x_scaler_ = self.y_scaler_ = None
        if self.standardize:
            self.x_scaler_ = StandardScaler().fit(X)
            self.y_scaler_ = StandardScaler().fit(Y)
            X, Y = self.x_scaler_.transform(X), self.y_scaler_.transform(Y)
        X, Y = X.astype(self.dtype, copy=False), Y.astype(self.dtype, copy=False)
        est = clone(self.estimator)
        if self.random_state is not None and "random_state" in est.get_params(deep=False):
            est.set_params(random_state=int(self.random_state))
        try:
            with warnings.catch_warnings():
                # max_iter is a budget the recipe states; reaching it is not news per job
                warnings.simplefilter("ignore", ConvergenceWarning)
                self.estimators_ = _fit_outputs(est, X, Y)
        except (ValueError, TypeError) as exc:
            lines = str(exc).strip().splitlines()
            raise ModelError(f"{self.name}: fit failed: {lines[0] if lines else exc}") from None
        self.n_features_in_ = X.shape[1]
        if rp:
            self.rp_bounds_ = rollout_bounds(as_array(samples, rp, self.name))
        return self

    def _raw_predict(self, X: np.ndarray) -> np.ndarray:
        """Outputs (n, q) in the changed variables, before multiplying back by rho."""
        if self.x_scaler_ is not None:
            X = self.x_scaler_.transform(X)
        X = X.astype(self.dtype, copy=False)
        if len(self.estimators_) == 1:
            Y = np.asarray(self.estimators_[0].predict(X), dtype=float).reshape(len(X), -1)
        else:
            Y = np.column_stack([np.asarray(e.predict(X), dtype=float) for e in self.estimators_])
        return self.y_scaler_.inverse_transform(Y) if self.y_scaler_ is not None else Y

    def predict(self, samples: pd.DataFrame) -> pd.DataFrame:
        """Predicted vx, vy (mm/s), wz (rad/s) [, drp_1..drp_k], same index as `samples`."""
        self._check_fitted()
        check_mode(self.mode, self.name)
        require_columns(samples, ("trial_id", "t", *self.columns_in_), self.name)
        if self.suds and self.mode == "rollout":
            return self._output_frame(self._predict_rollout(samples)[0], samples)
        X, f = self._inputs(samples)
        return self._output_frame(self._raw_predict(X) * f[:, None], samples)

    def rollout(self, samples: pd.DataFrame) -> pd.DataFrame:
        """r_p integrated from each trial's first sample, columns rp_1..rp_k, input's index."""
        self._check_fitted()
        if not self.suds:
            raise ModelError(f"{self.name}: rollout needs a +SUDS learner")
        require_columns(samples, ("trial_id", "t", *self.columns_in_), self.name)
        return pd.DataFrame(
            self._predict_rollout(samples)[1], index=samples.index, columns=self.rp_columns_
        )

    def _predict_rollout(self, samples):
        """(outputs (n, 3 + k), rolled-out r_p (n, k)) in the caller's order.

        All trials advance together: step i predicts the i-th sample of every trial still
        running in one call, so the estimator is called (longest trial) times, not n.
        """
        k = len(self.rp_columns_)
        X, f = self._inputs(samples)
        ts = TimeSeries.of(samples)
        X, f = X[ts.order], f[ts.order]
        rp_idx = np.array([self.columns_in_.index(c) for c in self.rp_columns_])
        lo, hi = self.rp_bounds_
        starts, ends = ts.starts[:-1], ts.starts[1:]
        out = np.empty((len(X), len(self.columns_out_)))
        rp = np.empty((len(X), k))
        state = X[starts][:, rp_idx].copy()
        for i in range(int((ends - starts).max())):
            live = starts + i < ends
            rows = (starts + i)[live]
            if i > 0:
                prev = rows - 1
                step = ts.dt[rows] * f[prev]
                state[live] = np.clip(state[live] + step[:, None] * out[prev, 3 : 3 + k], lo, hi)
            x = X[rows].copy()
            x[:, rp_idx] = state[live]
            out[rows] = self._raw_predict(x)
            rp[rows] = state[live]
        return ts.unsort(out * f[:, None]), ts.unsort(rp)


# -- checks ------------------------------------------------------------------------------
def check_regressor(estimator, name: str) -> None:
    """ConfigError unless ``estimator`` is an unfitted-estimator object that regresses."""
    if estimator is None or isinstance(estimator, type):
        raise ConfigError(f"{name}: estimator={estimator!r}; expected an estimator instance")
    missing = [
        m for m in ("fit", "predict", "get_params") if not callable(getattr(estimator, m, None))
    ]
    if missing:
        raise ConfigError(
            f"{name}: {type(estimator).__name__} is not a regressor (no {', '.join(missing)})"
        )
    kind = getattr(estimator, "_estimator_type", None)
    try:
        from sklearn.utils import get_tags

        kind = get_tags(estimator).estimator_type or kind
    except Exception:  # noqa: BLE001 - foreign estimators may lack tags
        pass
    if is_classifier(estimator) or kind not in (None, "regressor"):
        raise ConfigError(
            f"{name}: {type(estimator).__name__} is a {kind or 'classifier'}, not a regressor"
        )


__all__ = [
    "ADAPTER_PARAMS",
    "PREFIX",
    "SklearnLearner",
    "actuated_columns",
    "check_regressor",
]
