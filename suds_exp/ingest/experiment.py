"""The experiment description kept with the data (migrations 020, 021).

An ingest with a design other than the paper's stores it (`store_description`, in the
ingest's own transaction): one row of ``experiment_description`` (its file) and its axes
and levels in ``experiment_axes`` / ``experiment_levels``. `stored_design` reads it back,
so run, report, findings and status need no ``design`` argument; a design given to them
only overrides the stored one (`design_for`), and keeps the levels code added.

Code that adds trials after the declaration (the verify step of `gait design`, a planning
loop) calls `add_trial_levels` once its trials are ingested: each new trial's label
becomes an *added* level of the design's condition axis, and its values are stored like
an ingested trial's, so every command treats it as one of the design's conditions.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import TYPE_CHECKING

from suds_exp.errors import IngestError
from suds_exp.experiment import FREQUENCY_AXIS, PAPER_DESIGN, Axis, ExperimentDesign, is_paper
from suds_exp.experiment.design import level_problem

if TYPE_CHECKING:  # `suds-exp status` reads the design without loading SQLAlchemy
    import sqlalchemy as sa

#: ``experiment_description.source`` of the paper's design, stored when code adds levels
#: to a database ingested with the default design.
PAPER_SOURCE = "paper"


def stored_design(store) -> ExperimentDesign:
    """The design stored with the data in ``store``: the user's description given at
    ingest with the levels added since, or `PAPER_DESIGN` when none was stored (a paper
    database with added levels returns the paper's design with them)."""
    from suds_exp.store.rows import read_connection

    with read_connection(store.path) as conn:
        return read_design(conn)


def read_design(conn) -> ExperimentDesign:
    """`stored_design` on an open connection (read-only is enough): a SQLAlchemy one or
    DuckDB's own."""
    sql = getattr(conn, "exec_driver_sql", None) or conn.execute
    tables = {r[0] for r in sql("SELECT table_name FROM duckdb_tables()").fetchall()}
    if "experiment_axes" not in tables:  # a database older than migration 020
        return PAPER_DESIGN
    source = None
    if "experiment_description" in tables:
        row = sql("SELECT source FROM experiment_description").fetchone()
        source = row[0] if row else None
    axes = sql("SELECT axis, kind FROM experiment_axes ORDER BY position").fetchall()
    if source is None and not axes:
        return PAPER_DESIGN
    added_col = "added_by" if "experiment_description" in tables else "NULL"
    levels: dict[str, tuple[list[str], list[str]]] = {}
    for axis, level, added in sql(
        f"SELECT axis, level, {added_col} FROM experiment_levels ORDER BY axis, position"
    ).fetchall():
        levels.setdefault(axis, ([], []))[0 if added is None else 1].append(level)
    design = ExperimentDesign(
        tuple(
            Axis(name, kind, *(tuple(part) for part in levels.get(name, ([], []))))
            for name, kind in axes
        ),
        source or "experiment_axes",
    )
    if source == PAPER_SOURCE:
        return PAPER_DESIGN.with_added({a.name: a.added for a in design.axes})
    return design


def design_for(store, design: ExperimentDesign | None = None) -> ExperimentDesign:
    """The design a command on ``store`` uses: ``design`` when given (an override, with
    the levels code added to the stored design's axes of the same names), else the stored
    one (`stored_design`)."""
    stored = stored_design(store)
    if design is None:
        return stored
    return design.with_added({a.name: a.added for a in stored.axes})


def store_description(conn: sa.Connection, design: ExperimentDesign) -> None:
    """Store ``design`` as the database's experiment description, in the caller's
    transaction: its description row (once: a later ingest with the same axes keeps the
    first file's name) and the axes and levels not stored yet. `check_axes` has refused a
    different declaration of a stored axis before."""
    if is_paper(design):
        return
    conn.exec_driver_sql(
        "INSERT INTO experiment_description SELECT 1, ?, current_timestamp "
        "WHERE NOT EXISTS (SELECT 1 FROM experiment_description)",
        (design.source,),
    )
    _store_axes(conn, design)


def _store_axes(conn: sa.Connection, design: ExperimentDesign) -> None:
    have = {r[0] for r in conn.exec_driver_sql("SELECT axis FROM experiment_axes")}
    for a in design.axes:
        if a.name in have:
            continue
        conn.exec_driver_sql(
            "INSERT INTO experiment_axes SELECT ?, count(*), ?, ? FROM experiment_axes",
            (a.name, a.kind, levels_json(a)),
        )
        for i, level in enumerate(a.levels):
            conn.exec_driver_sql(
                "INSERT INTO experiment_levels (axis, level, position) VALUES (?, ?, ?)",
                (a.name, level, i),
            )


def levels_json(axis: Axis) -> str | None:
    """The declared levels as stored in ``experiment_axes.levels`` (JSON; None: numeric)."""
    return json.dumps(list(axis.levels)) if axis.levels else None


def store_values(conn: sa.Connection, trial_id: int, values) -> None:
    """Write trial ``trial_id``'s value along each axis (``(axis, value)`` pairs) into
    ``trial_conditions``, in the caller's transaction."""
    for name, value in values:
        number = float(value) if isinstance(value, float) else None
        text = f"{value:g}" if number is not None else str(value)
        conn.exec_driver_sql(
            "INSERT INTO trial_conditions VALUES (?, ?, ?, ?)", (trial_id, name, text, number)
        )


def add_trial_levels(
    store, trials: Mapping[int, str], added_by: str, axis: str | None = None
) -> ExperimentDesign:
    """Make trials added after the declaration conditions of the stored design.

    The one call for code that adds trials (the verify step of `gait design`, a planning
    loop), after they are ingested: each trial's ``level`` (e.g. the gait file's name)
    becomes a level of the stored design's condition ``axis`` (default: its one axis
    besides the frequency), recorded as added by ``added_by`` (stored in
    ``experiment_levels.added_by``); the trial's label must be that level (the name it was
    ingested with; a trial ingested without a condition gets it) and its values (the level
    and its frequency, when the frequency is an axis) are stored in ``trial_conditions``.
    A paper database gets the paper's design stored first, with its trials' values.
    Calling it again for the same trials changes nothing.

    Parameters
    ----------
    store : Store
    trials : mapping of int to str
        Trial id -> its level along ``axis``.
    added_by : str
        Who added them, e.g. ``"gait design 3"``.
    axis : str, optional
        Name of an ordered or unordered axis of the stored design.

    Returns
    -------
    ExperimentDesign
        The stored design with the new levels.

    Raises `IngestError` (one line, nothing written) for a design with several condition
    axes (a new trial's value along the others is unknown), an unknown or numeric
    ``axis``, a level name a label cannot hold, or an unknown trial.
    """
    with store.write() as conn:
        design = read_design(conn)
        target = trial_level_axis(design, axis)
        for trial_id, level in trials.items():
            problem = level_problem(level)
            if problem:
                raise IngestError(
                    f"trial {trial_id}: level {level!r} of axis {target.name!r}: {problem}",
                    param="trials",
                )
        found = {
            int(r[0]): (r[1], r[2])
            for r in conn.exec_driver_sql(
                "SELECT id, frequency_hz, gait FROM trials WHERE list_contains(?, id)",
                ([int(t) for t in trials],),
            ).fetchall()
        }
        missing = sorted(set(map(int, trials)) - set(found))
        if missing:
            raise IngestError(f"trials: no trial {missing[0]} in the database", param="trials")
        for trial_id, level in trials.items():
            label = found[int(trial_id)][1]
            # a label is what the trial was ingested as: never overwritten, so never lost
            if label is not None and label != level:
                raise IngestError(
                    f"trial {trial_id} is stored as {label!r}, not {level!r}; a trial's "
                    "level is the name it was ingested with",
                    param="trials",
                )
        described = conn.exec_driver_sql("SELECT count(*) FROM experiment_description")
        if not described.fetchone()[0]:
            _store_paper(conn)
        new = [lv for lv in dict.fromkeys(trials.values()) if lv not in target.all_levels]
        for level in new:
            conn.exec_driver_sql(
                "INSERT INTO experiment_levels SELECT ?, ?, "
                "coalesce(max(position) + 1, 0), ? FROM experiment_levels WHERE axis = ?",
                (target.name, level, added_by, target.name),
            )
        for trial_id, level in trials.items():
            trial_id = int(trial_id)
            # a trial ingested without a condition gets the level as its label
            conn.exec_driver_sql(
                "UPDATE trials SET gait = ? WHERE id = ? AND gait IS NULL", (level, trial_id)
            )
            # its values along the design: the same as any stored ones (same label and
            # frequency), so calling again rewrites them unchanged
            conn.exec_driver_sql("DELETE FROM trial_conditions WHERE trial_id = ?", (trial_id,))
            values = [(target.name, level)]
            if FREQUENCY_AXIS in design.names:
                values.append((FREQUENCY_AXIS, round(float(found[trial_id][0]), 6)))
            store_values(conn, trial_id, values)
        return read_design(conn)


def trial_level_axis(design: ExperimentDesign, axis: str | None = None) -> Axis:
    """The axis of ``design`` that `add_trial_levels` puts new levels on: ``axis`` or the
    design's one condition axis; `IngestError` when there is none such (code that adds
    trials checks this before it makes any)."""
    if axis is None:
        if len(design.label_axes) != 1:
            names = ", ".join(a.name for a in design.label_axes) or "none"
            raise IngestError(
                f"{design.source}: the design has {len(design.label_axes)} condition axes "
                f"besides the frequency ({names}); a new trial's values along them are "
                "unknown, so it cannot be one of its conditions"
            )
        return design.label_axes[0]
    target = design.axis(axis) if axis in design.names else None
    if target is None or target.kind == "numeric" or len(design.label_axes) != 1:
        raise IngestError(
            f"{design.source}: axis {axis!r}: expected the design's one ordered or "
            f"unordered condition axis ({', '.join(a.name for a in design.label_axes)})",
            param="axis",
        )
    return target


def _store_paper(conn: sa.Connection) -> None:
    """Store the paper's design as the description of a database ingested with the
    default design, with the values of its trials on the paper's gaits."""
    conn.exec_driver_sql(
        "INSERT INTO experiment_description VALUES (1, ?, current_timestamp)", (PAPER_SOURCE,)
    )
    _store_axes(conn, PAPER_DESIGN)
    gait = PAPER_DESIGN.axis("gait")
    for trial_id, label, hz in conn.exec_driver_sql(
        "SELECT id, gait, frequency_hz FROM trials WHERE list_contains(?, gait) ORDER BY id",
        (list(gait.levels),),
    ).fetchall():
        store_values(conn, int(trial_id), [("gait", label), (FREQUENCY_AXIS, round(hz, 6))])
