"""Names and recipes of scikit-learn learners: `sklearn:ClassName`, a dotted path, the named
baselines, and the JSON-safe recipe a campaign stores to build the same learner again.

`make_adapter(name, params)` is what `suds_exp.models.make_model` calls for such a name;
`recipe(model)` gives keyword arguments with which `make_model(name, **recipe(model))`
rebuilds it (nested estimator objects as class path + parameters).
"""

from __future__ import annotations

import importlib

import numpy as np

from suds_exp.errors import ConfigError
from suds_exp.models.baselines import BASELINES
from suds_exp.models.registry import SUDS_SUFFIX
from suds_exp.models.sklearn_adapter import ADAPTER_PARAMS, PREFIX, SklearnLearner, check_regressor

#: Where `sklearn:ClassName` looks for ClassName, in this order.
_SKLEARN_MODULES = (
    "sklearn.neural_network",
    "sklearn.ensemble",
    "sklearn.neighbors",
    "sklearn.kernel_ridge",
    "sklearn.gaussian_process",
    "sklearn.linear_model",
    "sklearn.svm",
    "sklearn.tree",
    "sklearn.cross_decomposition",
    "sklearn.multioutput",
    "sklearn.pipeline",
    "sklearn.compose",
    "sklearn.dummy",
    "sklearn.isotonic",
)


def resolve_class(path: str, name: str) -> type:
    """The estimator class of ``sklearn:ClassName`` or a dotted path; ConfigError if none."""
    if "." in path:
        module, _, cls = path.rpartition(".")
        try:
            found = getattr(importlib.import_module(module), cls, None)
        except ImportError as exc:
            raise ConfigError(f"model {name!r}: cannot import {module!r} ({exc})") from None
        if found is None:
            raise ConfigError(f"model {name!r}: module {module!r} has no {cls!r}")
    else:
        found = None
        for module in _SKLEARN_MODULES:
            found = getattr(importlib.import_module(module), path, None)
            if found is not None:
                break
        if found is None:
            raise ConfigError(
                f"model {name!r}: no scikit-learn regressor named {path!r}; give its "
                "class name (sklearn:MLPRegressor) or a dotted path (sklearn:pkg.mod.Class)"
            )
    if not isinstance(found, type):
        raise ConfigError(f"model {name!r}: {path!r} is not a class")
    return found


def encode(value):
    """A parameter value as JSON-safe data; estimator-like objects (anything with
    get_params, e.g. kernels, pipeline steps) become {"__class__": path, "params": {...}},
    recursively, so the recipe is deep. Tuples become lists."""
    if hasattr(value, "get_params") and not isinstance(value, type):
        cls = type(value)
        return {
            "__class__": f"{cls.__module__}.{cls.__qualname__}",
            "params": {k: encode(v) for k, v in value.get_params(deep=False).items()},
        }
    if isinstance(value, list | tuple):
        return [encode(v) for v in value]
    if isinstance(value, dict):
        return {str(k): encode(v) for k, v in value.items()}
    if isinstance(value, np.generic):
        return value.item()
    if value is None or isinstance(value, bool | int | float | str):
        return value
    raise ConfigError(f"learner parameter {value!r} cannot be stored in a campaign definition")


def decode(value, name: str):
    """Inverse of `encode` (lists stay lists: scikit-learn takes them for tuples)."""
    if isinstance(value, dict) and "__class__" in value:
        cls = resolve_class(str(value["__class__"]), name)
        params = {k: decode(v, name) for k, v in dict(value.get("params") or {}).items()}
        try:
            return cls(**params)
        except TypeError as exc:
            raise ConfigError(f"model {name!r}: {cls.__name__}: {exc}") from None
    if isinstance(value, list):
        # scikit-learn takes lists where it documents tuples (pipeline steps too)
        return [decode(v, name) for v in value]
    if isinstance(value, dict):
        return {k: decode(v, name) for k, v in value.items()}
    return value


def build(cls: type, name: str, suds: bool, defaults: dict, params: dict) -> SklearnLearner:
    """A SklearnLearner of ``cls`` with ``defaults`` then ``params`` (adapter keys split off)."""
    merged = {**defaults, **params}
    adapter = {k: merged.pop(k) for k in ADAPTER_PARAMS if k in merged}
    if "suds" in merged:
        raise ConfigError(f"model {name}: suds is set by the name; append +SUDS instead")
    est_params = {}
    for key, value in merged.items():
        key = key.removeprefix("estimator__")
        est_params[key] = decode(value, name)
    try:
        estimator = cls()
    except TypeError as exc:
        raise ConfigError(f"model {name!r}: {cls.__name__}() cannot be built ({exc})") from None
    check_regressor(estimator, name)
    valid = estimator.get_params(deep=True)
    bad = [k for k in est_params if k not in valid]
    if bad:
        raise ConfigError(
            f"model {name}: unknown parameter(s) {', '.join(bad)}; valid: "
            + ", ".join(sorted([*ADAPTER_PARAMS, *estimator.get_params(deep=False)]))
        )
    # Top-level keys first: a nested key (kernel__length_scale) refers to the object set.
    top = {k: v for k, v in est_params.items() if "__" not in k}
    nested = {k: v for k, v in est_params.items() if "__" in k}
    try:
        estimator.set_params(**top)
        estimator.set_params(**nested)
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"model {name}: {exc}") from None
    _check_values(estimator, name)
    model = SklearnLearner(estimator=estimator, suds=suds, **adapter)
    model._validate()
    return model


def _check_values(estimator, name: str) -> None:
    """scikit-learn's own check of parameter values, without data, where it has one."""
    validate = getattr(estimator, "_validate_params", None)
    if validate is None or not hasattr(estimator, "_parameter_constraints"):
        return
    try:
        validate()
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"model {name}: {str(exc).splitlines()[0]}") from None


def recipe(model: SklearnLearner) -> dict:
    """The keyword arguments that rebuild ``model`` with `make_model`, JSON-safe and deep:
    the adapter's parameters and every parameter of the estimator (nested objects as
    class path + parameters), the estimator's random_state excepted (it is the adapter's)."""
    out = {k: encode(getattr(model, k)) for k in ADAPTER_PARAMS}
    for key, value in model.estimator.get_params(deep=False).items():
        if key == "random_state":
            continue
        out[("estimator__" + key) if key in ADAPTER_PARAMS else key] = encode(value)
    return out


def split_name(name: str) -> tuple[str, bool]:
    """(name without +SUDS, whether it had it)."""
    if name.endswith(SUDS_SUFFIX):
        return name[: -len(SUDS_SUFFIX)], True
    return name, False


def make_adapter(name: str, params: dict) -> SklearnLearner | None:
    """The learner of a `sklearn:...` or baseline name, or None for any other name."""
    base, suds = split_name(name)
    if base in BASELINES:
        factory, defaults = BASELINES[base]
        return build(factory(), name, suds, defaults, params)
    if base.startswith(PREFIX):
        path = base[len(PREFIX) :].strip()
        if not path:
            raise ConfigError(
                f"model {name!r}: expected sklearn:ClassName or sklearn:pkg.mod.Class"
            )
        return build(resolve_class(path, name), name, suds, {}, params)
    return None


def is_adapter_name(name: str) -> bool:
    base, _ = split_name(name)
    return base in BASELINES or base.startswith(PREFIX)


__all__ = ["BASELINES", "make_adapter", "recipe"]
