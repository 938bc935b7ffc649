"""The candidate library: every named simulator effect as a fit of at most one parameter.

The simulator declares its effects as dataclasses in `suds_exp.sim.config.Effects`, each
parameter field carrying metadata (unit, realistic range, main flag, the value meaning
"on"). This module turns that declaration into candidates the workflow can try:

- an effect whose main parameter is a number becomes one candidate that fits that
  number inside its realistic range;
- an effect whose main parameter is a choice (``flippers``: free | locked | absent)
  becomes one candidate per choice other than the model's current one; a choice that
  comes with a numeric companion parameter with a range (``locked`` ->
  ``locked_angle_deg``) fits that companion, the others have nothing to fit.

Nothing here edits the simulator: configurations are copied and set by field name.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from suds_exp.errors import ConfigError
from suds_exp.sim.config import SimConfig
from suds_exp.sim.effects import apply_effects, set_effect

#: For a choice-valued effect: which numeric parameter each choice brings along.
CHOICE_COMPANIONS: dict[tuple[str, str], str] = {("flippers", "locked"): "locked_angle_deg"}


@dataclass(frozen=True)
class Candidate:
    """One way to extend the model: set ``fixed``, then fit ``param`` within ``bounds``.

    Attributes
    ----------
    effect : str
        Effect name (a field of `SimConfig.effects`).
    label : str
        Human name, ``effect`` or ``effect=choice``.
    param : str or None
        The fitted parameter (field of the effect), None when there is nothing to fit.
    bounds : (float, float)
        Realistic range of ``param`` in its unit.
    unit : str
    fixed : dict
        Settings of the effect applied before the fit (e.g. ``{"mode": "locked"}``).
    """

    effect: str
    label: str
    param: str | None
    bounds: tuple[float, float] = (0.0, 0.0)
    unit: str = "-"
    fixed: dict = field(default_factory=dict)

    def apply(self, cfg: SimConfig, value: float | None) -> SimConfig:
        """A copy of ``cfg`` with this candidate set (``value`` in ``unit``)."""
        settings = dict(self.fixed)
        if self.param is not None:
            settings[self.param] = float(value)
        return set_effect(cfg, self.effect, settings)


def _effect_fields(cfg: SimConfig) -> dict[str, object]:
    return {f.name: getattr(cfg.effects, f.name) for f in dataclasses.fields(cfg.effects)}


def effect_names() -> list[str]:
    """Names of the simulator's effects, in declaration order."""
    return list(_effect_fields(SimConfig()))


def effect_parameters(effect: str) -> list[dict]:
    """The declared parameters of ``effect``: name, unit, range, nominal, main, on."""
    effects = _effect_fields(SimConfig())
    if effect not in effects:
        raise ConfigError(f"effect {effect!r}: unknown; expected one of {', '.join(effects)}")
    out = []
    for f in dataclasses.fields(effects[effect]):
        meta = dict(f.metadata)
        out.append(
            {
                "name": f.name,
                "unit": meta.get("unit", "-"),
                "range": tuple(meta.get("range", (None, None))),
                "nominal": f.default,
                "main": bool(meta.get("main", False)),
                "on": meta.get("on"),
                "off": f.default if meta.get("off") is None else meta["off"],
                "doc": meta.get("doc", ""),
            }
        )
    return out


def main_parameter(effect: str) -> dict:
    """The main parameter of ``effect`` (the one ``NAME=VALUE`` sets)."""
    params = effect_parameters(effect)
    return next((p for p in params if p["main"]), params[0])


def get_effect(cfg: SimConfig, effect: str) -> dict:
    """Current settings of ``effect`` in ``cfg``, {param: value}."""
    return dataclasses.asdict(getattr(cfg.effects, effect))


def parse_effect_items(items: list[str], base: SimConfig | None = None) -> SimConfig:
    """Apply ``["flippers=absent", "hinge_damping=8"]`` (main parameters; ``NAME.PARAM=VALUE``
    for another) to ``base`` with the simulator's own parser (`sim.effects.parse_effect`).

    Raises `ConfigError` naming the item when the effect, parameter or value is not valid.
    """
    return apply_effects(SimConfig() if base is None else base.copy(), items, "model_effects")


def _choices(spec: dict) -> list[str]:
    low, high = spec["range"]
    values = [spec["nominal"], low, high, spec["on"]]
    # the doc string of a choice lists them as "a | b | c"
    values += [v.strip() for v in str(spec["doc"]).split("|")]
    out = []
    for v in values:
        if isinstance(v, str) and v and " " not in v and v not in out:
            out.append(v)
    return out


def candidates_for(
    cfg: SimConfig, exclude: set[str] | frozenset[str] = frozenset()
) -> list[Candidate]:
    """The candidates offered for model ``cfg``: every effect not in ``exclude`` that
    the model lacks.

    A numeric main parameter at its "off" value gives one candidate fitted over its
    realistic range (an effect already on in ``cfg`` is part of the model and not
    offered); a choice gives one candidate per other choice (see the module docstring).
    """
    out: list[Candidate] = []
    for effect in effect_names():
        if effect in exclude:
            continue
        spec = main_parameter(effect)
        if isinstance(spec["nominal"], str):
            current = get_effect(cfg, effect)[spec["name"]]
            for choice in _choices(spec):
                if choice == current:
                    continue
                companion = CHOICE_COMPANIONS.get((effect, choice))
                params = {p["name"]: p for p in effect_parameters(effect)}
                fixed = {spec["name"]: choice}
                if companion is None:
                    out.append(Candidate(effect, f"{effect}={choice}", None, fixed=fixed))
                else:
                    p = params[companion]
                    out.append(
                        Candidate(
                            effect,
                            f"{effect}={choice}",
                            companion,
                            tuple(float(b) for b in p["range"]),
                            p["unit"],
                            fixed,
                        )
                    )
            continue
        if get_effect(cfg, effect)[spec["name"]] != spec["off"]:
            continue
        low, high = spec["range"]
        out.append(Candidate(effect, effect, spec["name"], (float(low), float(high)), spec["unit"]))
    return out
