"""Ctrl-C and SIGTERM during a campaign: served between writes, never inside one, and kept
from the worker processes the run starts (this process stops the run and its workers)."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator


class Signals:
    """Turn SIGINT/SIGTERM into KeyboardInterrupt, but never in the middle of a write."""

    def __init__(self):
        self.critical = False
        self.pending = False
        self._old: dict = {}

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._old[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc):
        for sig, old in self._old.items():
            signal.signal(sig, old)

    def _handle(self, signum, frame):
        if self.critical:
            self.pending = True
            return
        raise KeyboardInterrupt

    @contextlib.contextmanager
    def shielded(self) -> Iterator[None]:
        self.critical = True
        try:
            yield
        finally:
            self.critical = False
        if self.pending:
            self.pending = False
            raise KeyboardInterrupt


@contextlib.contextmanager
def closed_shielded(signals: Signals) -> Iterator[contextlib.ExitStack]:
    """An exit stack closed with Ctrl-C held back: stopping a cluster's client and workers
    takes seconds on a loaded machine, and a Ctrl-C pressed again meanwhile would leave
    them to the interpreter's exit, which prints its own traceback."""
    stack = contextlib.ExitStack()
    try:
        yield stack
    finally:
        with signals.shielded():
            stack.close()


@contextlib.contextmanager
def sigint_blocked() -> Iterator[None]:
    """Worker processes started inside the block ignore SIGINT for their whole life.

    A terminal's Ctrl-C reaches the whole process group; only this process should act on
    it (it stops the run and its workers). A worker hit while it starts prints a
    traceback (and a dask cluster then fails to start), so workers are started while
    SIGINT is ignored, which a new process inherits (a blocked mask it does not: Python's
    process spawning resets it). This thread blocks SIGINT meanwhile, so a Ctrl-C that
    lands on it is served when the block ends; one that the kernel hands to another
    thread in that moment (a BLAS thread) is lost, and the user presses Ctrl-C again.
    """
    if not hasattr(signal, "pthread_sigmask") or (
        threading.current_thread() is not threading.main_thread()
    ):
        yield
        return
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler if old is None else old)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
