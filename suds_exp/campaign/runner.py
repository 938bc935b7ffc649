"""`run_campaign`: create or continue a campaign and fill its `results` rows.

The parent process loads the samples once, builds the `SampleBank`, works out which jobs
are not finished yet, and hands chunks of draws to workers (loky processes on this machine
through joblib, or the threads of a dask.distributed cluster, a few tasks a thread).
Finished rows come back to the parent, which writes them in batches, each batch in one
transaction, holding the database file only while it writes, so `suds-exp status`,
`suds-exp sql` and `duckdb -readonly` can read in between. A file lock beside the
database keeps a second run out. The chunks are run and their rows written by
`suds_exp.campaign.execute`; the dask side is `suds_exp.campaign.cluster`.

Stopping: Ctrl-C (or SIGTERM) stops after writing every row already received; a signal
that arrives while a batch is being written is served after the write, so a batch is
never written twice. `kill -9` loses at most the rows not yet written; DuckDB's
write-ahead log makes each batch all-or-nothing.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import socket
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from suds_exp.campaign import cluster, tables
from suds_exp.campaign.bank import SampleBank, rounded_conditions
from suds_exp.campaign.definition import (
    CampaignOptions,
    Plan,
    make_plan,
    merge_stored,
    normalise,
    skipped_cells_text,
)
from suds_exp.campaign.execute import How, execute
from suds_exp.campaign.lock import RunLock
from suds_exp.campaign.resume import load_stored_definition, max_cycles, pending_jobs
from suds_exp.campaign.sampling import check_feasible
from suds_exp.display import Summary
from suds_exp.errors import CampaignError
from suds_exp.ingest import stored_design
from suds_exp.ingest.added import added_conditions
from suds_exp.store import Store
from suds_exp.store.definition import check_same

BACKENDS = ("loky", "dask")
#: A batch is written when it holds this many rows ...
BATCH_ROWS = 1000
#: ... or when this many seconds passed since the last write, whichever comes first.
#: A write costs ~0.05 CPU s whatever its size (opening, committing and closing the
#: file); every 10 s that is 0.5 % of one core, and `kill -9` loses 10 s of work at most.
FLUSH_SECONDS = 10.0


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
        """The summary as JSON-safe values: `JSON_FIELDS`, then the left-out cells."""
        out = {name: getattr(self, name) for name in self.JSON_FIELDS}
        return out | {"skipped_cells": self.extra.get("skipped_cells", [])}

    #: The attributes of `to_dict`, in its order.
    JSON_FIELDS = (
        "campaign",
        "created",
        "total_jobs",
        "done_before",
        "done_now",
        "failed_now",
        "remaining",
        "interrupted",
        "seconds",
    )


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
        cluster.check_scheduler(scheduler)
    options = options or CampaignOptions()
    started = time.perf_counter()
    if backend == "dask":
        cluster.import_in_background()  # while the database and the plan are read
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
        record = (store, plan, stored is None, total, backend, n_workers, pending)
        if pending:
            how = How(
                jobs,
                n_workers,
                backend,
                scheduler,
                batch_rows,
                flush_seconds,
                progress,
                on_batch,
                chunk_jobs,
            )
            # the run is recorded once its first chunks are on their way
            execute(store, plan, bank, chunks, summary, how, lambda: _record_start(*record))
        else:
            _record_start(*record)
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
