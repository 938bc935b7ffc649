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


# importing happens before dask_setup, as early as a worker can act
dask_setup(None)
