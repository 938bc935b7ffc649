"""`suds-exp discrepancy`: its options from their strings, its default report folder, and
the lines it prints."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from suds_exp import console
from suds_exp.commands.simulate import build_config
from suds_exp.discrepancy import DiscrepancyOptions, DiscrepancyResult, run_discrepancy
from suds_exp.discrepancy.discover import DiscoverySettings
from suds_exp.discrepancy.naming import default_name
from suds_exp.discrepancy.options import check_exclude
from suds_exp.robot import parse_ids
from suds_exp.sim.config import SimConfig


def parse_exclude(text: str | None) -> tuple[str, ...]:
    """``"body_inertia,hinge_damping"`` -> a tuple of effect names, each checked."""
    if text is None or not text.strip():
        return ()
    return check_exclude(text.split(","))


def default_out(name: str) -> Path:
    """The report folder of run ``name``: reports/NAME, prefixed ``discrepancy-`` unless
    the name starts with it."""
    return Path("reports") / (name if name.startswith("discrepancy") else f"discrepancy-{name}")


def discrepancy_command(
    store,
    start: SimConfig,
    options: DiscrepancyOptions,
    trials: str | None = None,
    prep: str | None = None,
    name: str | None = None,
    out: Path | None = None,
    progress: bool = False,
) -> DiscrepancyResult:
    """`run_discrepancy` from the command's values: ``trials`` as ids text (``1,2,5-8``),
    ``name`` by default ``discrepancy-<time>`` and ``out`` by default `default_out` of it."""
    name = name or default_name()
    return run_discrepancy(
        store,
        prep,
        start,
        name=name,
        trials=parse_ids(trials),
        options=options,
        out=default_out(name) if out is None else out,
        progress=progress,
    )


def start_model(model: Path | None, model_effects: Sequence[str] = ()) -> SimConfig:
    """The starting simulator: the config file ``model`` (default nominal) with the
    ``NAME=VALUE`` items of ``model_effects`` applied."""
    return build_config(model, list(model_effects), param="model_effects")


def discrepancy_options(
    alpha: float = 0.01,
    max_effects: int = 3,
    seed: int = 0,
    exclude_candidates: str | None = None,
    discover: bool = True,
    max_terms: int = 4,
) -> DiscrepancyOptions:
    """The `DiscrepancyOptions` of the command's options (``exclude_candidates`` a comma
    list of effect names)."""
    return DiscrepancyOptions(
        alpha=alpha,
        max_effects=max_effects,
        seed=seed,
        exclude=parse_exclude(exclude_candidates),
        discover=discover,
        discovery=DiscoverySettings(max_terms=max_terms),
    )


def _num(value) -> str:
    """A fitted value to 4 significant digits (text, such as a level name, as it is)."""
    return f"{value:.4g}" if isinstance(value, int | float) else str(value)


def print_discrepancy(result: DiscrepancyResult) -> None:
    """One line per named effect and learned term, the outcome and the report folder."""
    for n in result.named:
        ci = "[" + ", ".join(f"{v:.4g}" for v in n["ci"]) + "]" if n["ci"] else ""
        console.out.print(
            f"step {n['step']}: {n['candidate']} {n['parameter'] or ''} = {_num(n['value'])} "
            f"{n['unit']} {ci} (p_adj {n['p_adjusted']:.2g}); "
            f"held-out loss {n['gap_before']:.4g} -> {n['gap_after']:.4g}"
        )
    if result.discovery is not None:
        for line in result.discovery.equations():
            console.out.print(f"learned correction: {line}")
    console.out.print(result.outcome)
    console.out.print(f"report: {result.report_dir}")
