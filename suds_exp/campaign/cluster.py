"""A campaign's tasks on a dask.distributed cluster: a user's over TCP (``scheduler``) or a
local one this process starts.

The client submits its tasks to the scheduler itself (joblib's dask backend runs every
task in the calling process when the cluster has a single thread), a few tasks a worker
thread at a time, each holding about `DASK_TASK_SECONDS` of jobs (`TaskSizer`). The
sample bank is scattered to every worker once. A worker that dies takes its task with it
and the scheduler runs that task again on another (the rows are the same: seeds come
from each job's key); a lost scheduler is one line (`cluster_lost`, then
`ClusterLostError` in `execute`).
"""

from __future__ import annotations

import asyncio
import contextlib
import importlib
import itertools
import logging
import math
import socket
import threading
import time
from collections.abc import Iterator

from suds_exp.campaign.job import run_chunk
from suds_exp.campaign.signals import sigint_blocked
from suds_exp.errors import CampaignError

#: How long to wait for a dask scheduler to answer before refusing the run, in s.
SCHEDULER_WAIT_S = 5.0
#: On dask, a task holds about this many seconds of jobs (their fit + predict time, from
#: the rows of the tasks finished so far; the first tasks are one draw each) ...
DASK_TASK_SECONDS = 1.0
#: ... at most the jobs pending at the start / (worker threads x this) ...
DASK_TASKS_PER_THREAD = 8
#: ... and at most the jobs not yet sent / (worker threads x this), so the last tasks
#: shrink to a draw each and the workers finish together.
DASK_TASKS_AT_END = 2
#: How often the dask path asks the scheduler how many worker threads there are, in s.
THREADS_POLL_S = 5.0


def check_scheduler(address: str, wait_s: float = SCHEDULER_WAIT_S) -> None:
    """Raise `CampaignError` when nothing answers at the dask scheduler ``address``
    (``tcp://host:port``) within ``wait_s`` s, before a campaign is created or continued."""
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    host, colon, port = rest.rpartition(":")
    if scheme not in ("tcp", "tls") or not colon or not port.isdigit():
        raise CampaignError(
            f"scheduler {address!r}: expected tcp://HOST:PORT, e.g. tcp://127.0.0.1:8786",
            param="scheduler",
        )
    try:
        socket.create_connection((host.strip("[]") or "127.0.0.1", int(port)), wait_s).close()
    except OSError as exc:
        reason = (exc.strerror or str(exc) or type(exc).__name__).lower()
        raise CampaignError(
            f"scheduler {address}: no dask scheduler answers there ({reason}); start one "
            "with `dask scheduler` or leave scheduler out for a local cluster",
            param="scheduler",
        ) from None


def import_in_background() -> None:
    """Start importing dask.distributed in a daemon thread.

    The import takes ~0.4 s of CPU; the campaign's own start (opening the database a few
    times, loading the samples, planning) waits on the file for about as long, so a run
    on a cluster starts its first tasks that much sooner. An import that fails here fails
    again, with its own message, where `dask_client` imports the same module."""

    def load() -> None:
        with contextlib.suppress(Exception):
            importlib.import_module("dask.distributed")

    threading.Thread(target=load, name="suds-import-distributed", daemon=True).start()


def dask_client(scheduler: str | None, n_workers: int, stack: contextlib.ExitStack):
    """A dask.distributed client of the cluster at ``scheduler``, or of a local cluster of
    ``n_workers`` one-thread worker processes; both closed with ``stack``."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        # a lost scheduler is one line (`ClusterLostError`), not the client's logged
        # reconnect tracebacks, nor tornado's of a result being gathered then (a
        # callback of the client's loop: 45 lines, seen in the cluster test)
        stack.enter_context(quiet_logger("distributed"))
        stack.enter_context(quiet_logger("tornado"))
        return stack.enter_context(Client(scheduler, timeout=SCHEDULER_WAIT_S))
    with sigint_blocked():
        cluster = LocalCluster(
            n_workers=n_workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            # workers ignore Ctrl-C: this process stops the run (dask_worker.py)
            preload=["suds_exp.campaign.dask_worker"],
            # closing busy workers is not worth a warning on the terminal
            silence_logs=logging.ERROR,
        )
    stack.enter_context(cluster)
    return stack.enter_context(Client(cluster))


def cluster_threads(client) -> int:
    """Worker threads of ``client``'s cluster now (at least 1: workers may join later)."""
    return max(1, sum(client.nthreads().values()))


class TaskSizer:
    """Jobs per dask task: `DASK_TASK_SECONDS` of fit + predict time at the mean job time
    seen so far, at most the jobs pending at the start / (threads x
    `DASK_TASKS_PER_THREAD`) and the jobs not yet sent / (threads x `DASK_TASKS_AT_END`);
    ``fixed`` (``chunk_jobs``) overrides them all.

    Each task costs the scheduler and this process 5-7 ms of CPU time (measured under
    load: 224 tasks fewer for the same 1,200 jobs saved 1.1-1.6 s), time the workers
    lose on a machine whose cores they fill: 2-3 % of a task of 0.25 s, under 1 % of one
    of a second. A job of a five-cycle campaign takes ~12 ms, so a task holds tens of
    draws. The last tasks shrink, so both ends of the run stay even (draws with the most
    cycles come first); the work a killed worker takes with it stays small, and a Ctrl-C
    waits at most about a second for a stopping local worker's task."""

    def __init__(self, pending: int, threads: int, fixed: int | None = None):
        self.fixed = fixed
        self.cap = max(1, math.ceil(pending / (threads * DASK_TASKS_PER_THREAD)))
        self.threads = threads
        self.unsent = pending
        self.jobs = 0
        self.seconds = 0.0

    def seen(self, rows: list[dict]) -> None:
        self.jobs += len(rows)
        self.seconds += sum(r["fit_seconds"] + r["predict_seconds"] for r in rows)

    def sent(self, jobs: int) -> None:
        self.unsent -= jobs

    def size(self) -> int:
        if self.fixed:
            return self.fixed
        if not self.jobs or self.seconds <= 0:
            return 1  # one draw: its learners stay together
        timed = DASK_TASK_SECONDS * self.jobs / self.seconds
        ending = self.unsent / (self.threads * DASK_TASKS_AT_END)
        return int(max(1, min(self.cap, timed, ending)))


def regroup(chunks, sizer: TaskSizer) -> Iterator[list]:
    """The draws of ``chunks`` in chunks of about ``sizer.size()`` jobs, a draw's learners
    together (the size read as each task is made)."""
    current: list = []
    n = 0
    for chunk in chunks:
        current.extend(chunk)
        n += sum(len(names) for _, names in chunk)
        if n >= sizer.size():
            sizer.sent(n)
            yield current
            current, n = [], 0
    if current:
        sizer.sent(n)
        yield current


def dask_rows(client, bank, chunks, args, pending: int, chunk_jobs, stack: contextlib.ExitStack):
    """Rows of the draws of ``chunks`` (one draw a chunk, regrouped into tasks by a
    `TaskSizer` of ``pending`` jobs) as each task finishes on ``client``'s cluster.

    The first tasks (two a worker thread) are on the cluster when this returns; the rest
    are sent as results come back, two tasks a thread at a time, so the chunks of a large
    campaign are built as they are sent. ``args``: the models and test cycles of
    `run_chunk`; ``chunk_jobs`` fixes the jobs a task.
    """
    from dask.distributed import as_completed

    sizer = TaskSizer(pending, cluster_threads(client), chunk_jobs)
    tasks = regroup(chunks, sizer)
    shared = client.scatter(bank, broadcast=True, hash=False)
    running = as_completed()

    def cancel() -> None:
        if client.status == "running":
            with contextlib.suppress(Exception):
                client.cancel(list(running.futures), asynchronous=False)

    stack.callback(cancel)

    def submit(n: int) -> None:
        for chunk in itertools.islice(tasks, max(0, n)):
            running.add(client.submit(run_chunk, shared, chunk, *args, blas="block", pure=False))

    submit(2 * sizer.threads)

    def rows() -> Iterator[list[dict]]:
        check = time.monotonic() + THREADS_POLL_S
        for future in running:
            result = future.result()
            future.release()
            sizer.seen(result)
            if time.monotonic() >= check:  # workers that joined since the start get work too
                sizer.threads, check = cluster_threads(client), time.monotonic() + THREADS_POLL_S
            submit(2 * sizer.threads - running.count())
            yield result

    return rows()


@contextlib.contextmanager
def quiet_logger(name: str) -> Iterator[None]:
    """Only critical records of logger ``name`` and its children (dask's config gives some
    of them levels of their own) while inside."""
    names = [name] + [n for n in logging.root.manager.loggerDict if n.startswith(name + ".")]
    loggers = [logging.getLogger(n) for n in names]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for lg, level in zip(loggers, levels, strict=True):
            lg.setLevel(level)


def cluster_lost(exc: BaseException) -> bool:
    """True for what a dask client raises when its scheduler or the connection to it goes
    away mid-run (a closed comm, cancelled futures, a reconnect that timed out)."""
    from concurrent.futures import CancelledError

    from distributed.comm.core import CommClosedError

    return isinstance(exc, CommClosedError | CancelledError | asyncio.CancelledError | TimeoutError)
