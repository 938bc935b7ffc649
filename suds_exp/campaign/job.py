"""What a worker does: run chunks of draws and return finished `results` rows.

Workers never touch the database. They get the `SampleBank` (shared, read-only), a chunk
of draws with the learners still to run on each, and the learners' parameters, and give
back plain row dicts for the parent to write.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import sys
import threading
import time
from datetime import UTC, datetime

import numpy as np
import pandas as pd
from threadpoolctl import ThreadpoolController, threadpool_limits

from suds_exp.campaign.bank import SampleBank
from suds_exp.campaign.grid import KEY_COLUMNS, Draw
from suds_exp.campaign.sampling import draw_sample
from suds_exp.robot import VB_COLUMNS

#: Columns of the `results` table, in order.
RESULT_COLUMNS = KEY_COLUMNS + (
    "train_trials",
    "train_ranges",
    "test_trial",
    "test_range",
    "rmse_vx",
    "rmse_vy",
    "rmse_wz",
    "n_test",
    "fit_seconds",
    "predict_seconds",
    "finished_at",
    "error",
)
#: Columns that vary from run to run of the same job (everything else is reproducible).
TIMING_COLUMNS = ("fit_seconds", "predict_seconds", "finished_at")

Chunk = list[tuple[Draw, list[str]]]


_PINNED = False


def run_chunk(
    bank: SampleBank,
    chunk: Chunk,
    models: dict[str, dict],
    test_cycles: int,
    blas: str = "block",
    parent: int | None = None,
) -> list[dict]:
    """Rows of every job in ``chunk`` (a list of (draw, learner names)).

    BLAS runs on one thread, so a job computes the same floating-point numbers in the
    parent, in a loky worker and on a dask worker, and workers do not oversubscribe the
    cores. ``blas``: "block" limits it for this call (`one_blas_thread`), "pin" once for
    the life of the process (dedicated loky workers), "none"
    leaves it to the caller. ``parent``: in a worker process, the pid of the process that
    runs the campaign; the worker then ends itself when that process is gone
    (`watch_parent`) and leaves Ctrl-C to it.
    """
    global _PINNED
    if parent is not None:
        watch_parent(parent)
    if blas == "block":
        settle_allocator()
    rows: list[dict] = []
    if blas == "pin" and not _PINNED:
        threadpool_limits(limits=1)
        _PINNED = True
    with one_blas_thread() if blas == "block" else contextlib.nullcontext():
        for draw, names in chunk:
            rows.extend(run_draw(bank, draw, names, models, test_cycles))
    return rows


_POOLS: tuple[int, ThreadpoolController] | None = None


def one_blas_thread():
    """A context manager: every BLAS and OpenMP pool of this process at one thread inside,
    as they were after.

    threadpoolctl finds the pools by scanning the loaded libraries, 2-5 ms of CPU a time
    (measured under load), as much as 7 % of a task of one draw on a dask worker; the
    scan is kept until a module is imported (how a new library gets loaded here), so a
    worker scans once rather than once a task."""
    global _POOLS
    if _POOLS is None or _POOLS[0] != len(sys.modules):
        _POOLS = (len(sys.modules), ThreadpoolController())
    return _POOLS[1].limit(limits=1)


#: glibc's mallopt parameters, and the thresholds `settle_allocator` sets, in bytes.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
MMAP_THRESHOLD = 4 << 20
_SETTLED = False


def settle_allocator() -> bool:
    """Once per process, where glibc's allocator was given a fixed trim or mmap threshold
    by environment (``MALLOC_TRIM_THRESHOLD_``: dask's nanny sets 64 KiB in every worker
    it starts): allocations up to `MMAP_THRESHOLD` come from the heap again and it is
    trimmed beyond twice that. Returns whether it changed anything.

    A fixed threshold turns off glibc's adaptive one. In a thread other than the main one
    (a dask worker runs its tasks in one), every freed block then goes back to the
    system, and the next array of a few hundred KiB faults its pages in again: about 300
    page faults a job on a 5-cycle campaign's frames instead of 0-3, counted, and a job's
    CPU time up by a third (measured under load). Results do not change.
    """
    global _SETTLED
    if _SETTLED or not any(
        os.environ.get(v) for v in ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_")
    ):
        return False
    _SETTLED = True
    try:
        import ctypes

        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # not glibc
        return False
    return bool(
        mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)
        and mallopt(_M_TRIM_THRESHOLD, 2 * MMAP_THRESHOLD)
    )


_WATCHED: set[int] = set()
#: How often a worker checks that the campaign's process is still there, in s.
PARENT_POLL_S = 0.5


def watch_parent(pid: int) -> None:
    """In a worker process of ``pid``'s campaign: ignore SIGINT (a terminal's Ctrl-C
    reaches the whole process group; the parent stops the run and its workers) and, once
    per process, start a daemon thread that ends this process within `PARENT_POLL_S` s of
    ``pid`` ending (kill -9 included), instead of idling until the pool's timeout."""
    if pid == os.getpid() or pid in _WATCHED:
        return
    _WATCHED.add(pid)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch() -> None:
        while _alive(pid):
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="suds-watch-parent", daemon=True).start()


def _alive(pid: int) -> bool:
    # An orphan is re-parented, so its parent id changes when the parent dies. Windows
    # keeps the old id (and has no cheap safe probe: os.kill terminates): there the
    # pool's own idle timeout ends the workers.
    return os.getppid() == pid if os.name == "posix" else True


def run_draw(
    bank: SampleBank, draw: Draw, names: list[str], models: dict[str, dict], test_cycles: int
) -> list[dict]:
    """Fit and test each learner in ``names`` on the draw's cycles; one row per learner."""
    from suds_exp.models import make_model

    sample = draw_sample(bank, draw, test_cycles)
    train = bank.frame([bank.rows(*r) for r in sample.train])
    test_rows = bank.rows(*sample.test)
    test = bank.frame([test_rows])
    truth = np.ascontiguousarray(test_rows[:, [bank.columns.index(c) for c in VB_COLUMNS]])
    ids = bank.trial_ids
    common = {
        "campaign": draw.campaign,
        "train_gait": draw.train[0],
        "train_frequency_hz": draw.train[1],
        "test_gait": draw.test[0],
        "test_frequency_hz": draw.test[1],
        "boot": draw.boot,
        "n_cycles": draw.n_cycles,
        "train_trials": json.dumps(list(dict.fromkeys(int(ids[i]) for i, _, _ in sample.train))),
        "train_ranges": json.dumps([[int(ids[i]), a, b] for i, a, b in sample.train]),
        "test_trial": int(ids[sample.test[0]]),
        "test_range": json.dumps([sample.test[1], sample.test[2]]),
        "n_test": len(test),
    }
    rows = []
    for k, name in enumerate(names):
        last = k == len(names) - 1
        params = dict(models[name])
        if "random_state" in params and params["random_state"] is None:
            params["random_state"] = draw.model_seed(name)
        rmse = (np.nan, np.nan, np.nan)
        error = None
        fit_s = predict_s = 0.0
        try:
            model = make_model(name, **params)
            t0 = time.perf_counter()
            # Shallow copies: pandas copies on write, so a learner that adds or overwrites
            # columns changes only its own copy and the next learner sees the same frame
            # (the draw's last learner has no next one: it gets the frames themselves).
            model.fit(train if last else train.copy(deep=False))
            t1 = time.perf_counter()
            pred = model.predict(test if last else test.copy(deep=False))
            t2 = time.perf_counter()
            fit_s, predict_s = t1 - t0, t2 - t1
            err = predicted_velocity(pred) - truth
            # np.mean(err**2, axis=0) without its Python wrapper: the same sum and division
            rmse = tuple(float(v) for v in np.sqrt(np.add.reduce(err**2, axis=0) / len(err)))
            if not np.all(np.isfinite(rmse)):
                error = "prediction is not finite (NaN or inf), e.g. a diverging rollout"
        except Exception as exc:  # noqa: BLE001 - a failed job is recorded, not retried forever
            lines = str(exc).strip().splitlines()
            error = f"{type(exc).__name__}: {lines[0] if lines else ''}"
        rows.append(
            {
                **common,
                "model": name,
                "rmse_vx": _finite(rmse[0]),
                "rmse_vy": _finite(rmse[1]),
                "rmse_wz": _finite(rmse[2]),
                "fit_seconds": fit_s,
                "predict_seconds": predict_s,
                "finished_at": datetime.now(UTC).replace(tzinfo=None),
                "error": error,
            }
        )
    return rows


def predicted_velocity(pred) -> np.ndarray:
    """vx, vy, wz of a learner's prediction frame as a float array of shape (n, 3), in C
    order (the layout the RMS error's row-wise sum was always taken on)."""
    # Column positions from a plain list: a prediction frame's new column index would
    # build its hash table for one look-up, dearer than the look-up itself.
    names = pred.columns.tolist() if isinstance(pred, pd.DataFrame) else []
    if names and len(set(names)) == len(names) and all(c in names for c in VB_COLUMNS):
        values = pred.to_numpy()  # a view of a prediction frame's one float block
        if values.dtype == np.float64:
            return np.ascontiguousarray(values[:, [names.index(c) for c in VB_COLUMNS]])
    return np.column_stack([pred[c].to_numpy(dtype=float) for c in VB_COLUMNS])


def _finite(value: float) -> float | None:
    return value if np.isfinite(value) else None
