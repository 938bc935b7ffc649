"""Engines for one DuckDB file, and the retry that lets readers wait out a writer.

DuckDB lets one process hold a file for writing, and while it does no other process can
open it at all. Every connection here is therefore short-lived (``NullPool``): the file
is held only inside a ``with store.write()`` / ``with store.read()`` block, and a
process that finds the file locked retries for a few seconds before giving up.
"""

from __future__ import annotations

import os
import re
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

import duckdb

from suds_exp.errors import StoreError
from suds_exp.store.integrity import check_file

DEFAULT_DB = "suds.duckdb"
#: On-disk format of new files: the newest one the released DuckDB CLI (`duckdb-cli`
#: 1.5) can read, so a stock `duckdb -readonly suds.duckdb` session opens our files.
#: A file keeps the format it was created with.
STORAGE_VERSION = "v1.4.0"
#: How long a process waits for another one to release the file, in seconds.
LOCK_WAIT_S = 15.0

T = TypeVar("T")

if TYPE_CHECKING:
    import sqlalchemy as sa


def default_db_path() -> Path:
    """The database path used when none is given: ``$SUDS_DB`` or ``./suds.duckdb``."""
    return Path(os.environ.get("SUDS_DB") or DEFAULT_DB)


def make_engine(path: Path, read_only: bool = False) -> sa.Engine:
    """A SQLAlchemy engine on the DuckDB file ``path`` that never pools connections."""
    import sqlalchemy as sa
    from sqlalchemy.pool import NullPool

    connect_args: dict = {"read_only": read_only}
    if not read_only:
        connect_args["config"] = {"storage_compatibility_version": STORAGE_VERSION}
    # the dialect named in full: a venv that still has duckdb-engine registers "duckdb" too
    url = f"duckdb+duckdb_sqlalchemy:///{path}"
    return sa.create_engine(url, poolclass=NullPool, connect_args=connect_args)


def is_lock_error(exc: BaseException) -> bool:
    """True when ``exc`` says another process holds the DuckDB file."""
    text = str(exc)
    return "Could not set lock" in text or "Conflicting lock" in text


_HOLDER = re.compile(r"Conflicting lock is held in (.+?) \(PID (\d+)\)")


def lock_holder(exc: BaseException) -> str:
    """The program and pid DuckDB names as holding its file in ``exc``'s text
    ("/usr/bin/python3.12, pid 4242"), or "owner unknown"."""
    m = _HOLDER.search(str(exc))
    return f"{m.group(1)}, pid {m.group(2)}" if m else "owner unknown"


#: DuckDB's words for a file it cannot use -> what to tell the user (after the path).
_OPEN_PROBLEMS = (
    ("not a valid DuckDB database file", "not a DuckDB database file"),
    (
        "Could not read enough bytes",
        "the database file is truncated or damaged (shorter than its own header says); "
        "restore it from a copy",
    ),
    ("Permission denied", "permission denied: cannot create or write the database there"),
    ("No such file or directory", "cannot create the database: no such folder"),
    ("Read-only file system", "cannot create or write the database on a read-only file system"),
    ("No space left", "no space left on the device; nothing was written"),
    (
        "Corrupt database file",
        "the database file is damaged (a block fails its checksum); restore it from a copy",
    ),
)


def open_problem(exc: BaseException, path: Path) -> StoreError | None:
    """The one-line `StoreError` for a database file DuckDB cannot open or create
    (``exc`` an I/O error from DuckDB, or an `OSError` creating its folder); None for
    any other error, which is left to surface as it is."""
    orig = getattr(exc, "orig", exc)
    if isinstance(orig, OSError):
        reason = orig.strerror or str(orig)
        return StoreError(f"{path}: cannot create the database's folder: {reason.lower()}")
    if not isinstance(orig, duckdb.IOException):
        return None
    text = str(orig)
    for needle, message in _OPEN_PROBLEMS:
        if needle in text:
            return StoreError(f"{path}: {message}")
    return StoreError(f"{path}: cannot open the database: {text.splitlines()[0]}")


def _open_errors() -> tuple[type[BaseException], ...]:
    # SQLAlchemy wraps DuckDB's errors when a `Store` opens the file; a plain DuckDB
    # connection (`suds_exp.store.rows`) raises them bare, and never loads SQLAlchemy
    sa = sys.modules.get("sqlalchemy")
    return (duckdb.IOException,) if sa is None else (duckdb.IOException, sa.exc.DBAPIError)


def retry_on_lock(open_fn: Callable[[], T], path: Path, wait_s: float = LOCK_WAIT_S) -> T:
    """Call ``open_fn`` until it stops failing on a file lock, for at most ``wait_s`` s.

    A file DuckDB cannot open for another reason (not a database, truncated, a folder
    that cannot be written) raises a one-line `StoreError` naming it."""
    check_file(path)
    deadline = time.monotonic() + wait_s
    delay = 0.02
    while True:
        try:
            return open_fn()
        except _open_errors() as exc:
            if not is_lock_error(exc):
                problem = open_problem(exc, path)
                if problem is None:
                    raise
                raise problem from None
            if time.monotonic() >= deadline:
                raise StoreError(
                    f"{path}: the database is held by another process ({lock_holder(exc)}); "
                    f"waited {wait_s:g} s. Try again when it finishes."
                ) from None
            time.sleep(delay)
            delay = min(delay * 2, 0.5)
