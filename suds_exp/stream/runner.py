"""`run_stream`: prequential evaluation of learners on stored trials, resumable.

A stream is named; its definition (learners and their parameters, trials, settings,
change times) is stored in `streams` and a continuation must match it. The unit of work
is one (learner, trial): its rows are computed by `prequential.run_trial` and written in
one transaction, so a killed run loses at most the unit in hand, and a rerun skips the
units already stored. Every unit is deterministic (learners are seeded), so a killed and
resumed stream holds exactly the rows of an uninterrupted one (timings aside).
"""

from __future__ import annotations

import dataclasses
import json
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime

import pandas as pd
import sqlalchemy as sa

from suds_exp.campaign.definition import resolve_models
from suds_exp.errors import StreamError
from suds_exp.progress import progress_bar
from suds_exp.store import Store
from suds_exp.store.definition import check_same
from suds_exp.stream.prequential import StreamSettings, run_trial, trial_cycles

_SCHEDULE = re.compile(r"schedule=\S+@([0-9.eE+-]+)s")


@dataclass
class StreamSummary:
    """What a call of `run_stream` did."""

    stream: str
    units: int
    done_before: int
    done_now: int = 0
    rows_now: int = 0
    created: bool = False
    trials: list[int] = field(default_factory=list)

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


def change_times(store: Store, trials: list[int]) -> dict[int, float | None]:
    """First scheduled change (s) of each trial, from its notes (``schedule=...@Ts``)."""
    if not trials:
        return {}
    notes = store.query_df(
        f"SELECT id, notes FROM trials WHERE id IN ({', '.join('?' * len(trials))})", trials
    )
    out: dict[int, float | None] = {int(t): None for t in trials}
    for tid, text in zip(notes.id, notes.notes, strict=True):
        times = [float(m) for m in _SCHEDULE.findall(text or "")]
        out[int(tid)] = min(times) if times else None
    return out


def _definition(models, trials, prep, settings, changes) -> dict:
    return {
        "prep": prep,
        "models": resolve_models(models, "measured"),
        "trials": [int(t) for t in trials],
        "settings": dataclasses.asdict(settings),
        "change_s": {str(k): v for k, v in changes.items()},
    }


def run_stream(
    store: Store,
    name: str,
    models: list[str] | str | dict,
    trials: list[int] | None = None,
    prep: str | None = None,
    settings: StreamSettings | None = None,
    change_at: float | str | None = None,
    samples: pd.DataFrame | None = None,
    progress: bool = True,
    on_unit: Callable[[int], None] | None = None,
) -> StreamSummary:
    """Create or continue stream `name`; fill `stream_cycles` with one row per scored cycle.

    models: learner names (see `suds_exp.models.make_model`), comma text, or name ->
    params. trials: trial ids (default: every trial of the version). prep: preprocessing
    version (default: the only one). change_at: the change time (s) of every trial,
    overriding the ``schedule=`` notes the simulator writes. samples: use this frame
    instead of loading `prep` (tests, benchmarks; `prep` then only labels it).
    on_unit(n_done) is called after each written (learner, trial).
    """
    settings = settings or StreamSettings()
    if settings.warmup_cycles < 1:
        raise StreamError(
            f"warmup_cycles: {settings.warmup_cycles}; expected >= 1 cycle", param="warmup_cycles"
        )
    change_at = check_change_at(change_at)
    resolve_models(models, "measured")  # a bad learner or parameter: before anything else
    with store.locked("stream", name):
        prep, samples, trials = _stream_samples(store, prep, trials, samples)
        changes = _stream_changes(store, samples, trials, change_at, settings)
        definition = _definition(models, trials, prep, settings, changes)
        summary = StreamSummary(name, len(definition["models"]) * len(trials), 0, trials=trials)
        stored = _stored_definition(store, name)
        if stored is not None:
            check_same(
                stored,
                definition,
                f"stream {name!r}",
                "use the same options or a new name",
                StreamError,
            )
        done = _done_units(store, name) if stored is not None else set()
        summary.done_before = len(done)
        by_trial = {int(t): g for t, g in samples.groupby("trial_id", sort=True)}
        todo = [
            (tid, model, params)
            for tid in trials
            for model, params in definition["models"].items()
            if (model, tid) not in done
        ]

        def rows_of(tid: int, model: str, params: dict) -> pd.DataFrame:
            return _unit_rows(by_trial[tid], name, model, params, settings, changes)

        created = _run_units(
            store, prep, definition, stored, todo, rows_of, summary, progress, on_unit
        )
        if stored is None and not created:  # nothing to run (no scored cycle): still record it
            with store.write() as conn:
                _register(conn, name, prep, definition)
        summary.created = stored is None
    return summary


def _run_units(store, prep, definition, stored, todo, rows_of, summary, progress, on_unit) -> bool:
    """Compute and write each (trial, learner, params) unit of ``todo`` (rows by
    ``rows_of``), counting them in ``summary``; True when this call stored the stream's
    definition (with its first rows)."""
    name = summary.stream
    # Every learner's first unit is computed before anything is stored, so a learner
    # that cannot run with these settings (too short a warm-up...) is refused with
    # the database unchanged and the name still free.
    first: dict[tuple[str, int], pd.DataFrame] = {}
    for tid, model, params in todo:
        if not any(m == model for m, _ in first):
            first[(model, tid)] = rows_of(tid, model, params)
    created = False
    bar = progress_bar(
        f"Stream {name}", summary.units, progress, done=summary.done_before, unit="runs"
    )
    with bar as advance:
        for tid, model, params in todo:
            rows = first.pop((model, tid)) if (model, tid) in first else rows_of(tid, model, params)
            with store.write() as conn:
                if stored is None and not created:
                    _register(conn, name, prep, definition)
                    created = True
                Store.insert_df(conn, "stream_cycles", rows)
            summary.done_now += 1
            summary.rows_now += len(rows)
            advance()
            if on_unit is not None:
                on_unit(summary.done_before + summary.done_now)
    return created


def check_change_at(value: float | None) -> float | None:
    """``change_at``, a time in s after each trial's start (> 0, a number or its text), as
    a float; None stays None."""
    if value is None:
        return None
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise StreamError(
            f"change_at {value!r}: expected a time in s, e.g. 20", param="change_at"
        ) from None
    if not out > 0:
        raise StreamError(
            f"change_at {value!r}: expected a time > 0 s after the trial's start",
            param="change_at",
        )
    return out


def _unit_rows(trial, name, model, params, settings, changes) -> pd.DataFrame:
    rows = run_trial(trial, model, params, settings)
    rows.insert(0, "stream", name)
    rows["change_s"] = changes[int(trial["trial_id"].iloc[0])]
    return rows


def _stream_samples(store: Store, prep, trials, samples):
    """The version's name, the samples of ``trials`` and their trial ids (every one asked
    for must be there)."""
    from suds_exp.preprocess import get_version

    if samples is None:
        version = get_version(store, prep)
        prep = version.name
        samples = version.samples(trials)
    else:
        prep = prep or "(samples given)"
        if trials is not None:
            samples = samples[samples["trial_id"].isin(trials)]
    present = sorted(int(t) for t in samples["trial_id"].unique())
    if trials is not None:
        missing = sorted(set(int(t) for t in trials) - set(present))
        if missing:
            raise StreamError(
                f"trials: no samples of trial(s) {', '.join(map(str, missing))} "
                f"in preprocessing version {prep}",
                param="trials",
            )
    trials = present
    if not trials:
        raise StreamError(f"no samples in preprocessing version {prep}")
    return prep, samples, trials


def _stream_changes(store: Store, samples, trials, change_at, settings) -> dict:
    """Trial id -> change time (s, None: no change), each inside its trial; every trial
    must have more whole cycles than the warm-up."""
    if change_at is not None:
        changes: dict[int, float | None] = {t: float(change_at) for t in trials}
    elif store.path.exists():
        changes = change_times(store, trials) if _has_trials(store) else {t: None for t in trials}
    else:
        changes = {t: None for t in trials}
    ends = samples.groupby("trial_id")["t"].max()
    for t, c in changes.items():
        if c is not None and not 0 < c < float(ends[t]):
            raise StreamError(
                f"change at {c:g} s: past the end of trial {t} ({float(ends[t]):.1f} s long); "
                "expected 0 < time < the trial's duration"
            )
    for tid, g in samples.groupby("trial_id"):
        n = len(trial_cycles(g, settings.min_samples))
        if n <= settings.warmup_cycles:
            raise StreamError(
                f"trial {tid}: {n} whole cycles, not more than warmup_cycles "
                f"{settings.warmup_cycles}; give longer trials or a shorter warm-up",
                param="warmup_cycles",
            )
    return changes


def _has_trials(store: Store) -> bool:
    with store.read() as conn:
        return sa.inspect(conn).has_table("trials")


def _stored_definition(store: Store, name: str) -> dict | None:
    if not store.path.exists():
        return None
    with store.read() as conn:
        if not sa.inspect(conn).has_table("streams"):
            return None
        row = conn.execute(
            sa.text("SELECT definition FROM streams WHERE name = :n"), {"n": name}
        ).first()
    return None if row is None else json.loads(row.definition)


def _register(conn: sa.Connection, name: str, prep: str, definition: dict) -> None:
    """Store a new stream's definition (in the transaction of its first rows)."""
    conn.execute(
        sa.text(
            "INSERT INTO streams (name, prep_version, definition, created_at) "
            "VALUES (:n, :p, :d, :c)"
        ),
        {
            "n": name,
            "p": prep,
            "d": json.dumps(definition, sort_keys=True),
            "c": datetime.now(UTC).replace(tzinfo=None),
        },
    )


def _done_units(store: Store, name: str) -> set[tuple[str, int]]:
    done = store.query_df(
        "SELECT DISTINCT model, trial_id FROM stream_cycles WHERE stream = ?", [name]
    )
    return {(m, int(t)) for m, t in zip(done.model, done.trial_id, strict=True)}


def stream_rows(store: Store, name: str) -> pd.DataFrame:
    """The stored rows of stream `name`, ordered by model, trial and cycle."""
    rows = store.query_df(
        "SELECT * FROM stream_cycles WHERE stream = ? ORDER BY model, trial_id, cycle", [name]
    )
    if rows.empty and store.query_df("SELECT 1 FROM streams WHERE name = ?", [name]).empty:
        raise StreamError(f"no stream named {name!r}; start one first", step="stream")
    return rows
