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
imported before the worker sets its periodic callbacks up, so the setting takes effect.
"""

from __future__ import annotations

import signal
import threading


def dask_setup(worker) -> None:
    """Called by dask in each worker process as it starts."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    from suds_exp.campaign.job import settle_allocator

    settle_allocator()
    import suds_exp.models  # noqa: F401  (warm: see the module's docstring)


def _quiet_profiler() -> None:
    import dask

    dask.config.set({"distributed.worker.profile.enabled": False})


# importing happens before dask_setup, as early as a worker can act
_quiet_profiler()
dask_setup(None)
