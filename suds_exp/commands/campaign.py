"""`suds-exp run` and `status`: campaign options from their strings, the status table.

The library (`suds_exp.campaign`) takes a `CampaignOptions` of Python values; this module
reads the command line's strings into one and prints what `campaign_status` returns.
"""

from __future__ import annotations

import ast
import json
from collections.abc import Sequence
from typing import TYPE_CHECKING

from suds_exp import console
from suds_exp.campaign.conditions import parse_int_list
from suds_exp.errors import CampaignError

if TYPE_CHECKING:
    from suds_exp.campaign.definition import CampaignOptions

# The definition and the learner registry import every learner (scikit-learn and more):
# imported where options are parsed, so `suds-exp status` starts without them.


def parse_campaign_options(
    *,
    models: str | None = None,
    sweep: str | None = None,
    model_params: Sequence[str] | None = None,
    **rest,
) -> CampaignOptions:
    """Options from command-line strings: ``models="TLS,GMR"`` (``survey`` stands for
    `SURVEY_LEARNERS`), ``sweep="1-10,21"`` (or ``"paper"``), ``model_params`` as
    ``["MLP.alpha=0.01", ...]`` (see `parse_model_params`); the rest as in
    `CampaignOptions`."""
    from suds_exp.campaign.definition import DEFAULTS, CampaignOptions, resolve_models
    from suds_exp.models.registry import LEARNERS, SURVEY_LEARNERS

    names = None if models is None else [m.strip() for m in models.split(",") if m.strip()]
    if names is not None:
        names = [n for m in names for n in (SURVEY_LEARNERS if m == "survey" else (m,))]
    cycles = None if sweep is None else parse_int_list(sweep, "sweep")
    chosen = names
    if model_params:
        chosen = parse_model_params(model_params, names or list(LEARNERS))
    if chosen is not None:
        # a bad learner spec fails here, before the database is opened
        resolve_models(chosen, rest.get("mode") or DEFAULTS.mode)
    return CampaignOptions(models=chosen, sweep=cycles, **rest)


def parse_model_params(items: Sequence[str], names: Sequence[str]) -> dict[str, dict]:
    """``NAME.KEY=VALUE`` strings -> {name: {key: value}} over every name in ``names``.

    NAME may itself hold dots (``sklearn:pkg.mod.Class``): KEY is what follows the last
    dot before ``=``. VALUE is read as JSON (``true``, ``0.01``, ``[64, 64]``), else as a
    Python literal (``(64, 64)``), else kept as text.
    """
    out: dict[str, dict] = {n: {} for n in names}
    for item in items:
        left, eq, text = item.partition("=")
        name, dot, key = left.strip().rpartition(".")
        if not eq or not dot or not name or not key:
            raise CampaignError(
                f"model_params {item!r}: expected NAME.KEY=VALUE, e.g. MLP.alpha=0.01",
                param="model_params",
            )
        if name not in out:
            raise CampaignError(
                f"model_params {item!r}: learner {name!r} is not in models ({', '.join(names)})",
                param=("model_params", "models"),
            )
        try:
            value = json.loads(text)
        except ValueError:
            try:
                value = ast.literal_eval(text)
            except (ValueError, SyntaxError):
                value = text
        out[name][key.strip()] = value
    return out


def status_rows(status: dict):
    """`campaign_status`'s per-learner counts as `Rows` (model, done, total, failed)."""
    from suds_exp.store.rows import Rows

    columns = ("model", "done", "total", "failed")
    return Rows(columns, [tuple(m[c] for c in columns) for m in status["models"]])


def print_status(status: dict) -> None:
    """Print `campaign_status` as a per-learner table and one summary line."""
    table = status_rows(status)
    console.print_rows(table, title=f"campaign {status['campaign']} (prep {status['prep']})")
    rate = status["rate_jobs_per_s"]
    line = f"{status['done']} / {status['total']} jobs done"
    if status["failed"]:
        line += f", {status['failed']} failed (see results.error)"
    if status["running"]:
        line += " - running"
        if rate:
            line += f" at {rate:.2f} jobs/s, about {_duration(status['eta_s'])} left"
    elif rate:
        line += f" - not running (last run: {rate:.2f} jobs/s)"
    console.out.print(line)
    if status.get("experiment"):
        console.out.print(design_line(status["experiment"]))
    if status.get("skipped_cells"):
        from suds_exp.campaign.definition import skipped_cells_text

        console.out.print(
            "left out (--skip-infeasible; the data cannot supply them): "
            + skipped_cells_text(status)
        )


def design_line(experiment: dict) -> str:
    """``experiment paper.toml: axes gait (unordered; 1 level added), frequency_hz
    (numeric)`` from `suds_exp.campaign.status.design_document`."""
    axes = []
    for a in experiment["axes"]:
        added = f"; {len(a['added'])} level(s) added" if a["added"] else ""
        axes.append(f"{a['name']} ({a['kind']}{added})")
    return f"experiment {experiment['source']}: axes {', '.join(axes) or 'none'}"


def _duration(seconds: float | None) -> str:
    if seconds is None:
        return "?"
    seconds = int(round(seconds))
    h, rem = divmod(seconds, 3600)
    m, s = divmod(rem, 60)
    return f"{h}h{m:02d}m" if h else (f"{m}m{s:02d}s" if m else f"{s}s")
