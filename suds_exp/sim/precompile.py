"""Compile the simulator's numba kernels into numba's on-disk cache ahead of first use.

The kernels (`suds_exp.sim.rft`, `suds_exp.sim.files`) are compiled with ``cache=True``:
the first process that calls one compiles it (some 15 CPU seconds for the RFT solver)
and every later process loads it from ``__pycache__`` in a fraction of a second. The
cache is tied to the simulator's source files (a hash of every module of `suds_exp.sim`,
`sim/_jit.py`), so every fresh install or change of the simulator pays the compile once;
``make`` pays it at install time (``python -m suds_exp.sim.precompile``) so that the
first ``suds-exp simulate`` a user runs does not.
"""

from __future__ import annotations

import sys
import time

import numpy as np


def compile_kernels() -> float:
    """Call every compiled entry point once on a tiny input (one trial of a few frames,
    a 2 x 2 connection grid, a one-row table), so their machine code is in the cache.

    Returns the seconds it took (about 15 on an idle core when nothing was cached, well
    under one when everything was).
    """
    from suds_exp.sim.config import SimConfig
    from suds_exp.sim.connection import local_connection
    from suds_exp.sim.files import format_table
    from suds_exp.sim.mechanics import simulate_prescribed

    t0 = time.perf_counter()
    cfg = SimConfig()
    t = np.arange(3) / cfg.measurement.sample_rate_hz
    phi = np.stack([np.cos(t), np.sin(t)], axis=-1)[None]
    simulate_prescribed(phi, 1.0 / cfg.measurement.sample_rate_hz, cfg)
    local_connection(grid=2, config=cfg, n_directions=2)
    format_table(np.zeros((1, 2)), np.array([0, 3], dtype=np.int64))
    return time.perf_counter() - t0


#: what the first compile takes, in seconds on an idle core (compile_kernels, measured when
#: this module was written; a loaded machine takes longer)
COMPILE_S = 15


def kernels_cached() -> bool:
    """Whether numba's on-disk cache holds the simulator's main kernel for the installed
    source, so a simulation starts without compiling. Reads the kernel's cache index
    only (numba's own check: the source file's stamp and numba's version); True when the
    cache cannot be asked, so that nothing is announced that may not happen."""
    from suds_exp.sim import rft

    try:
        cache = rft.run_trials._cache
        return bool(cache._cache_file._load_index())
    except Exception:  # numba's cache layout is internal: assume cached
        return True


def main() -> int:
    print(f"simulator kernels compiled and cached in {compile_kernels():.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
