"""Resume state of a campaign: its stored definition, and the jobs left.

The finished jobs are counted per (cell, learner) in DuckDB; only cells with jobs left
go through an anti-join on job codes, and only the jobs left come back, as chunks built
while they are consumed. So resuming costs time and memory in the work left, not in the
work done.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Iterator

import numpy as np
import pandas as pd
import sqlalchemy as sa

from suds_exp.campaign import tables
from suds_exp.campaign.definition import Plan, normalise
from suds_exp.campaign.grid import Draw, enumerate_cells
from suds_exp.campaign.job import Chunk
from suds_exp.store import Store


def load_stored_definition(store: Store, name: str) -> dict | None:
    """The stored definition of campaign ``name``, or None when it does not exist."""
    if not store.path.exists():
        return None
    with store.read() as conn:
        return _stored_definition(conn, name)


def _stored_definition(conn: sa.Connection, name: str) -> dict | None:
    row = conn.execute(
        sa.select(tables.campaigns.c.definition).where(tables.campaigns.c.name == name)
    ).first()
    return None if row is None else normalise(json.loads(row[0]))


def pending_jobs(store: Store, plan: Plan, chunk_jobs: int) -> tuple[Iterator[Chunk], int, int]:
    """The jobs of ``plan`` not in `results` yet, in chunks of about ``chunk_jobs`` jobs.

    The set difference (every job of the grid minus the finished ones) is an anti-join in
    DuckDB on job codes; only the codes of the jobs left come back (8 bytes a job), and
    draws are built from them as the chunks are consumed. So a resume costs time and
    memory in the work left, not in the work done: a finished campaign is one count.

    Draws with the most training cycles come first (longest jobs first), so the last
    tasks of a run are short and no worker idles long at the end; the order changes no
    number, since every draw's seed comes from its key.

    Returns (chunks, total jobs of the campaign, pending jobs).
    """
    cells = enumerate_cells(
        plan.train_conditions, plan.test_conditions, plan.train_cycles, plan.sweep, plan.skipped
    )
    # a stable sort: within a size, the grid's order
    cells = sorted(cells, key=lambda c: -c[2])
    names = list(plan.models)
    total = len(cells) * plan.boots * len(names)
    if total == 0 or not store.path.exists():
        codes = np.arange(total, dtype=np.int64)
    else:
        with store.read() as conn:
            codes = _pending_codes(conn.connection.driver_connection, plan, cells, names, total)
    return _chunks(plan, cells, names, codes, chunk_jobs), total, len(codes)


def _pending_codes(raw, plan: Plan, cells: list, names: list[str], total: int) -> np.ndarray:
    """Codes ((cell rank x boots + boot) x learners + learner rank) of the jobs of the grid
    with no row in `results`, ascending (int64, shape (pending,)).

    First the finished jobs are counted per (cell, learner), one pass over the campaign's
    rows grouped into as many groups as the grid has cells; a finished campaign ends
    there. Only the cells with jobs left then go through the anti-join.
    """
    if not raw.execute(
        "SELECT count(*) FROM information_schema.tables WHERE table_name = 'results'"
    ).fetchone()[0]:
        return np.arange(total, dtype=np.int64)
    nm, boots = len(names), plan.boots
    # Each key is stored once (the unique key on `results`), so rows count distinct jobs.
    counts = raw.execute(
        "SELECT train_gait, train_frequency_hz, test_gait, test_frequency_hz, n_cycles, "
        "model, count(*) FILTER (WHERE boot >= 0 AND boot < $boots) AS done "
        "FROM results WHERE campaign = $name GROUP BY ALL",
        {"boots": boots, "name": plan.name},
    ).fetchall()
    rank = {(tr[0], tr[1], te[0], te[1], n): i for i, (tr, te, n) in enumerate(cells)}
    learner = {m: k for k, m in enumerate(names)}
    done = np.zeros((len(cells), nm), dtype=np.int64)
    for *cell, model, n_done in counts:
        i, k = rank.get(tuple(cell)), learner.get(model)
        if i is not None and k is not None:
            done[i, k] = n_done
    if done.sum() == 0:
        return np.arange(total, dtype=np.int64)
    open_cells = np.flatnonzero((done < boots).any(axis=1))
    if len(open_cells) == 0:
        return np.empty(0, dtype=np.int64)
    frame = pd.DataFrame(
        [(int(i), *cells[i][0], *cells[i][1], cells[i][2]) for i in open_cells],
        columns=["rank", "tg", "tf", "dg", "df", "n"],
    )
    tag = next(_frame_tags)
    raw.register(f"_suds_cells_{tag}", frame)
    raw.register(f"_suds_learners_{tag}", pd.DataFrame({"rank": range(nm), "model": names}))
    code = "(c.rank * $boots + {boot}) * $nm + m.rank"
    grid = (
        f"SELECT {code.format(boot='b.boot')} AS code FROM _suds_cells_{tag} c, "
        f"range($boots) b(boot), _suds_learners_{tag} m"
    )
    finished = f"""
        SELECT {code.format(boot="r.boot")} AS code
        FROM results r
        JOIN _suds_cells_{tag} c
          ON r.train_gait = c.tg AND r.train_frequency_hz = c.tf
         AND r.test_gait = c.dg AND r.test_frequency_hz = c.df AND r.n_cycles = c.n
        JOIN _suds_learners_{tag} m ON r.model = m.model
        WHERE r.campaign = $name AND r.boot >= 0 AND r.boot < $boots
    """
    try:
        left = raw.execute(
            f"SELECT g.code FROM ({grid}) g ANTI JOIN ({finished}) d ON g.code = d.code "
            "ORDER BY g.code",
            {"boots": boots, "nm": nm, "name": plan.name},
        ).fetchnumpy()["code"]
    finally:
        raw.unregister(f"_suds_cells_{tag}")
        raw.unregister(f"_suds_learners_{tag}")
    return np.asarray(left, dtype=np.int64)


_frame_tags = itertools.count()


def _chunks(plan: Plan, cells: list, names: list[str], codes: np.ndarray, chunk_jobs: int):
    """Chunks (lists of (draw, learner names)) of about ``chunk_jobs`` jobs from the
    ascending job ``codes`` of `_pending_codes`, one draw's learners kept together."""
    nm = len(names)
    current: Chunk = []
    size = 0
    draws = codes // nm
    starts = np.flatnonzero(np.diff(draws, prepend=-1))
    ends = np.append(starts[1:], len(codes))
    for a, b in zip(starts.tolist(), ends.tolist(), strict=True):
        rank, boot = divmod(int(draws[a]), plan.boots)
        tr, te, n = cells[rank]
        todo = [names[int(k)] for k in codes[a:b] % nm]
        current.append((Draw(plan.name, tr, te, boot, n), todo))
        size += len(todo)
        if size >= chunk_jobs:
            yield current
            current, size = [], 0
    if current:
        yield current


def max_cycles(plan: Plan) -> dict:
    """Cycles each condition of the plan must supply, by condition: the training size, and
    for a test condition the largest of it and the sweep's sizes."""
    tests = set(plan.test_conditions)
    return {
        c: max([plan.train_cycles, *(plan.sweep if c in tests else [])])
        for c in plan.train_conditions
    }
