"""Names of discrepancy runs: the default, a free one, and the check that a name and a
report folder are not a stored run's already."""

from __future__ import annotations

import datetime as _dt
from pathlib import Path

import sqlalchemy as sa

from suds_exp.errors import DiscrepancyError


def default_name(when: _dt.datetime | None = None) -> str:
    """A run's default name, ``discrepancy-<YYYYmmdd-HHMMSS>`` of ``when`` (default: now)."""
    return f"discrepancy-{(when or _dt.datetime.now()):%Y%m%d-%H%M%S}"


def stored_names(store) -> set[str]:
    """The names of the discrepancy runs stored in ``store`` (empty for a new file)."""
    if not store.path.exists():
        return set()
    with store.read() as conn:
        if not sa.inspect(conn).has_table("discrepancy_runs"):
            return set()
        return set(conn.execute(sa.text("SELECT name FROM discrepancy_runs")).scalars())


def free_name(store, base: str) -> str:
    """``base``, or ``base-2``, ``base-3``, ... when a stored run has it: two unnamed runs
    started within the same second get names of their own."""
    taken = stored_names(store)
    candidates = (base, *(f"{base}-{k}" for k in range(2, len(taken) + 3)))
    return next(n for n in candidates if n not in taken)


def check_free(store, name: str, out: str | Path | None) -> None:
    """Raise `DiscrepancyError` when ``name`` or the report folder ``out`` belongs to a
    stored run already."""
    if not store.path.exists():
        return
    with store.read() as conn:
        if not sa.inspect(conn).has_table("discrepancy_runs"):
            return
        rows = conn.execute(sa.text("SELECT id, name, report_dir FROM discrepancy_runs")).fetchall()
    for run_id, other, folder in rows:
        if other == name:
            raise DiscrepancyError(
                f"name {name!r}: discrepancy run {run_id} already has that name; choose "
                "another name",
                param="name",
            )
        if out is not None and folder and Path(folder).resolve() == Path(out).resolve():
            raise DiscrepancyError(
                f"out {out}: the report folder of discrepancy run {run_id} ({other!r}); "
                "choose another folder",
                param="out",
            )
