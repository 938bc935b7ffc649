"""The named candidate effects as data, and setting them on a configuration.

`effect_library()` lists every effect with its parameters (unit, nominal value, realistic
range, meaning), its main parameter and that parameter's "on" and "off" values; the
discrepancy workflow fits effects within these ranges and `suds-exp effects` prints it.
"""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Mapping

from suds_exp.errors import ConfigError
from suds_exp.sim import effect_params
from suds_exp.sim.config import SimConfig, config_from_dict

#: The built-in effects' names (`effect_params.EFFECTS` also holds any registered later).
EFFECT_NAMES = tuple(effect_params.EFFECTS)


def _effect_class(name: str):
    try:
        return effect_params.EFFECTS[name]
    except KeyError:
        raise ConfigError(
            f"effect {name!r}: expected one of {', '.join(effect_params.EFFECTS)}"
        ) from None


def _main_field(name: str) -> dataclasses.Field:
    return next(f for f in dataclasses.fields(_effect_class(name)) if f.metadata.get("main"))


def effect_library(config: SimConfig | None = None) -> list[dict]:
    """Every named effect as a dict (JSON-ready).

    Keys: ``name``, ``description``, ``main`` (main parameter name), ``on_value``,
    ``off_value``, ``nominal_state`` ("on"/"off", or the mode for ``flippers``),
    ``state`` (the same for `config`, default nominal), ``replay`` (what a replay of
    measured joint angles does with it: "exact", "mean" for an effect drawn anew per
    trial, "none" for one acting between command and joint) and ``parameters``: list of
    {``name``, ``unit``, ``nominal``, ``value`` (in `config`), ``range`` [low, high],
    ``description``, ``config_key`` (dotted path in the config file)}.
    """
    nominal = SimConfig().effects
    current = (config or SimConfig()).effects
    out = []
    for name, cls in effect_params.EFFECTS.items():
        main = _main_field(name)
        params = []
        for f in dataclasses.fields(cls):
            md = f.metadata
            params.append(
                {
                    "name": f.name,
                    "unit": md["unit"],
                    "nominal": getattr(getattr(nominal, name), f.name),
                    "value": getattr(getattr(current, name), f.name),
                    "range": list(md["range"]),
                    "description": md["doc"],
                    "config_key": f"effects.{name}.{f.name}",
                }
            )
        off = main.metadata["off"]

        def state(effects, name=name, main=main, off=off) -> str:
            value = getattr(getattr(effects, name), main.name)
            if isinstance(value, str):
                return value
            return "off" if value == off else "on"

        out.append(
            {
                "name": name,
                "description": inspect.cleandoc(cls.__doc__ or ""),
                "main": main.name,
                "on_value": main.metadata["on"],
                "off_value": off,
                "nominal_state": state(nominal),
                "state": state(current),
                "replay": getattr(cls, "replay", "exact"),
                "parameters": params,
            }
        )
    return out


def parse_effect(assignment: str, param: str = "effects") -> tuple[str, dict]:
    """``"NAME=VALUE"`` or ``"NAME.PARAM=VALUE"`` -> (effect, {parameter: value}).

    VALUE is a number, ``on`` / ``off`` (the main parameter's typical on value / its
    no-effect value) or, for ``flippers``, ``free`` / ``locked`` / ``absent``. Errors name
    ``param``, the parameter that carried the text.
    """
    if "=" not in assignment:
        raise ConfigError(
            f"{param} {assignment!r}: expected NAME=VALUE, e.g. hinge_damping=5", param=param
        )
    key, text = (s.strip() for s in assignment.split("=", 1))
    name, _, field_name = key.partition(".")
    cls = _effect_class(name)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    field = _main_field(name) if not field_name else fields.get(field_name)
    if field is None:
        raise ConfigError(
            f"{param} {assignment!r}: {name} has parameters {', '.join(fields)}", param=param
        )
    md = field.metadata
    if text in ("on", "off") and md.get("main"):
        value = md[text]
    elif isinstance(field.default, str):
        value = text
    else:
        try:
            value = float(text)
        except ValueError:
            raise ConfigError(
                f"{param} {assignment!r}: expected a number, on or off for {name}.{field.name}",
                param=param,
            ) from None
    return name, {field.name: value}


def set_effect(
    config: SimConfig, effect: str, settings: Mapping[str, float | str] | None = None
) -> SimConfig:
    """A validated copy of ``config`` with ``settings`` ({parameter: value}) on ``effect``.

    ``set_effect(config, "NAME=VALUE")`` (no ``settings``) first reads the assignment with
    `parse_effect`; an invalid value is then reported with the assignment.
    """
    if settings is not None:
        return config_from_dict({"effects": {effect: dict(settings)}}, base=config)
    name, parsed = parse_effect(effect)
    try:
        return config_from_dict({"effects": {name: parsed}}, base=config)
    except ConfigError as exc:
        raise ConfigError(f"effects {effect!r}: {exc}", param="effects") from None


def apply_effects(config: SimConfig, assignments, param: str = "effects") -> SimConfig:
    """``config`` with each ``NAME=VALUE`` of ``assignments`` set in order (`parse_effect`);
    errors name ``param`` and the assignment."""
    for assignment in assignments:
        name, settings = parse_effect(assignment, param)
        try:
            config = set_effect(config, name, settings)
        except ConfigError as exc:
            raise ConfigError(f"{param} {assignment!r}: {exc}", param=param) from None
    return config


def with_effects(config: SimConfig, effects: dict[str, dict[str, float | str]]) -> SimConfig:
    """A copy of `config` with effect parameters set, e.g. {"body_inertia": {"tau_s": 0.1}}."""
    return config_from_dict({"effects": effects}, base=config)
