"""Trials recorded by code (a planning loop), kept with the data (``trials_added``,
migration 024), so that later steps know them from the data layer alone."""

from __future__ import annotations

from collections.abc import Iterable


def mark_trials_added(store, trial_ids: Iterable[int], added_by: str) -> None:
    """Record that code (``added_by``, e.g. ``"plan loop NAME"``) recorded the ingested
    trials ``trial_ids``; a trial marked before keeps its first mark."""
    ids = sorted({int(t) for t in trial_ids})
    if not ids:
        return
    with store.write() as conn:
        for trial_id in ids:
            conn.exec_driver_sql(
                "INSERT INTO trials_added SELECT ?, ? "
                "WHERE NOT EXISTS (SELECT 1 FROM trials_added WHERE trial_id = ?)",
                (trial_id, added_by, trial_id),
            )


def added_conditions(store) -> frozenset[tuple[str, float]]:
    """The (gait label, frequency_hz rounded to 6 digits) conditions every trial of which
    code recorded (``trials_added``); empty for a database without such trials."""
    from suds_exp.store.rows import read_connection

    with read_connection(store.path) as conn:
        tables = {r[0] for r in conn.execute("SELECT table_name FROM duckdb_tables()").fetchall()}
        if "trials_added" not in tables:  # a database older than migration 024
            return frozenset()
        rows = conn.execute(
            "SELECT t.gait, round(t.frequency_hz, 6) FROM trials AS t "
            "LEFT JOIN trials_added AS a ON a.trial_id = t.id "
            "WHERE t.gait IS NOT NULL AND t.frequency_hz IS NOT NULL "
            "GROUP BY t.gait, round(t.frequency_hz, 6) "
            "HAVING bool_and(a.trial_id IS NOT NULL)"
        ).fetchall()
    return frozenset((str(g), round(float(f), 6)) for g, f in rows)
