"""One `suds-exp run` per database: an OS advisory lock on a file beside it.

`fcntl.flock` locks belong to the open file, so the OS releases them when the process
ends however it ends (Ctrl-C, crash, kill -9): a stale lock cannot block the next run.
The file holds the owner's pid, host and campaign for the refusal message.
"""

from __future__ import annotations

import fcntl
import json
import os
import socket
import time
from pathlib import Path

from suds_exp.errors import CampaignError

#: How long a new run waits for the lock before refusing, in s (covers a `status` probe).
ACQUIRE_WAIT_S = 1.0


def lock_path(db_path: Path) -> Path:
    """The lock file of the database ``db_path``: ``<db>.run.lock`` beside it."""
    return db_path.with_name(db_path.name + ".run.lock")


class RunLock:
    """Exclusive lock of a database for one campaign run (a context manager)."""

    def __init__(self, db_path: Path, campaign: str):
        self.db = Path(db_path)
        self.path = lock_path(self.db)
        self.campaign = campaign
        self._fd: int | None = None

    def __enter__(self) -> RunLock:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        deadline = time.monotonic() + ACQUIRE_WAIT_S
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() >= deadline:
                    holder = _describe(_read(fd))
                    os.close(fd)
                    raise CampaignError(
                        f"{self.db}: another `suds-exp run` "
                        f"is using this database ({holder}); wait for it to finish or stop it "
                        "with Ctrl-C, then run again (finished jobs are kept)"
                    ) from None
                time.sleep(0.05)
        info = {"pid": os.getpid(), "host": socket.gethostname(), "campaign": self.campaign}
        os.ftruncate(fd, 0)
        os.pwrite(fd, json.dumps(info).encode(), 0)
        self._fd = fd
        return self

    def __exit__(self, *exc) -> None:
        if self._fd is not None:
            os.ftruncate(self._fd, 0)
            fcntl.flock(self._fd, fcntl.LOCK_UN)
            os.close(self._fd)
            self._fd = None


def run_holder(db_path: Path) -> dict | None:
    """The {pid, host, campaign} of the run holding ``db_path``, or None when none does."""
    path = lock_path(Path(db_path))
    if not path.exists():
        return None
    fd = os.open(path, os.O_RDONLY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return _read(fd) or {"pid": None, "host": None, "campaign": None}
        fcntl.flock(fd, fcntl.LOCK_UN)
        return None
    finally:
        os.close(fd)


def _read(fd: int) -> dict:
    try:
        return json.loads(os.pread(fd, 4096, 0).decode() or "{}")
    except (OSError, ValueError):
        return {}


def _describe(info: dict) -> str:
    if not info:
        return "owner unknown"
    return f"pid {info.get('pid')} on {info.get('host')}, campaign {info.get('campaign')!r}"
