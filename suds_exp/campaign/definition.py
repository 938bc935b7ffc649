"""A campaign's definition: the options, the data it runs on and every learner's recipe.

The definition is a JSON document stored in `campaigns.definition`. Continuing a
campaign recomputes it from the options given (an option left out takes its stored
value) and the samples, and refuses to go on when anything differs, naming each
difference, since the finished rows would no longer describe the same experiment.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from suds_exp.campaign.bank import SampleBank
from suds_exp.campaign.conditions import (
    Condition,
    format_condition,
    select_conditions,
)
from suds_exp.campaign.sampling import infeasible_cells
from suds_exp.errors import CampaignError, ConfigError
from suds_exp.models.registry import LEARNERS, MOMENTUM_SUFFIX
from suds_exp.robot import VB_COLUMNS

MODES = ("measured", "rollout")
DEFINITION_VERSION = 1


@dataclass
class CampaignOptions:
    """What a user chooses about a campaign; None means "as stored, else the default".

    Parameters
    ----------
    prep : str
        Preprocessing version whose samples the campaign uses.
    models : sequence of learner names, or mapping name -> parameters
        Learners to compare (default: the five of the paper, default parameters).
    boots : int
        Bootstrap draws per (train, test) pair (default 10).
    train_cycles : int
        Training cycles of the main grid, also the test range length (default 30).
    sweep : sequence of int
        Training cycles of the sample-efficiency sweep on same-condition pairs (default none).
    train_conditions, test_conditions : str or list of (gait, frequency_hz)
        Option string (`GAIT@FREQ`, `GAIT`, `@FREQ`, comma-separated) or conditions;
        default every condition in the samples.
    mode : str
        ``measured`` or ``rollout``, passed to learners that take `mode` (SUDS ones).
    skip_infeasible : bool
        Leave out the (train condition, training cycles) cells the samples cannot supply
        instead of refusing the campaign (default False); the cells left out are stored in
        the definition (``skipped_cells``).
    """

    prep: str | None = None
    models: Sequence[str] | Mapping[str, Mapping[str, Any]] | None = None
    boots: int | None = None
    train_cycles: int | None = None
    sweep: Sequence[int] | None = None
    train_conditions: str | list[Condition] | None = None
    test_conditions: str | list[Condition] | None = None
    mode: str | None = None
    skip_infeasible: bool | None = None


DEFAULTS = CampaignOptions(
    prep=None,
    models=LEARNERS,
    boots=10,
    train_cycles=30,
    sweep=(),
    train_conditions=None,
    test_conditions=None,
    mode="measured",
    skip_infeasible=False,
)


def merge_stored(options: CampaignOptions, stored: dict | None) -> CampaignOptions:
    """``options`` with every None filled from the stored definition, else the default."""
    merged = {}
    for f in fields(CampaignOptions):
        value = getattr(options, f.name)
        if value is None and stored is not None:
            value = stored.get("options", {}).get(f.name)
        if value is None:
            value = getattr(DEFAULTS, f.name)
        merged[f.name] = value
    return CampaignOptions(**merged)


def resolve_models(models, mode: str) -> dict[str, dict]:
    """Learner name -> the JSON-safe recipe (`model_recipe`) of ``make_model(name, **params)``."""
    from suds_exp.models import make_model, model_recipe

    if isinstance(models, str):
        models = [m.strip() for m in models.split(",") if m.strip()]
    items = models.items() if isinstance(models, Mapping) else ((m, {}) for m in models)
    out: dict[str, dict] = {}
    for name, params in items:
        if name in out:
            raise CampaignError(f"models: {name!r} is listed twice", param="models")
        model = make_model(name, **dict(params or {}))
        if "mode" in model.get_params(deep=False):
            model.set_params(mode=mode)
        # values are otherwise first checked by fit, in every job, after the campaign
        # (and its name) was stored with them
        check = getattr(model, "_validate", None)
        try:
            if check is not None:
                check()
        except ConfigError as exc:
            raise CampaignError(f"model_params: {exc}", param="model_params") from None
        out[name] = json.loads(json.dumps(model_recipe(model), default=_json_default))
    if not out:
        raise CampaignError("models: no learner given; expected e.g. TLS,GMR", param="models")
    return out


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple | set):
        return list(value)
    raise TypeError(f"learner parameter {value!r} cannot be stored as JSON")


@dataclass(frozen=True)
class Plan:
    """A resolved campaign: its definition and what the runner needs from it."""

    name: str
    definition: dict
    models: dict[str, dict]
    train_conditions: list[Condition]
    test_conditions: list[Condition]
    boots: int
    train_cycles: int
    sweep: list[int]
    #: (train condition, n_cycles, scope) cells left out (see `enumerate_draws`).
    skipped: tuple = ()

    @property
    def test_cycles(self) -> int:
        return self.train_cycles


def make_plan(
    name: str,
    options: CampaignOptions,
    available: list[Condition],
    bank_for,
    added: frozenset = frozenset(),
) -> tuple[Plan, SampleBank]:
    """Resolve ``options`` (already merged) against the conditions in the samples.

    ``bank_for(conditions)`` builds the `SampleBank` of those conditions; the plan's
    definition records its decimation and the trials used. ``added``: labels of
    conditions that code added to the design after its declaration
    (`suds_exp.experiment.ExperimentDesign.added_labels`, e.g. one verify trial of a
    designed gait each), and (label, frequency) conditions whose every trial a planning
    loop chose and recorded (e.g. its warm-up: one short trial of a declared level);
    their cells the data cannot supply are left out, as ``skip_infeasible`` leaves out
    every condition's.
    """
    if not name or not name.strip():
        raise CampaignError("campaign NAME must not be empty")
    _check_int("boots", options.boots, 1)
    _check_int("train_cycles", options.train_cycles, 1)
    for n in options.sweep:
        _check_int("sweep", n, 1)
    if options.mode not in MODES:
        raise CampaignError(
            f"mode: {options.mode!r}; expected one of {', '.join(MODES)}", param="mode"
        )
    train = _conditions(options.train_conditions, available, "train_conditions")
    test = _conditions(options.test_conditions, available, "test_conditions")
    models = resolve_models(options.models, options.mode)
    bank = bank_for(sorted(set(train) | set(test)))
    _check_velocity(models, bank)
    sweep = sorted({int(n) for n in options.sweep})
    stored_options = {
        "prep": options.prep,
        "models": models,
        "boots": int(options.boots),
        "train_cycles": int(options.train_cycles),
        "sweep": sweep,
        "train_conditions": [list(c) for c in train],
        "test_conditions": [list(c) for c in test],
        "mode": options.mode,
    }
    skipped: list = []
    if not isinstance(options.skip_infeasible, bool):
        raise CampaignError(
            f"skip_infeasible: {options.skip_infeasible!r}; expected true or false",
            param="skip_infeasible",
        )
    if options.skip_infeasible:
        # Stored only when asked for, so the definitions of earlier campaigns (which have
        # no such key) still compare equal when they are continued.
        stored_options["skip_infeasible"] = True
        skipped = infeasible_cells(bank, train, test, int(options.train_cycles), sweep)
    elif added:
        # an added condition holds the few trials a loop ran (one per designed gait), not
        # the repeats a declared one has: what it cannot supply is left out, and said
        cells = infeasible_cells(bank, train, test, int(options.train_cycles), sweep)
        skipped = [cell for cell in cells if cell[0][0] in added or cell[0] in added]
    definition = {
        "version": DEFINITION_VERSION,
        "options": stored_options,
        "test_cycles": int(options.train_cycles),
        "samples_per_cycle": bank.samples_per_cycle,
        "decimation": {f"{k:g}": v for k, v in bank.decimation.items()},
        "trials": bank.describe(),
    }
    if options.skip_infeasible or skipped:
        definition["skipped_cells"] = [
            {"condition": format_condition(c), "n_cycles": n, "pairs": scope}
            for c, n, scope in skipped
        ]
    plan = Plan(
        name=name,
        definition=definition,
        models=models,
        train_conditions=train,
        test_conditions=test,
        boots=int(options.boots),
        train_cycles=int(options.train_cycles),
        sweep=sweep,
        skipped=tuple(skipped),
    )
    return plan, bank


def _check_velocity(models: dict, bank) -> None:
    """A momentum learner learns from measured body velocity: refuse it, before anything
    is written, on samples whose vx, vy, wz are zero throughout (a version of a tethered
    body, or one whose velocity was never measured)."""
    momentum = [m for m in models if m.endswith(MOMENTUM_SUFFIX)]
    cols = [bank.columns.index(c) for c in VB_COLUMNS if c in bank.columns]
    if momentum and (len(cols) < len(VB_COLUMNS) or not np.any(bank.values[:, cols])):
        raise CampaignError(
            f"models: {momentum[0]} learns a momentum state from the body velocity, and "
            "the version's samples have none (vx, vy, wz zero throughout)",
            param="models",
        )


def _conditions(value, available, option) -> list[Condition]:
    if value is None or isinstance(value, str):
        return select_conditions(value, available, option)
    spec = ",".join(format_condition((str(g), float(f))) for g, f in value)
    return select_conditions(spec, available, option)


def _check_int(option: str, value, low: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
        raise CampaignError(f"{option}: {value!r}; expected an integer >= {low}", param=option)


def skipped_cells_text(definition: dict) -> str:
    """The cells a definition leaves out, e.g. ``D-@1 x 48 cycles (same-condition pairs)``
    (comma-separated); empty when none."""
    return ", ".join(
        f"{c['condition']} x {c['n_cycles']} cycles ({c['pairs']} pairs)"
        for c in definition.get("skipped_cells", [])
    )


def normalise(definition: dict) -> dict:
    """The definition as it reads back from JSON (tuples -> lists, keys -> str)."""
    return json.loads(json.dumps(definition, default=_json_default))
