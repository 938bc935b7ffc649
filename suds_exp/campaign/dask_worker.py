"""Preloaded into every dask worker a campaign's local cluster starts (`preload=`), and
into the workers of a cluster a user starts with ``dask worker ... --preload
suds_exp.campaign.dask_worker``.

A worker imports the learners (scikit-learn, SciPy: 1.5 s on a 2-core machine) as it
starts rather than during its first job, so a campaign's wall time and its first jobs'
fit times do not carry every worker's imports.

A terminal's Ctrl-C reaches the whole process group, workers included; the campaign's own
process stops the run and closes the cluster, so a worker ignores SIGINT instead of
printing its own KeyboardInterrupt traceback. Its allocator is settled before any job
(`suds_exp.campaign.job.settle_allocator`: the nanny's fixed trim threshold costs page
faults in every job).

It also turns off the worker's statistical profiler (``distributed.worker.profile``: a
look at the task thread's stack every 10 ms, for the dashboard's profile page): on a
2-worker cluster of 1,200 five-cycle jobs it took 7 % of the workers' CPU time (8.9-9.6 s
against 9.5-10.2 s a worker, two rounds each, measured under load). The module is
imported before the worker sets its profiler up, so the setting takes effect.

And it wakes the worker's event loop less often for its chores (`QUIET_LOOP`): the
tick that watches the loop's health (every 20 ms by default), the system monitor that
feeds the dashboard's graphs (500 ms) and the memory monitor (100 ms). Each wake-up takes
the GIL from the task thread and a core from the other workers; on a 2-worker cluster
of 1,200 five-cycle jobs the loop's own CPU time fell from 0.39-0.40 s to 0.12-0.15 s a
worker (4 % of a worker's CPU time to 1.3 %; measured under load). The memory limits
still hold, checked every second.
"""

from __future__ import annotations

import signal
import threading

#: How often (ms) a worker's event loop wakes for each chore: the name of its periodic
#: callback and of the dask setting it starts from.
QUIET_LOOP = {
    "tick": ("distributed.admin.tick.interval", 1000),
    "monitor": ("distributed.admin.system-monitor.interval", 5000),
    "memory_monitor": ("distributed.worker.memory.monitor-interval", 1000),
}


def dask_setup(worker) -> None:
    """Called by dask in each worker process as it starts (``worker``: the dask Worker;
    None when this module is imported)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    from suds_exp.campaign.job import settle_allocator

    settle_allocator()
    import suds_exp.models  # noqa: F401  (warm: see the module's docstring)

    # the tick and the system monitor were set up before the preload was imported
    callbacks = getattr(worker, "periodic_callbacks", {})
    for name, (_, ms) in QUIET_LOOP.items():
        if name in callbacks:
            callbacks[name].callback_time = ms


def _quiet() -> None:
    import dask

    dask.config.set({"distributed.worker.profile.enabled": False})
    dask.config.set({key: f"{ms}ms" for key, ms in QUIET_LOOP.values()})


# importing happens before dask_setup, as early as a worker can act
_quiet()
dask_setup(None)
