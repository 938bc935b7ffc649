"""`campaign_status`: how far a campaign is, how fast it goes, and when it will finish."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from typing import TYPE_CHECKING

from suds_exp.campaign.lock import run_holder
from suds_exp.errors import CampaignError
from suds_exp.ingest.experiment import read_design
from suds_exp.store.rows import read_connection, text_literal

if TYPE_CHECKING:  # status reads through DuckDB alone: a Store is only its path here
    from suds_exp.store import Store


def _read_status(raw, path, name: str):
    """The campaign's row (definition, number of jobs, version), results per model, the
    start of its last run and what it finished since."""
    # the campaign's name as a literal, not a bound parameter: see text_literal
    name_sql = text_literal(name)
    has = raw.execute(
        "SELECT count(*) FROM information_schema.tables WHERE table_name = 'campaigns'"
    ).fetchone()[0]
    row = (
        raw.execute(
            f"SELECT definition, n_jobs, prep_version FROM campaigns WHERE name = {name_sql}"
        ).fetchone()
        if has
        else None
    )
    if row is None:
        names = (
            [r[0] for r in raw.execute("SELECT name FROM campaigns ORDER BY 1").fetchall()]
            if has
            else []
        )
        raise CampaignError(
            f"no campaign {name!r} in {path} (have: {', '.join(names) or 'none'}); start one first",
            step="run",
        )
    definition, total, prep = json.loads(row[0]), int(row[1]), row[2]
    per_model = {
        model: (int(done), int(failed))
        for model, done, failed in raw.execute(
            "SELECT model, count(*) AS done, count(error) AS failed FROM results "
            f"WHERE campaign = {name_sql} GROUP BY model"
        ).fetchall()
    }
    last_run = raw.execute(
        f"SELECT started_at FROM campaign_runs WHERE campaign = {name_sql} ORDER BY id DESC LIMIT 1"
    ).fetchone()
    started = last_run[0] if last_run else None
    since = (
        raw.execute(
            f"SELECT count(*), max(finished_at) FROM results WHERE campaign = {name_sql} "
            "AND finished_at >= (SELECT started_at FROM campaign_runs "
            f"WHERE campaign = {name_sql} ORDER BY id DESC LIMIT 1)"
        ).fetchone()
        if started is not None
        else (0, None)
    )
    return definition, total, prep, per_model, started, since


def _model_table(models: list[str], total: int, per_model: dict) -> list[dict]:
    per_job = total // max(len(models), 1)
    return [
        {
            "model": m,
            "done": per_model.get(m, (0, 0))[0],
            "total": per_job,
            "failed": per_model.get(m, (0, 0))[1],
        }
        for m in models
    ]


def campaign_status(store: Store, name: str) -> dict:
    """Progress of campaign ``name`` (read-only; waits briefly if a run is writing).

    Returns a dict: ``campaign``, ``prep``, ``done``, ``total``, ``failed`` (jobs whose
    learner raised or predicted non-finite values), ``models`` (list of {model, done,
    total, failed}), ``running`` (whether a run holds the database and works on this
    campaign), ``last_run_started`` (UTC), ``rate_jobs_per_s`` (jobs finished per second
    during the last run, None before any), ``eta_s`` (seconds left at that rate while
    running, else None), ``skipped_cells`` (the (condition, training cycles) cells the
    campaign leaves out, asked for with ``skip_infeasible``: list of {condition,
    n_cycles, pairs}), ``experiment`` (the design stored with the data,
    `suds_exp.ingest.stored_design`: {source, axes: list of {name, kind, levels, added}}).
    """
    with read_connection(store.path) as raw:
        definition, total, prep, per_model, started, since = _read_status(raw, store.path, name)
        design = read_design(raw)
    table = _model_table(list(definition["options"]["models"]), total, per_model)
    done = sum(r["done"] for r in table)
    holder = run_holder(store.path)
    running = bool(holder) and holder.get("campaign") in (name, None)
    now = datetime.now(UTC).replace(tzinfo=None)
    rate = None
    if started is not None and since[0]:
        end = now if running else since[1]
        seconds = (end - started).total_seconds()
        rate = since[0] / seconds if seconds > 0 else None
    eta = (total - done) / rate if running and rate else None
    return {
        "campaign": name,
        "prep": prep,
        "done": done,
        "total": total,
        "failed": sum(r["failed"] for r in table),
        "models": table,
        "running": running,
        "last_run_started": started,
        "rate_jobs_per_s": rate,
        "eta_s": eta,
        "skipped_cells": definition.get("skipped_cells", []),
        "experiment": design_document(design),
    }


def design_document(design) -> dict:
    """An `ExperimentDesign` as JSON-ready data: ``source`` and ``axes`` (each ``name``,
    ``kind``, declared ``levels`` and ``added`` levels)."""
    return {
        "source": design.source,
        "axes": [
            {"name": a.name, "kind": a.kind, "levels": list(a.levels), "added": list(a.added)}
            for a in design.axes
        ],
    }
