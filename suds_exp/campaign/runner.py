"""`run_campaign`: create or continue a campaign and fill its `results` rows.

The parent process loads the samples once, builds the `SampleBank`, works out which jobs
are not finished yet, and hands chunks of draws to workers (loky processes on this machine
through joblib, or the threads of a dask.distributed cluster, a few tasks a thread).
Finished rows come back to the parent, which writes them in batches, each batch in one
transaction, holding the database file only while it writes, so `suds-exp status`,
`suds-exp sql` and `duckdb -readonly` can read in between. A file lock beside the
database keeps a second run out.

Stopping: Ctrl-C (or SIGTERM) stops after writing every row already received; a signal
that arrives while a batch is being written is served after the write, so a batch is
never written twice. `kill -9` loses at most the rows not yet written; DuckDB's
write-ahead log makes each batch all-or-nothing.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import itertools
import json
import logging
import math
import os
import shutil
import signal
import socket
import tempfile
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd
from threadpoolctl import threadpool_limits

from suds_exp.campaign import tables
from suds_exp.campaign.bank import SampleBank, rounded_conditions
from suds_exp.campaign.definition import (
    CampaignOptions,
    Plan,
    make_plan,
    merge_stored,
    normalise,
    skipped_cells_text,
)
from suds_exp.campaign.job import RESULT_COLUMNS, run_chunk
from suds_exp.campaign.lock import RunLock
from suds_exp.campaign.resume import load_stored_definition, max_cycles, pending_jobs
from suds_exp.campaign.sampling import check_feasible
from suds_exp.display import Summary
from suds_exp.errors import CampaignError, ClusterLostError, StoreError
from suds_exp.ingest import stored_design
from suds_exp.ingest.added import added_conditions
from suds_exp.progress import progress_bar
from suds_exp.store import Store
from suds_exp.store.definition import check_same

BACKENDS = ("loky", "dask")
#: A batch is written when it holds this many rows ...
BATCH_ROWS = 1000
#: ... or when this many seconds passed since the last write, whichever comes first.
#: A write costs ~0.05 CPU s whatever its size (opening, committing and closing the
#: file); every 10 s that is 0.5 % of one core, and `kill -9` loses 10 s of work at most.
FLUSH_SECONDS = 10.0
#: How long to wait for a dask scheduler to answer before refusing the run, in s.
SCHEDULER_WAIT_S = 5.0
#: On dask, a task holds about this many seconds of jobs (their fit + predict time, from
#: the rows of the tasks finished so far; the first tasks are one draw each) ...
DASK_TASK_SECONDS = 0.25
#: ... and at most the jobs left / (worker threads x this), so the run's end stays even.
DASK_TASKS_PER_THREAD = 8


@dataclass(repr=False)
class RunSummary(Summary):
    """What a call of `run_campaign` did; shown (repr, notebook) with the campaign's jobs
    done and its best learner so far (lowest median RMSE of vx, read from ``db``)."""

    campaign: str
    total_jobs: int
    done_before: int
    done_now: int = 0
    failed_now: int = 0
    interrupted: bool = False
    seconds: float = 0.0
    batches: int = 0
    flush_seconds: float = 0.0
    created: bool = False
    extra: dict = field(default_factory=dict)
    db: Path | None = None

    def _summary(self):
        done = self.total_jobs - self.remaining
        fields = [
            ("jobs done", f"{done} / {self.total_jobs}"),
            ("this run", f"{self.done_now} jobs in {self.seconds:.1f} s"),
        ]
        if self.failed_now:
            fields.append(("failed", self.failed_now))
        if self.interrupted:
            fields.append(("stopped", "run again to continue"))
        best = best_learner(self.db, self.campaign) if self.db is not None else None
        if best is not None:
            fields.append(("best learner", f"{best[0]} (median RMSE vx {best[1]:.3g} mm/s)"))
        return f"campaign {self.campaign}", fields

    @property
    def remaining(self) -> int:
        return self.total_jobs - self.done_before - self.done_now

    def message(self) -> str:
        """One line for the terminal."""
        head = f"campaign {self.campaign!r}: " + ("created; " if self.created else "")
        if self.done_now == 0 and self.remaining == 0 and not self.interrupted:
            return head + f"all {self.total_jobs} jobs were already done"
        text = head + f"{self.done_now} jobs run in {self.seconds:.1f} s"
        if self.failed_now:
            text += f" ({self.failed_now} failed: see results.error)"
        text += f"; {self.total_jobs - self.remaining} / {self.total_jobs} done"
        if self.interrupted:
            text += "; stopped - run the same command again to continue"
        if self.extra.get("skipped_cells"):
            text += "; left out: " + skipped_cells_text(self.extra)
        return text

    def to_dict(self) -> dict:
        return {
            "campaign": self.campaign,
            "created": self.created,
            "total_jobs": self.total_jobs,
            "done_before": self.done_before,
            "done_now": self.done_now,
            "failed_now": self.failed_now,
            "remaining": self.remaining,
            "interrupted": self.interrupted,
            "seconds": self.seconds,
            "skipped_cells": self.extra.get("skipped_cells", []),
        }


def best_learner(db: Path, campaign: str) -> tuple[str, float] | None:
    """The learner of ``campaign`` with the lowest median RMSE of vx (mm/s) over its
    finished jobs, and that median; None before any job (or when the file is busy)."""
    from suds_exp.store.rows import read_rows

    try:
        rows = read_rows(
            db,
            "SELECT model, median(rmse_vx) AS m FROM results WHERE campaign = ? "
            "AND error IS NULL GROUP BY model ORDER BY m NULLS LAST LIMIT 1",
            [campaign],
        )
    except Exception:  # a display never raises: the line is left out
        return None
    if not rows.rows or rows.rows[0][1] is None:
        return None
    return rows.rows[0][0], float(rows.rows[0][1])


def run_campaign(
    store: Store,
    name: str,
    options: CampaignOptions | None = None,
    *,
    samples: pd.DataFrame | None = None,
    jobs: int = 1,
    backend: str = "loky",
    scheduler: str | None = None,
    chunk_jobs: int | None = None,
    batch_rows: int = BATCH_ROWS,
    flush_seconds: float = FLUSH_SECONDS,
    progress: bool = True,
    on_batch=None,
) -> RunSummary:
    """Create campaign ``name`` or continue it, and run its unfinished jobs.

    Parameters
    ----------
    store : Store
    name : str
        Campaign name (the `campaign` column of `results`).
    options : CampaignOptions, optional
        None fields take the stored value (continuing) or the default (creating).
    samples : DataFrame, optional
        A samples frame (columns of `samples` plus `gait`, `frequency_hz`) to use instead
        of ``load_samples(store, options.prep)``; ``options.prep`` then only labels it.
    jobs : int
        loky: worker processes (-1: one per core; 1 runs in this process). dask: every
        thread of the cluster is used; ``jobs`` only sizes the local cluster started
        when no ``scheduler`` is given.
    backend : {"loky", "dask"}
    scheduler : str, optional
        dask scheduler address (``tcp://host:8786``); None with dask starts a local
        cluster of ``jobs`` single-threaded workers.
    chunk_jobs : int, optional
        Jobs per task sent to a worker (default: loky, enough for ~30 tasks per worker,
        1-32; dask, `DASK_TASK_SECONDS` of work a task, see `DASK_TASKS_PER_THREAD`).
    batch_rows, flush_seconds : int, float
        Write finished rows when this many are waiting or this long after the last write.
    progress : bool
        Draw a progress bar with rate and ETA on stderr.
    on_batch : callable, optional
        Called with the number of rows after each write (tests, notebooks).

    Returns
    -------
    RunSummary
    """
    check_backend(backend, scheduler, jobs)
    if scheduler:
        check_scheduler(scheduler)
    options = options or CampaignOptions()
    started = time.perf_counter()
    with RunLock(store.path, name):
        store.upgrade()
        stored = load_stored_definition(store, name)
        merged = merge_stored(options, stored)
        prep, samples = campaign_samples(store, merged.prep, samples)
        plan, bank = plan_campaign(
            name,
            dataclasses.replace(merged, prep=prep),
            stored,
            samples,
            stored_design(store).added_labels | added_conditions(store),
        )
        n_workers = _n_workers(jobs)
        # dask: one draw a chunk here, grouped into tasks once the cluster's size is known
        chunks, total, pending = pending_jobs(
            store,
            plan,
            chunk_jobs or (1 if backend == "dask" else _default_chunk(plan, n_workers)),
        )
        if total == 0:
            raise CampaignError(
                f"campaign {name!r}: the data cannot supply any cell, all left out ("
                + skipped_cells_text(plan.definition)
                + "); lower train_cycles/sweep",
                param=("skip_infeasible", "train_cycles", "sweep"),
            )
        summary = RunSummary(
            name, total, total - pending, created=stored is None, db=Path(store.path)
        )
        summary.extra["skipped_cells"] = plan.definition.get("skipped_cells", [])
        _record_start(store, plan, stored is None, total, backend, n_workers, pending)
        if pending:
            how = _How(
                jobs, backend, scheduler, batch_rows, flush_seconds, progress, on_batch, chunk_jobs
            )
            _execute(store, plan, bank, chunks, summary, how)
    summary.seconds = time.perf_counter() - started
    return summary


def check_backend(backend: str, scheduler: str | None, jobs: int) -> None:
    """Raise `CampaignError` for an unknown ``backend``, a ``scheduler`` without dask or
    a ``jobs`` that is not a number of workers."""
    if backend not in BACKENDS:
        raise CampaignError(
            f"backend: {backend!r}; expected one of {', '.join(BACKENDS)}", param="backend"
        )
    if scheduler and backend != "dask":
        raise CampaignError("scheduler needs backend dask", param=("scheduler", "backend"))
    if jobs == 0 or jobs < -1:
        raise CampaignError(
            f"jobs: {jobs}; expected a positive number of workers (or -1)", param="jobs"
        )


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


def campaign_samples(
    store: Store, prep: str | int | None, samples: pd.DataFrame | None = None
) -> tuple[str | int, pd.DataFrame]:
    """The label and samples frame a campaign runs on: preprocessing version ``prep``
    (resolved once, here, into its `Version`: its name and samples) or, given ``samples``,
    that frame, labelled ``prep`` (default ``"(samples given)"``)."""
    if samples is not None:
        return (prep if prep is not None else "(samples given)"), samples
    from suds_exp.preprocess import get_version

    version = get_version(store, prep)
    return version.name, version.samples()


def plan_campaign(
    name: str,
    options: CampaignOptions,
    stored: dict | None,
    samples: pd.DataFrame,
    added: frozenset = frozenset(),
) -> tuple[Plan, SampleBank]:
    """The plan and sample bank of campaign ``name`` with ``options`` (merged with the
    ``stored`` definition; ``options.prep`` the label of ``samples``, see
    `campaign_samples`; ``added`` as in `make_plan`); refuses a definition that differs
    from the stored one or data that cannot supply it."""
    plan, bank = make_plan(
        name,
        options,
        rounded_conditions(samples),
        lambda c: SampleBank.build(samples, c),
        added,
    )
    if stored is not None:
        check_same(
            stored,
            normalise(plan.definition),
            f"campaign {name!r}",
            "continue it with its stored options or choose a new NAME",
            CampaignError,
        )
    # With skip_infeasible the plan already left out every cell the data cannot
    # supply; conditions without any complete cycle are refused either way.
    needs = {} if plan.definition["options"].get("skip_infeasible") else max_cycles(plan)
    # the added conditions' infeasible cells are already left out (`make_plan`)
    needs = {c: n for c, n in needs.items() if c[0] not in added and c not in added}
    check_feasible(bank, plan.train_conditions, plan.test_conditions, needs)
    return plan, bank


def _n_workers(jobs: int) -> int:
    if jobs == -1:
        return os.cpu_count() or 1
    return jobs


def _default_chunk(plan: Plan, n_workers: int) -> int:
    if n_workers <= 1:
        return len(plan.models)
    total = len(plan.train_conditions) * len(plan.test_conditions) * plan.boots * len(plan.models)
    return int(min(32, max(1, math.ceil(total / (n_workers * 30)))))


def _record_start(store, plan, create, total, backend, n_workers, pending) -> None:
    now = datetime.now(UTC).replace(tzinfo=None)
    with store.write() as conn:
        if create:
            conn.execute(
                tables.campaigns.insert().values(
                    name=plan.name,
                    prep_version=str(plan.definition["options"]["prep"]),
                    definition=json.dumps(plan.definition),
                    n_jobs=total,
                    created_at=now,
                )
            )
        conn.execute(
            tables.campaign_runs.insert().values(
                campaign=plan.name,
                started_at=now,
                pid=os.getpid(),
                host=socket.gethostname(),
                backend=backend if n_workers != 1 or backend == "dask" else "in-process",
                n_workers=n_workers,
                n_pending=pending,
            )
        )


class _Signals:
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


def _results_iter(bank, chunks, plan, how: _How, pending: int, stack: contextlib.ExitStack):
    args = (plan.models, plan.test_cycles)
    jobs = how.jobs
    if how.backend == "dask":
        client = _dask_client(how.scheduler, jobs, stack)
        threads = _cluster_threads(client)
        sizer = _TaskSizer(pending, threads, how.chunk_jobs)
        return _dask_rows(client, bank, _regroup(chunks, sizer), args, sizer, stack)
    if jobs == 1:
        stack.enter_context(threadpool_limits(limits=1))
        return (run_chunk(bank, c, *args, blas="none") for c in chunks)
    from joblib import Parallel, delayed, parallel_config

    shared = bank.memmapped(_bank_folder(stack))
    stack.enter_context(parallel_config(backend="loky", n_jobs=jobs))
    # loky workers end with this process, even after kill -9 (see `job.watch_parent`)
    worker_args = {"blas": "pin", "parent": os.getpid()}
    # loky starts its workers here, with SIGINT ignored like dask's (`_sigint_blocked`)
    with _sigint_blocked():
        gen = Parallel(return_as="generator_unordered", batch_size=1, pre_dispatch="2*n_jobs")(
            delayed(run_chunk)(shared, c, *args, **worker_args) for c in chunks
        )
    stack.callback(getattr(gen, "close", lambda: None))
    return gen


def _dask_client(scheduler: str | None, jobs: int, stack: contextlib.ExitStack):
    """A dask.distributed client of the cluster at ``scheduler``, or of a local cluster of
    ``jobs`` one-thread worker processes; both closed with ``stack``."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        # a lost scheduler is one line (`ClusterLostError`), not the client's logged
        # reconnect tracebacks, nor tornado's of a result being gathered then (a
        # callback of the client's loop: 45 lines, seen in the cluster test)
        stack.enter_context(_quiet_logger("distributed"))
        stack.enter_context(_quiet_logger("tornado"))
        return stack.enter_context(Client(scheduler, timeout=SCHEDULER_WAIT_S))
    with _sigint_blocked():
        cluster = LocalCluster(
            n_workers=_n_workers(jobs),
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


def _cluster_threads(client) -> int:
    """Worker threads of ``client``'s cluster now (at least 1: workers may join later)."""
    return max(1, sum(client.nthreads().values()))


class _TaskSizer:
    """Jobs per dask task: `DASK_TASK_SECONDS` of fit + predict time at the mean job time
    seen so far, at most the jobs pending at the start / (threads x
    `DASK_TASKS_PER_THREAD`); ``fixed`` (``chunk_jobs``) overrides both.

    A job of a five-cycle campaign takes ~12 ms: one task a draw would pay the scheduler's
    round trip, the task's (de)serialisation and the worker's event loop hundreds of times
    for little work each (dask advises tasks of 100 ms or more). Tasks of a fraction of a
    second keep the end of the run even (draws with the most cycles come first), the work
    a killed worker takes with it small, and a Ctrl-C quick (a stopping local worker
    finishes its task first)."""

    def __init__(self, pending: int, threads: int, fixed: int | None = None):
        self.fixed = fixed
        self.cap = max(1, math.ceil(pending / (threads * DASK_TASKS_PER_THREAD)))
        self.threads = threads
        self.jobs = 0
        self.seconds = 0.0

    def seen(self, rows: list[dict]) -> None:
        self.jobs += len(rows)
        self.seconds += sum(r["fit_seconds"] + r["predict_seconds"] for r in rows)

    def size(self) -> int:
        if self.fixed:
            return self.fixed
        if not self.jobs or self.seconds <= 0:
            return 1  # one draw: its learners stay together
        return int(min(self.cap, max(1, DASK_TASK_SECONDS * self.jobs / self.seconds)))


def _regroup(chunks, sizer: _TaskSizer) -> Iterator[list]:
    """The draws of ``chunks`` in chunks of about ``sizer.size()`` jobs, a draw's learners
    together (the size read as each task is made)."""
    current: list = []
    n = 0
    for chunk in chunks:
        current.extend(chunk)
        n += sum(len(names) for _, names in chunk)
        if n >= sizer.size():
            yield current
            current, n = [], 0
    if current:
        yield current


#: How often the dask path asks the scheduler how many worker threads there are, in s.
THREADS_POLL_S = 5.0


def _dask_rows(client, bank, tasks, args, sizer: _TaskSizer, stack: contextlib.ExitStack):
    """Rows of each task of ``tasks`` as it finishes on ``client``'s cluster.

    Submitted straight to the scheduler (not through joblib, whose dask backend runs every
    task in this process when the cluster has a single thread), two tasks a worker thread
    at a time, so the chunks of a large campaign are built as they are sent. The bank is
    scattered to every worker once; a worker that dies takes its task with it and the
    scheduler runs that task again on another (the rows are the same: seeds come from
    each job's key).
    """
    from dask.distributed import as_completed

    shared = client.scatter(bank, broadcast=True, hash=False)
    running = as_completed()
    tasks = iter(tasks)

    def cancel() -> None:
        if client.status == "running":
            with contextlib.suppress(Exception):
                client.cancel(list(running.futures), asynchronous=False)

    stack.callback(cancel)

    def submit(n: int) -> None:
        for chunk in itertools.islice(tasks, max(0, n)):
            running.add(client.submit(run_chunk, shared, chunk, *args, blas="block", pure=False))

    submit(2 * sizer.threads)
    check = time.monotonic() + THREADS_POLL_S
    for future in running:
        rows = future.result()
        future.release()
        sizer.seen(rows)
        if time.monotonic() >= check:  # workers that joined since the start get work too
            sizer.threads, check = _cluster_threads(client), time.monotonic() + THREADS_POLL_S
        submit(2 * sizer.threads - running.count())
        yield rows


@contextlib.contextmanager
def _closed_shielded(signals: _Signals) -> Iterator[contextlib.ExitStack]:
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
def _quiet_logger(name: str) -> Iterator[None]:
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


def _cluster_lost(exc: BaseException) -> bool:
    """True for what a dask client raises when its scheduler or the connection to it goes
    away mid-run (a closed comm, cancelled futures, a reconnect that timed out)."""
    from concurrent.futures import CancelledError

    from distributed.comm.core import CommClosedError

    return isinstance(exc, CommClosedError | CancelledError | asyncio.CancelledError | TimeoutError)


BANK_PREFIX = "suds_bank_"


def _bank_folder(stack: contextlib.ExitStack) -> Path:
    """A new temporary folder for the memory-mapped bank, removed when ``stack`` closes.

    It holds a file lock for as long as this process lives; a folder whose lock is free
    belonged to a process that was killed before it could remove it (kill -9), and is
    removed by the next run."""
    from filelock import FileLock, Timeout

    for old in Path(tempfile.gettempdir()).glob(BANK_PREFIX + "*"):
        lock = FileLock(old / "owner.lock")
        try:
            if time.time() - old.stat().st_mtime < 60:
                continue  # just made: its owner may not hold the lock yet
            lock.acquire(timeout=0)
        except (Timeout, OSError):
            continue
        lock.release()
        shutil.rmtree(old, ignore_errors=True)
    folder = Path(tempfile.mkdtemp(prefix=BANK_PREFIX))
    stack.callback(shutil.rmtree, folder, ignore_errors=True)
    lock = FileLock(folder / "owner.lock")
    lock.acquire(timeout=0)
    stack.callback(lock.release)
    return folder


@contextlib.contextmanager
def _sigint_blocked() -> Iterator[None]:
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


@dataclass(frozen=True)
class _How:
    """How `_execute` runs the chunks and writes their rows (see `run_campaign`)."""

    jobs: int
    backend: str
    scheduler: str | None
    batch_rows: int
    flush_seconds: float
    progress: bool
    on_batch: object
    chunk_jobs: int | None = None


def _execute(store, plan, bank, chunks, summary, how: _How) -> None:
    buffer: list[dict] = []

    def flush(final: bool = False):
        if not buffer:
            return
        t0 = time.perf_counter()
        with signals.shielded():
            frame = pd.DataFrame(buffer, columns=list(RESULT_COLUMNS))
            try:
                with store.write() as conn:
                    store.insert_df(conn, "results", frame)
            except StoreError:
                # Another process held the file longer than the store waits: keep the
                # rows and try again at the next batch (the last write gives up).
                if final:
                    raise
                return
            summary.done_now += len(frame)
            summary.failed_now += int(frame["error"].notna().sum())
            summary.batches += 1
            buffer.clear()
        summary.flush_seconds += time.perf_counter() - t0
        if how.on_batch is not None:
            how.on_batch(len(frame))

    lost: BaseException | None = None
    with (
        _Signals() as signals,
        progress_bar(
            f"campaign {plan.name}",
            summary.total_jobs,
            enabled=how.progress,
            done=summary.done_before,
            unit="jobs",
        ) as advance,
    ):
        last = time.monotonic()
        try:
            with _closed_shielded(signals) as stack:
                # a cluster stopped while it starts fails on its own assertions: a
                # Ctrl-C then is served once it is up
                with signals.shielded():
                    rows_iter = _results_iter(
                        bank, chunks, plan, how, summary.total_jobs - summary.done_before, stack
                    )
                for rows in rows_iter:
                    buffer.extend(rows)
                    advance(len(rows))
                    if (
                        len(buffer) >= how.batch_rows
                        or time.monotonic() - last >= how.flush_seconds
                    ):
                        flush()
                        last = time.monotonic()
        except KeyboardInterrupt:
            summary.interrupted = True
        except (Exception, asyncio.CancelledError) as exc:
            if how.backend != "dask" or not _cluster_lost(exc):
                raise
            lost = exc
        finally:
            # Rows already received are written even when stopping or failing: a stop
            # loses no finished work. A second Ctrl-C during this write is served after it.
            try:
                flush(final=True)
            except KeyboardInterrupt:
                summary.interrupted = True
    if lost is not None:
        where, again = "the local dask cluster", ""
        if how.scheduler:
            where, again = how.scheduler, "start the scheduler and its workers again, then "
        raise ClusterLostError(
            f"dask cluster lost during campaign {plan.name!r} ({where}: "
            f"{type(lost).__name__}); the {summary.done_before + summary.done_now} finished "
            f"jobs are stored; {again}run the same command to continue"
        ) from None
