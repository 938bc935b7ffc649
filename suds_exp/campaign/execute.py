"""Running a campaign's pending chunks and writing their rows (`execute`, called by
`run_campaign` once the plan and the pending jobs are known).

The chunks run in this process, on loky worker processes through joblib (the bank
memory-mapped from a temporary folder), or on a dask cluster (`suds_exp.campaign.cluster`).
Finished rows come back here and are written in batches, each batch in one transaction.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import shutil
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from threadpoolctl import threadpool_limits

from suds_exp.campaign import cluster
from suds_exp.campaign.job import RESULT_COLUMNS, run_chunk
from suds_exp.campaign.signals import Signals, closed_shielded, sigint_blocked
from suds_exp.errors import ClusterLostError, StoreError
from suds_exp.progress import progress_bar


@dataclass(frozen=True)
class How:
    """How `execute` runs the chunks and writes their rows (see `run_campaign`);
    ``n_workers`` is ``jobs`` with -1 resolved to the machine's cores."""

    jobs: int
    n_workers: int
    backend: str
    scheduler: str | None
    batch_rows: int
    flush_seconds: float
    progress: bool
    on_batch: object
    chunk_jobs: int | None = None


def execute(store, plan, bank, chunks, summary, how: How, started: Callable[[], None]) -> None:
    """Run ``chunks`` (lists of (draw, learner names)) of ``plan`` on ``bank`` as ``how``
    says, writing their rows to ``store`` and counting them in ``summary``.

    ``started`` is called once the chunks are on their way (on a cluster: its first tasks
    submitted), before any row is written: the campaign's own records are written while
    the workers already run. Raises `ClusterLostError` when a dask cluster goes away; a
    Ctrl-C sets ``summary.interrupted``. Rows already received are written either way.
    """
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
        Signals() as signals,
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
            with closed_shielded(signals) as stack:
                # a cluster stopped while it starts fails on its own assertions: a
                # Ctrl-C then is served once it is up
                with signals.shielded():
                    rows_iter = results_iter(
                        bank, chunks, plan, how, summary.total_jobs - summary.done_before, stack
                    )
                    started()
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
            if how.backend != "dask" or not cluster.cluster_lost(exc):
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


def results_iter(bank, chunks, plan, how: How, pending: int, stack: contextlib.ExitStack):
    """An iterator of each chunk's rows as it finishes (in any order), its workers and
    their clean-up on ``stack``."""
    args = (plan.models, plan.test_cycles)
    if how.backend == "dask":
        client = cluster.dask_client(how.scheduler, how.n_workers, stack)
        return cluster.dask_rows(client, bank, chunks, args, pending, how.chunk_jobs, stack)
    if how.jobs == 1:
        stack.enter_context(threadpool_limits(limits=1))
        return (run_chunk(bank, c, *args, blas="none") for c in chunks)
    from joblib import Parallel, delayed, parallel_config

    shared = bank.memmapped(bank_folder(stack))
    stack.enter_context(parallel_config(backend="loky", n_jobs=how.jobs))
    # loky workers end with this process, even after kill -9 (see `job.watch_parent`)
    worker_args = {"blas": "pin", "parent": os.getpid()}
    # loky starts its workers here, with SIGINT ignored like dask's (`sigint_blocked`)
    with sigint_blocked():
        gen = Parallel(return_as="generator_unordered", batch_size=1, pre_dispatch="2*n_jobs")(
            delayed(run_chunk)(shared, c, *args, **worker_args) for c in chunks
        )
    stack.callback(getattr(gen, "close", lambda: None))
    return gen


BANK_PREFIX = "suds_bank_"


def bank_folder(stack: contextlib.ExitStack) -> Path:
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
