"""What every learner shares: reading a samples frame, trials as time series, checks.

A samples frame has the columns of the `samples` table (`robot.sample_columns`): `trial_id`,
`t` (s), `phase` (rad, unwrapped), `ra_1..ra_m`, `dra_1..dra_m` (m = 2 joint angles,
rad and rad/s, or the paper preset's Cartesian values, mm and mm/s), `rp_1..rp_k`,
`drp_1..drp_k`, `vx`, `vy` (mm/s), `wz` (rad/s), all in the body frame.
Learners never assume the rows are sorted: every time-series operation works on the
rows ordered by (`trial_id`, `t`) and results are put back in the caller's order.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd
from sklearn.base import BaseEstimator

from suds_exp.display import Summary
from suds_exp.errors import ConfigError, ModelError
from suds_exp.models.params import Param, init_from
from suds_exp.robot import RA_COLUMNS, VB_COLUMNS

_RP_PATTERN = re.compile(r"^rp_(\d+)$")
_RA_PATTERN = re.compile(r"^ra_(\d+)$")
GAP_FACTOR = 5.0


def _consecutive(samples: pd.DataFrame, pattern: re.Pattern) -> int:
    present = {int(m.group(1)) for c in samples.columns if (m := pattern.match(str(c)))}
    k = 0
    while k + 1 in present:
        k += 1
    return k


def passive_columns(samples: pd.DataFrame) -> tuple[list[str], list[str]]:
    """Names of the passive shape columns present, in order.

    Returns `(["rp_1", ..., "rp_k"], ["drp_1", ..., "drp_k"])`; k is the number of
    consecutive `rp_i` columns starting at 1 (0 when there are none).
    """
    k = _consecutive(samples, _RP_PATTERN)
    return [f"rp_{i}" for i in range(1, k + 1)], [f"drp_{i}" for i in range(1, k + 1)]


def actuated_columns(samples: pd.DataFrame) -> tuple[list[str], list[str]]:
    """Names of the actuated shape columns present, in order.

    Returns `(["ra_1", ..., "ra_m"], ["dra_1", ..., "dra_m"])`; m is the number of
    consecutive `ra_i` columns starting at 1 (2 joint angles by default, 4 Cartesian
    values with the paper preset). Without any, the default pair, so that the missing
    columns are named by `require_columns`.
    """
    m = _consecutive(samples, _RA_PATTERN) or len(RA_COLUMNS)
    return [f"ra_{i}" for i in range(1, m + 1)], [f"dra_{i}" for i in range(1, m + 1)]


@dataclass(frozen=True, eq=False)
class Columns:
    """A samples table as named column arrays, each of shape (n_samples,): the cheap form
    of a samples frame that `Learner.predict_array` reads too. A caller that predicts
    thousands of small tables (the gait designer rolls one out per candidate gait) saves
    building a DataFrame and reading it back column by column; the numbers are the same.
    ``series``: the rows' `TimeSeries` when the caller already has it (many tables on the
    same trial_id and t columns), else None (computed when a learner needs it).
    """

    data: dict
    series: TimeSeries | None = None

    def __len__(self) -> int:
        return len(next(iter(self.data.values()))) if self.data else 0

    def __contains__(self, name) -> bool:
        return name in self.data

    def __getitem__(self, name) -> np.ndarray:
        return self.data[name]

    def frame(self) -> pd.DataFrame:
        """The same table as a samples DataFrame (columns in `data`'s order)."""
        return pd.DataFrame(self.data)


def column(samples: pd.DataFrame | Columns, name: str, dtype=None) -> np.ndarray:
    """One column of a samples frame or `Columns` as an array (n_samples,)."""
    if isinstance(samples, Columns):
        return np.asarray(samples[name], dtype=dtype)
    return samples[name].to_numpy(dtype=dtype)


def require_columns(samples: pd.DataFrame | Columns, columns, model: str) -> None:
    """Raise ModelError naming the first missing column."""
    if not isinstance(samples, pd.DataFrame | Columns):
        raise ModelError(f"{model}: expected a pandas DataFrame of samples, got {type(samples)}")
    missing = [c for c in columns if c not in samples]
    if missing:
        raise ModelError(
            f"{model}: samples frame lacks column(s) {', '.join(missing)}; "
            "expected the columns of the `samples` table"
        )
    if len(samples) == 0:
        raise ModelError(f"{model}: samples frame is empty")


def as_array(samples: pd.DataFrame | Columns, columns, model: str) -> np.ndarray:
    """Columns as a float array of shape (n_samples, len(columns)); NaN/inf is an error."""
    columns = list(columns)
    if isinstance(samples, Columns):
        x = np.empty((len(samples), len(columns)), order="F")
        for j, c in enumerate(columns):
            x[:, j] = samples[c]
    elif samples.columns.is_unique:
        # Column by column: a quarter of the time of .loc[:, columns].to_numpy() on the
        # many-block frames learners get (pandas builds an index and a block manager for
        # the subset first). Same values, and the same Fortran layout that call returns
        # (BLAS may round differently on another layout).
        x = np.empty((len(samples), len(columns)), order="F")
        for j, c in enumerate(columns):
            x[:, j] = samples[c].to_numpy(dtype=float)
    else:
        x = samples.loc[:, columns].to_numpy(dtype=float, copy=True)
    if not np.isfinite(x).all():
        bad = [c for c, ok in zip(columns, np.isfinite(x).all(axis=0), strict=True) if not ok]
        raise ModelError(f"{model}: column(s) {', '.join(bad)} hold NaN or inf values")
    return x


@dataclass(frozen=True)
class TimeSeries:
    """Row order that makes every trial (or gap-free stretch of one) a time-ordered run.

    `order` (n,) indexes the caller's rows in (trial_id, t) order; `starts` (n_trials + 1,)
    are the run boundaries in that order; `dt` (n,) is the step to the previous sample of
    the same trial in s (0 at each trial's first sample).
    """

    order: np.ndarray
    starts: np.ndarray
    dt: np.ndarray

    @classmethod
    def of(cls, samples: pd.DataFrame | Columns) -> TimeSeries:
        if isinstance(samples, Columns) and samples.series is not None:
            return samples.series
        trial = column(samples, "trial_id") if "trial_id" in samples else np.zeros(len(samples))
        t = column(samples, "t", float)
        order = np.lexsort((t, trial))
        ts, tr = t[order], trial[order]
        new = np.ones(len(order), dtype=bool)
        new[1:] = tr[1:] != tr[:-1]
        dt = np.diff(ts, prepend=ts[0])
        # Two cycle windows cut from one trial are two series too: a step more than
        # GAP_FACTOR times the median step starts a new run.
        steps = dt[~new]
        if steps.size:
            typical = np.median(steps[steps > 0]) if (steps > 0).any() else 0.0
            if typical > 0:
                new |= dt > GAP_FACTOR * typical
        starts = np.append(np.flatnonzero(new), len(order))
        dt[new] = 0.0
        return cls(order=order, starts=starts, dt=dt)

    @property
    def first(self) -> np.ndarray:
        """Boolean mask (in sorted order) of each trial's first sample."""
        m = np.zeros(len(self.order), dtype=bool)
        m[self.starts[:-1]] = True
        return m

    def unsort(self, values: np.ndarray) -> np.ndarray:
        """Put rows computed in sorted order back into the caller's order."""
        out = np.empty_like(values)
        out[self.order] = values
        return out


def phase_rate(samples: pd.DataFrame) -> np.ndarray:
    """d(phase)/dt per sample, rad/s, shape (n_samples,), estimated within each trial.

    Central differences of the unwrapped `phase` column against `t` (one-sided at the
    ends of a trial); a trial of a single sample gets the median rate of the others.
    """
    ts = TimeSeries.of(samples)
    ph = samples["phase"].to_numpy(dtype=float)[ts.order]
    t = samples["t"].to_numpy(dtype=float)[ts.order]
    rate = np.full(len(ph), np.nan)
    for a, b in zip(ts.starts[:-1], ts.starts[1:], strict=True):
        if b - a >= 2:
            rate[a:b] = np.gradient(ph[a:b], t[a:b])
    if np.isnan(rate).all():
        raise ModelError(
            "samples frame: every trial has a single sample; cannot estimate phase rate"
        )
    rate[np.isnan(rate)] = np.nanmedian(rate)
    return ts.unsort(rate)


def rollout_bounds(rp: np.ndarray, margin: float = 0.1) -> np.ndarray:
    """(2, k) lower and upper limits for rolled-out r_p: the training range widened by
    `margin` of its width on each side. Passive joints are bounded (flippers open no
    further than their stops), and a learned drift must not carry r_p where no data was.
    """
    lo, hi = rp.min(axis=0), rp.max(axis=0)
    w = hi - lo
    return np.stack([lo - margin * w, hi + margin * w])


def check_int(name: str, value, low: int, model: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
        raise ConfigError(f"{model}: {name}={value!r}; expected an integer >= {low}")
    return int(value)


def check_float(name: str, value, low: float, model: str, strict: bool = False) -> float:
    ok = isinstance(value, int | float | np.floating | np.integer) and not isinstance(value, bool)
    if ok:
        ok = value > low if strict else value >= low
    if not ok:
        raise ConfigError(
            f"{model}: {name}={value!r}; expected a number {'>' if strict else '>='} {low}"
        )
    return float(value)


def check_choice(name: str, value, choices, model: str):
    if value not in choices:
        raise ConfigError(
            f"{model}: {name}={value!r}; expected one of {', '.join(map(str, choices))}"
        )
    return value


class Learner(Summary, BaseEstimator):
    """Common face of the learners: `fit(samples) -> self`, `predict(samples) -> DataFrame`.

    Subclasses set `name` (the learner name of `make_model`) and `suds` (whether the
    learner models r_p and predicts dr_p/dt), and declare their hyper-parameters once in
    ``_hyper_parameters`` (name -> `params.Param`: default and constraint); the constructor and
    `_validate_params` follow from that table (see `suds_exp.models.params`). A learner
    shows itself under its name, with the parameters it changes from its defaults and
    whether it is fitted (``GMR+SUDS(n_components=8) [fitted: 6 inputs]``; in a
    notebook, a table of all).
    """

    name = "learner"
    suds = False
    _hyper_parameters: ClassVar[dict[str, Param]] = {}

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        # a class that declares its parameters gets the constructor they describe; one
        # that declares none (a variant with its parent's parameters) inherits its parent's
        if "_hyper_parameters" in vars(cls) and "__init__" not in vars(cls):
            cls.__init__ = init_from(cls._hyper_parameters)
            cls.__init__.__qualname__ = f"{cls.__qualname__}.__init__"
            cls.__init__.__module__ = cls.__module__

    def _validate_params(self) -> None:
        """Check every declared hyper-parameter (in declaration order); the first bad one
        raises a one-line ConfigError naming it and what was expected."""
        for name, param in self._hyper_parameters.items():
            if param.constraint is not None:
                param.constraint.check(name, getattr(self, name), self)

    def _validate(self) -> None:
        """What `fit` checks before it reads any data: the declared constraints (a
        learner with checks across its parameters extends this)."""
        self._validate_params()

    def _state(self) -> str:
        n = getattr(self, "n_features_in_", None)
        return "not fitted" if n is None else f"fitted: {n} inputs"

    def _changed_params(self) -> dict:
        try:
            defaults = type(self)().get_params(deep=False)
        except TypeError:  # a learner without defaults for every parameter
            defaults = {}
        return {
            k: v
            for k, v in self.get_params(deep=False).items()
            if k not in defaults or repr(defaults[k]) != repr(v)
        }

    def _summary(self):
        fields = [("state", self._state()), ("SUDS", "yes" if self.suds else "no")]
        return self.name, fields + sorted(self.get_params(deep=False).items())

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self._changed_params().items())
        return f"{self.name}({args}) [{self._state()}]"

    def predict_array(self, samples: pd.DataFrame | Columns) -> np.ndarray:
        """`predict`'s numbers as an array (n_samples, n_outputs): vx, vy (mm/s), wz
        (rad/s) [, drp_1..drp_k], in the caller's row order; ``samples`` a samples frame
        or `Columns`. Learners with a cheaper array path override this, and their
        `predict` is that array in a frame, so the two always agree."""
        frame = samples.frame() if isinstance(samples, Columns) else samples
        return self.predict(frame).to_numpy(dtype=float)

    def _output_frame(self, values: np.ndarray, samples: pd.DataFrame) -> pd.DataFrame:
        cols = list(VB_COLUMNS) + (list(self.drp_columns_) if self.suds else [])
        return pd.DataFrame(values, index=samples.index, columns=cols)

    def _check_fitted(self):
        if not hasattr(self, "n_features_in_"):
            raise ModelError(f"{self.name}: predict called before fit")
