"""One `suds-exp run` per database: the database's write lock, held for the whole run.

The lock itself (`suds_exp.store.lock`, a cross-platform OS file lock the OS releases
however the process ends) is the one every writing command takes; a run waits only
`ACQUIRE_WAIT_S` for it, since campaigns are long and a second one should hear at once
that the database is taken.
"""

from __future__ import annotations

from pathlib import Path

from suds_exp.store.lock import WriteLock, holder

#: How long a new run waits for the lock before refusing, in s (covers a `status` probe).
ACQUIRE_WAIT_S = 1.0


def RunLock(db_path: Path, campaign: str) -> WriteLock:
    """The write lock of database ``db_path`` for a run of ``campaign`` (a context manager;
    a `StoreError` naming the holder when another writer keeps it past `ACQUIRE_WAIT_S`)."""
    return WriteLock(db_path, "run", campaign, ACQUIRE_WAIT_S)


def run_holder(db_path: Path) -> dict | None:
    """The {pid, host, campaign} of the run holding ``db_path``, or None when no run does
    (another command writing it is not a run)."""
    info = holder(Path(db_path))
    if info is None or (info and info.get("command") != "run"):
        return None
    return {"pid": info.get("pid"), "host": info.get("host"), "campaign": info.get("name")}
