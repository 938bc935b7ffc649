"""One writer at a time per database: an OS file lock beside it, held for a whole command.

Every writing step (init, ingest, preprocess, run, stream, discrepancy) holds the write
lock of its database from the moment it reads what it will build on until its last
row is stored, so "is this version / stream / run already there?" and "create it" cannot
interleave with another process doing the same. `Store.write` takes the lock too, so a
writer that forgot to cannot slip in between; inside one process the lock is re-entrant.

The lock is `filelock.FileLock` on ``<db>.lock`` (fcntl on POSIX, msvcrt on Windows): the
OS releases it when the process ends however it ends (Ctrl-C, crash, kill -9), so a
stale lock never blocks the next command. Who holds it (command, name, pid, host) is kept
in ``<db>.lock.json`` for the refusal message; the holder removes it before it lets go,
and one left by a killed holder is only read while the lock is taken by another.
"""

from __future__ import annotations

import json
import os
import socket
import threading
import time
from pathlib import Path

from filelock import FileLock, Timeout

from suds_exp.errors import StoreError
from suds_exp.store.integrity import check_file

#: How long a writer waits for another one to finish before refusing, in s.
WRITE_WAIT_S = 15.0

#: Commands that only write inside another one's lock: re-entrant under any holder.
_INNER = ("write", "init")

_held: dict[Path, tuple[FileLock, int, dict]] = {}
_guard = threading.Lock()


def lock_path(db_path: Path) -> Path:
    """The lock file of the database ``db_path``: ``<db>.lock`` beside it."""
    db_path = Path(db_path)
    return db_path.with_name(db_path.name + ".lock")


def _info_path(db_path: Path) -> Path:
    return lock_path(db_path).with_suffix(".lock.json")


class WriteLock:
    """Exclusive write access to a database for one command (a context manager).

    Parameters
    ----------
    db_path : path
        The database file.
    command : str
        The `suds-exp` command (``"run"``, ``"preprocess"``...) named in a refusal.
    name : str, optional
        The campaign, stream, version or run it writes, named in a refusal.
    wait_s : float, optional
        How long to wait for another writer before raising `StoreError` (default
        `WRITE_WAIT_S`).

    Entered again in a process that holds it, it is a no-op (the outer holder stays)
    for the same command and name, and for a plain write (``command`` "write" or "init");
    another command is refused as if the holder were another process.
    """

    def __init__(self, db_path, command: str, name: str | None = None, wait_s=None):
        self.db = Path(db_path)
        self.key = self.db.resolve()
        self.command, self.name = command, name
        self.wait_s = WRITE_WAIT_S if wait_s is None else wait_s

    def __enter__(self) -> WriteLock:
        with _guard:
            if self.key in _held:
                lock, depth, info = _held[self.key]
                same = (info["command"], info["name"]) == (self.command, self.name)
                if not (same or self.command in _INNER):
                    raise StoreError(
                        f"{self.db}: {describe_holder(info)} is writing to this database; "
                        "wait for it to finish, then try again"
                    )
                _held[self.key] = (lock, depth + 1, info)
                return self
        check_file(self.db)  # a damaged database is refused before a lock file is made
        path = lock_path(self.db)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            lock = FileLock(path)
            lock.acquire(timeout=self.wait_s, poll_interval=0.05)
        except Timeout:
            raise StoreError(
                f"{self.db}: {describe_holder(holder(self.db, probe=False))} is writing to this "
                f"database; waited {self.wait_s:g} s; wait for it to finish or stop it "
                "(Ctrl-C), then try again"
            ) from None
        except OSError as exc:
            raise StoreError(
                f"{path}: cannot create the database's lock file: "
                f"{(exc.strerror or str(exc)).lower()}"
            ) from None
        info = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "command": self.command,
            "name": self.name,
        }
        _write_info(_info_path(self.db), info)
        with _guard:
            _held[self.key] = (lock, 1, info)
        return self

    def __exit__(self, *exc) -> None:
        with _guard:
            lock, depth, info = _held[self.key]
            if depth > 1:
                _held[self.key] = (lock, depth - 1, info)
                return
            del _held[self.key]
        try:
            _info_path(self.db).unlink()
        except OSError:
            pass
        lock.release()


def holds(db_path) -> bool:
    """True when this process holds the write lock of ``db_path``."""
    with _guard:
        return Path(db_path).resolve() in _held


def holder(db_path, probe: bool = True) -> dict | None:
    """The {pid, host, command, name} of the process writing ``db_path``, or None when
    none does (``probe``: check the lock itself; False: it is known to be taken)."""
    db_path = Path(db_path)
    if probe:
        path = lock_path(db_path)
        if not path.exists() or holds(db_path):
            return None
        lock = FileLock(path)
        try:
            lock.acquire(timeout=0)
        except Timeout:
            pass
        except OSError:
            return None
        else:
            lock.release()
            return None
    # the holder writes its card right after taking the lock: give it a moment
    for _ in range(20):
        try:
            info = json.loads(_info_path(db_path).read_text() or "{}")
        except (OSError, ValueError):
            info = {}
        if info:
            return info
        time.sleep(0.01)
    return {}


def describe_holder(info: dict | None) -> str:
    """``info`` of `holder` as words: "run 'paper' (pid 12 on h)" (the step that holds
    the lock, as `run_campaign` or `suds-exp run`, and what it works on)."""
    if not info:
        return "another process (owner unknown)"
    what = f"{info.get('command')}"
    if info.get("name"):
        what += f" {info['name']!r}"
    return f"{what} (pid {info.get('pid')} on {info.get('host')})"


def _write_info(path: Path, info: dict) -> None:
    # a new file renamed over the old one, so a reader never sees half of it
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(json.dumps(info))
        os.replace(tmp, path)
    except OSError:
        pass
