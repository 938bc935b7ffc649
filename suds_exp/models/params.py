"""Hyper-parameters declared once: a default and a constraint each, per learner class.

A learner class lists its hyper-parameters in ``_hyper_parameters`` (name -> `Param`), in the
order of its constructor. From that one table follow its ``__init__`` (`init_from`: one
keyword per parameter, stored unchanged as scikit-learn's estimator contract asks, with a
real signature that `get_params` reads) and its checks (`Learner._validate_params`, the
counterpart of scikit-learn's ``_parameter_constraints`` and ``_validate_params``). A
variant that adds parameters declares ``Parent._hyper_parameters | {...}``; one that adds none
declares nothing and inherits its parent's ``__init__``.

A constraint checks one value and raises a one-line `ConfigError` naming the learner, the
parameter and what was expected: ``GMR: n_components=0; expected an integer >= 1``.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from suds_exp.errors import ConfigError


def _refuse(model: str, name: str, value, expected: str):
    raise ConfigError(f"{model}: {name}={value!r}; expected {expected}")


def _is_int(value) -> bool:
    return isinstance(value, int | np.integer) and not isinstance(value, bool)


def _is_number(value) -> bool:
    return isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool)


@dataclass(frozen=True)
class Integer:
    """An integer >= ``low`` (and <= ``high`` when given: "from low to high")."""

    low: int
    high: int | None = None
    why: str = ""

    def check(self, name: str, value, model) -> None:
        if self.high is None:
            if not _is_int(value) or value < self.low:
                _refuse(model.name, name, value, f"an integer >= {self.low}")
        elif not _is_int(value) or not self.low <= value <= self.high:
            why = f" ({self.why})" if self.why else ""
            _refuse(model.name, name, value, f"an integer from {self.low} to {self.high}{why}")


@dataclass(frozen=True)
class Real:
    """A number >= ``low`` (> with ``strict``), and below ``high`` when given (<=, or <
    with ``high_open``): "a number in [low, high]" / "[low, high)"."""

    low: float
    strict: bool = False
    high: float | None = None
    high_open: bool = False

    def check(self, name: str, value, model) -> None:
        ok = _is_number(value) and (value > self.low if self.strict else value >= self.low)
        if not ok:
            _refuse(model.name, name, value, f"a number {'>' if self.strict else '>='} {self.low}")
        if self.high is not None and (value >= self.high if self.high_open else value > self.high):
            close = ")" if self.high_open else "]"
            _refuse(model.name, name, value, f"a number in [{self.low:g}, {self.high:g}{close}")


@dataclass(frozen=True)
class Options:
    """One of ``choices``."""

    choices: tuple

    def check(self, name: str, value, model) -> None:
        if value not in self.choices:
            _refuse(model.name, name, value, f"one of {', '.join(map(str, self.choices))}")


@dataclass(frozen=True)
class Rule:
    """Any other check: ``rule(name, value, model)`` raises ConfigError (it may read the
    model's other parameters, as GMR's ``k_candidates`` reads ``select_k``)."""

    rule: Callable[[str, Any, Any], None]

    def check(self, name: str, value, model) -> None:
        self.rule(name, value, model)


@dataclass(frozen=True)
class Param:
    """One hyper-parameter: its ``default`` and its ``constraint`` (None: not checked by
    this learner, e.g. one it hands to another estimator that checks it)."""

    default: Any
    constraint: Integer | Real | Options | Rule | None = None


def pick(parameters: dict[str, Param], *names: str) -> dict[str, Param]:
    """Some of ``parameters``, in the order named (a learner that shares a subset)."""
    return {n: parameters[n] for n in names}


def init_from(parameters: dict[str, Param]) -> Callable:
    """An ``__init__`` taking each of ``parameters`` (positionally or by keyword, in
    their order) with its default and storing it unchanged under its own name."""
    signature = inspect.Signature(
        [inspect.Parameter("self", inspect.Parameter.POSITIONAL_OR_KEYWORD)]
        + [
            inspect.Parameter(n, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=p.default)
            for n, p in parameters.items()
        ]
    )
    names = tuple(parameters)

    def __init__(self, *args, **kwargs):
        bound = signature.bind(self, *args, **kwargs)
        bound.apply_defaults()
        arguments = bound.arguments
        for n in names:
            setattr(self, n, arguments[n])

    __init__.__signature__ = signature
    return __init__
