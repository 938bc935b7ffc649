"""The five learners of the paper, built by name with `make_model`.

Every learner's name, family, SUDS flag and tags are in `registry.REGISTRY`.

| name         | class                          | learns                                   |
|--------------|--------------------------------|------------------------------------------|
| `phase-only` | `phase_only.PhaseOnly`         | v_b(phase), Fourier series               |
| `TLS`        | `tls.TLS`                      | phase-binned TLS of v_b on r_a offsets   |
| `TLS+SUDS`   | `tls.TLSSuds`                  | the same on (r_a, r_p) + dr_p/dt         |
| `GMR`        | `gmr.GMR`                      | A-GBR of v_b on (r_a, dr_a/dt)           |
| `GMR+SUDS`   | `gmr.GMRSuds`                  | A-GBR of (v_b, dr_p/dt) on (r_a, r_p, dr_a/dt) |

Online learners (`ONLINE_MODELS`, also built by `make_model`) add `partial_fit(samples)`:
`OnlineGMR` and `OnlineGMR+SUDS` (`online.OnlineGMR`, `online.OnlineGMRSuds`), and
`GradualGMR+SUDS` (`gradual.GradualGMRSuds`: GMR that adds passive coordinates online).

Momentum learners (`MOMENTUM_MODELS`, the paper's Future Work): `GMR+P` and
`GMR+SUDS+P` (`momentum.GMRMomentum`, `momentum.GMRSudsMomentum`), body velocity relaxing
to a learned quasi-static GMR map with learned time constants.

`GMR+F` (`finsler.GMRFinsler`, `FINSLER_MODELS`): GMR on the positive and negative parts
of each shape velocity, a map homogeneous but not linear in it (Finsler contact);
`TLS+F` (`tls_finsler.TLSFinsler`): phase-binned TLS of the same map around the mean gait.

Beyond the paper (`sklearn_adapter.py`; names and recipes in `sklearn_recipes.py`):
`MLP`, `MLP+SUDS`, `GBT`, `kNN`, `KRR` (each also `+SUDS`) and `sklearn:ClassName` /
`sklearn:pkg.mod.Class` (any regressor, `+SUDS` for GMR+SUDS's inputs);
`model_recipe(model)` is what a campaign stores to rebuild one.

Every learner is a scikit-learn estimator: `fit(samples) -> self`,
`predict(samples) -> DataFrame[vx, vy, wz(, drp_1..drp_k)]` with the input's index.
"""

from __future__ import annotations

from functools import cache
from importlib import import_module

from suds_exp import vocabulary
from suds_exp.errors import ConfigError
from suds_exp.models.base import Learner, ModelError
from suds_exp.models.finsler import GMRFinsler
from suds_exp.models.gmr import GMR, GMRSuds
from suds_exp.models.gradual import GradualGMRSuds
from suds_exp.models.momentum import GMRMomentum, GMRSudsMomentum
from suds_exp.models.online import OnlineGMR, OnlineGMRSuds
from suds_exp.models.phase_only import PhaseOnly
from suds_exp.models.sklearn_adapter import SklearnLearner
from suds_exp.models.sklearn_recipes import make_adapter, recipe
from suds_exp.models.tls import TLS, TLSSuds
from suds_exp.models.tls_finsler import TLSFinsler


def builder(name: str) -> type[Learner]:
    """The class that builds the registered learner ``name`` (its registry `builder`);
    KeyError for a name the registry does not hold."""
    info = vocabulary.learner(name)
    if info is None:
        raise KeyError(name)
    return _resolve(info.builder)


@cache
def _resolve(path: str) -> type[Learner]:
    # "module.Class" inside suds_exp.models, or "package.module:Class" anywhere
    if ":" in path:
        module, attr = path.split(":")
    else:
        module, attr = path.rsplit(".", 1)
        module = f"suds_exp.models.{module}"
    return getattr(import_module(module), attr)


def _builders(names) -> dict[str, type[Learner]]:
    return {n: builder(n) for n in names}


#: The paper's five by name (`registry.LEARNERS`, in its order).
MODELS: dict[str, type[Learner]] = _builders(vocabulary.LEARNERS)
MODEL_NAMES = vocabulary.LEARNERS
#: Learners with `partial_fit(samples)`; kept out of MODEL_NAMES (the paper's five).
ONLINE_MODELS: dict[str, type[Learner]] = _builders(vocabulary.ONLINE_LEARNERS)
#: Learners with a momentum state (`momentum.py`).
MOMENTUM_MODELS: dict[str, type[Learner]] = _builders(vocabulary.MOMENTUM_LEARNERS)
#: Learners whose map is homogeneous but not linear in the shape velocity (`finsler.py`).
FINSLER_MODELS: dict[str, type[Learner]] = _builders(vocabulary.FINSLER_LEARNERS)
#: The survey's named baselines (scikit-learn regressors with documented defaults).
BASELINE_NAMES = vocabulary.BASELINE_LEARNERS


def make_model(name: str, **params) -> Learner:
    """A new, unfitted learner by name (any name of the registry, `suds_exp.vocabulary`)
    with the given hyper-parameters.

    Also `sklearn:ClassName[+SUDS]` (see `sklearn_recipes`). Unknown names or parameters
    raise ConfigError; parameter values are checked by `fit` (by scikit-learn's own checks
    for the adapter).
    """
    info = vocabulary.learner(name)
    if info is None or info.builder == vocabulary.ADAPTER:
        adapter = make_adapter(name, params)
        if adapter is not None:
            return adapter
    if info is None:
        known = (i.name for i in vocabulary.REGISTRY)
        raise ConfigError(
            f"unknown model {name!r}; expected one of {', '.join(known)} or sklearn:ClassName"
        )
    cls = _resolve(info.builder)
    valid = _param_names(cls)
    bad = [p for p in params if p not in valid]
    if bad:
        raise ConfigError(
            f"model {name}: unknown parameter(s) {', '.join(bad)}; "
            f"valid: {', '.join(sorted(valid))}"
        )
    return cls(**params)


@cache
def _param_names(cls: type) -> frozenset[str]:
    # a learner's parameter names are its constructor's: fixed per class, so the throwaway
    # instance that lists them (~0.1 ms, once per campaign job before) is built once
    return frozenset(cls().get_params())


def model_recipe(model: Learner) -> dict:
    """JSON-safe keyword arguments that rebuild ``model`` with `make_model` (its name):
    `get_params()` for the paper's learners, the deep recipe for scikit-learn ones."""
    if isinstance(model, SklearnLearner):
        return recipe(model)
    return model.get_params(deep=False)


__all__ = [
    "BASELINE_NAMES",
    "builder",
    "SklearnLearner",
    "model_recipe",
    "MODELS",
    "MODEL_NAMES",
    "ONLINE_MODELS",
    "OnlineGMR",
    "OnlineGMRSuds",
    "GradualGMRSuds",
    "ModelError",
    "MOMENTUM_MODELS",
    "GMRMomentum",
    "GMRSudsMomentum",
    "FINSLER_MODELS",
    "GMRFinsler",
    "TLSFinsler",
    "make_model",
    "GMR",
    "GMRSuds",
    "TLS",
    "TLSSuds",
    "PhaseOnly",
]
