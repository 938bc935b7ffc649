"""Engines for one DuckDB file, and the retry that lets readers wait out a writer.

DuckDB lets one process hold a file for writing, and while it does no other process can
open it at all. Every connection here is therefore short-lived (``NullPool``): the file
is held only inside a ``with store.write()`` / ``with store.read()`` block, and a
process that finds the file locked retries for a few seconds before giving up.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import duckdb
import sqlalchemy as sa
from sqlalchemy.pool import NullPool

from suds_exp.errors import StoreError

DEFAULT_DB = "suds.duckdb"
#: On-disk format of new files: the newest one the released DuckDB CLI (`duckdb-cli`
#: 1.5) can read, so a stock `duckdb -readonly suds.duckdb` session opens our files.
#: A file keeps the format it was created with.
STORAGE_VERSION = "v1.4.0"
#: How long a process waits for another one to release the file, in seconds.
LOCK_WAIT_S = 15.0

T = TypeVar("T")


def default_db_path() -> Path:
    """The database path used when none is given: ``$SUDS_DB`` or ``./suds.duckdb``."""
    return Path(os.environ.get("SUDS_DB") or DEFAULT_DB)


def make_engine(path: Path, read_only: bool = False) -> sa.Engine:
    """A SQLAlchemy engine on the DuckDB file ``path`` that never pools connections."""
    connect_args: dict = {"read_only": read_only}
    if not read_only:
        connect_args["config"] = {"storage_compatibility_version": STORAGE_VERSION}
    return sa.create_engine(f"duckdb:///{path}", poolclass=NullPool, connect_args=connect_args)


def is_lock_error(exc: BaseException) -> bool:
    """True when ``exc`` says another process holds the DuckDB file."""
    text = str(exc)
    return "Could not set lock" in text or "Conflicting lock" in text


def retry_on_lock(open_fn: Callable[[], T], path: Path, wait_s: float = LOCK_WAIT_S) -> T:
    """Call ``open_fn`` until it stops failing on a file lock, for at most ``wait_s`` s."""
    deadline = time.monotonic() + wait_s
    delay = 0.02
    while True:
        try:
            return open_fn()
        except (duckdb.IOException, sa.exc.DBAPIError) as exc:
            if not is_lock_error(exc):
                raise
            if time.monotonic() >= deadline:
                holder = str(exc).split("Conflicting lock is held in", 1)[-1].split(".")[0]
                raise StoreError(
                    f"{path}: the database is held by another process ({holder.strip()}); "
                    f"waited {wait_s:g} s. Try again when it finishes."
                ) from None
            time.sleep(delay)
            delay = min(delay * 2, 0.5)
