"""Hide effects in freshly simulated "measured" data and let the workflow find them.

The measured data always takes the real path: simulator -> QTM files -> ingest ->
preprocess; only the effect settings are known to the caller, never to the workflow.
Used by `suds-exp demo`, the tests and `benchmarks/discrepancy.py`.
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from suds_exp.discrepancy import DiscrepancyOptions, DiscrepancyResult, run_discrepancy
from suds_exp.discrepancy.effects import main_parameter
from suds_exp.robot import FREQUENCIES_HZ
from suds_exp.sim.config import SimConfig
from suds_exp.sim.dataset import SimDesign
from suds_exp.sim.effects import set_effect

#: Hidden-effect settings for the checks: (effect, fixed settings, drawn parameter).
HIDDEN: dict[str, tuple[dict, str]] = {
    "flippers": ({"mode": "locked"}, "locked_angle_deg"),
    "hinge_damping": ({}, "damping"),
    "body_inertia": ({}, "tau_s"),
    "asymmetric_drag": ({}, "ratio"),
    "drag_anisotropy": ({}, "normal_scale"),
    "medium_compaction": ({}, "rate_per_m"),
    "spoke_oscillation": ({}, "gain"),
    "hinge_friction": ({}, "torque_n_mm"),
}


def draw_hidden(effect: str, rng: np.random.Generator, min_fraction: float = 0.35) -> dict:
    """Settings of ``effect`` with its parameter drawn from the realistic range.

    The value is uniform over the part of the range at least ``min_fraction`` of the way
    from the "off" value to the range's end (on a random side when "off" is inside the
    range): a value right next to "off" is no effect at all and nothing could name it.
    """
    fixed, param = HIDDEN[effect]
    spec = next(p for p in _params(effect) if p["name"] == param)
    lo, hi = (float(v) for v in spec["range"])
    off = spec["off"] if not isinstance(spec["off"], str) else lo
    off = float(np.clip(off, lo, hi))
    sides = [(off, hi)] if off <= lo else [(off, lo)] if off >= hi else [(off, lo), (off, hi)]
    a, b = sides[int(rng.integers(len(sides)))]
    u = rng.uniform(min_fraction, 1.0)
    return {**fixed, param: float(a + u * (b - a))}


def _params(effect: str) -> list[dict]:
    from suds_exp.discrepancy.effects import effect_parameters

    return effect_parameters(effect)


@dataclass
class HiddenRun:
    """What was hidden and what the workflow said."""

    hidden: dict[str, dict]
    result: DiscrepancyResult

    @property
    def named_effects(self) -> list[str]:
        return [n["effect"] for n in self.result.named]

    def truth(self, effect: str) -> float | None:
        fixed, param = HIDDEN.get(effect, ({}, main_parameter(effect)["name"]))
        v = self.hidden.get(effect, {}).get(param)
        return None if v is None else float(v)


def simulate_measured(workdir: Path, config: SimConfig, design: SimDesign):
    """Simulate ``design`` on the robot of ``config`` into ``workdir``, ingest and
    preprocess it; return the store."""
    from suds_exp.preprocess import preprocess
    from suds_exp.store import Store
    from suds_exp.workflows.simulate import simulate_and_ingest

    store = Store(workdir / "suds.duckdb")
    simulate_and_ingest(store, workdir / "data", config, design)
    preprocess(store, "v1", progress=False)
    return store


def hidden_models(
    hidden: dict[str, dict], model: SimConfig | None = None
) -> tuple[SimConfig, SimConfig]:
    """(truth, starting model) of a hidden-effect run: the nominal robot with ``hidden``
    set, and ``model`` or, by default, the nominal model with every hidden effect
    switched off (an effect the nominal robot already has, spoke_oscillation, is hidden
    only by starting from a model without it)."""
    truth = SimConfig()
    start = model or SimConfig()
    for effect, settings in hidden.items():
        truth = set_effect(truth, effect, settings)
        if model is None:
            spec = main_parameter(effect)
            if not isinstance(spec["off"], str):
                start = set_effect(start, effect, {spec["name"]: spec["off"]})
    return truth, start


def hidden_effect_run(
    hidden: dict[str, dict] | None = None,
    seed: int = 0,
    model: SimConfig | None = None,
    workdir: str | Path | None = None,
    gaits: Sequence[str] = ("S+", "O", "D+"),
    frequencies_hz: Sequence[float] = FREQUENCIES_HZ,
    repeats: int = 4,
    cycles: tuple[int, int] = (4, 6),
    options: DiscrepancyOptions | None = None,
    out: str | Path | None = None,
    progress: bool = False,
) -> HiddenRun:
    """Simulate "measured" data with ``hidden`` effects ({effect: settings}, e.g.
    ``{"body_inertia": {"tau_s": 0.2}}``; None or {}: the nominal robot) and run the
    workflow on it starting from ``model`` (default: nominal, with every hidden effect
    switched off).

    Returns the hidden settings and the workflow's result (``result.named``,
    ``result.gap_before``, ``result.gap_after``).
    """
    hidden = dict(hidden or {})
    truth, start = hidden_models(hidden, model)
    opts = options or DiscrepancyOptions(seed=seed)
    with tempfile.TemporaryDirectory(prefix="suds-discrepancy-") as tmp:
        base = Path(workdir) if workdir is not None else Path(tmp)
        design = SimDesign(tuple(gaits), tuple(frequencies_hz), repeats, cycles, seed)
        store = simulate_measured(base, truth, design)
        result = run_discrepancy(
            store,
            "v1",
            start,
            name=f"hidden-{seed}",
            options=opts,
            out=out,
            progress=progress,
        )
    return HiddenRun(hidden, result)


def demo_discrepancy(
    effect: str = "body_inertia",
    seed: int = 0,
    out: str | Path | None = None,
    progress: bool = False,
    **design,
) -> dict:
    """`suds-exp demo`'s last act: hide ``effect`` (parameter drawn with ``seed``) in
    freshly simulated data and run the workflow with the nominal model.

    ``design`` (gaits, frequencies_hz, repeats, cycles) overrides the simulated design of
    `hidden_effect_run` (3 gaits x 3 frequencies x 4 repeats, 4-6 cycles: about a minute).

    Returns a dict: hidden effect and value, named effects with values and intervals,
    held-out gap (mean normalised squared residual) and RMS of vx before and after.
    """
    rng = np.random.default_rng(seed)
    settings = draw_hidden(effect, rng)
    run = hidden_effect_run({effect: settings}, seed=seed, out=out, progress=progress, **design)
    res = run.result
    return {
        "hidden": {effect: settings},
        "named": res.named,
        "gap_before": res.gap_before,
        "gap_after": res.gap_after,
        "rmse_vx_before": float(res.steps[0].test_rmse[0]),
        "rmse_vx_after": float(res.steps[-1].test_rmse[0]),
        "outcome": res.outcome,
        "seconds": res.seconds,
    }
