"""Benchmark: `suds-exp report` on a campaign of ~100k synthetic results.

Writes the results into a temporary database once, then writes the full report
``--repeats`` times and prints each wall time and the median. Target: under 60 s.

    .venv/bin/python -m benchmarks.speed.report [--rows 100000] [--repeats 3]

``--quick``: one report of one draw a cell (a smoke run, no figure).
"""

from __future__ import annotations

import math
import statistics
import tempfile
import time
from pathlib import Path

from benchmarks._harness import script_parser
from suds_exp.analysis import write_report
from suds_exp.store import Store
from suds_exp.testing.synthetic_results import synthetic_results

N_CYCLES = (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 21, 30, 39, 48)  # the paper's sweep
TARGET_S = 60.0


def main(argv=None) -> None:
    parser = script_parser(__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=100_000, help="approximate number of results")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    if args.quick:
        args.rows, args.repeats = 1, 1
    per_boot = 5 * 15 * 15 * len(N_CYCLES)
    n_boot = max(1, math.ceil(args.rows / per_boot))
    frame = synthetic_results("bench", n_boot=n_boot, n_cycles=N_CYCLES, seed=7)
    with tempfile.TemporaryDirectory() as tmp:
        store = Store(Path(tmp) / "bench.duckdb")
        t0 = time.perf_counter()
        with store.write() as conn:
            store.insert_df(conn, "results", frame)
        print(f"inserted {len(frame)} results in {time.perf_counter() - t0:.2f} s")
        times = []
        for i in range(args.repeats):
            t0 = time.perf_counter()
            write_report(store, "bench", Path(tmp) / f"report{i}")
            times.append(time.perf_counter() - t0)
            print(f"report {i + 1}: {times[-1]:.2f} s")
    median = statistics.median(times)
    verdict = "under" if median < TARGET_S else "OVER"
    print(
        f"median report time for {len(frame)} results: {median:.2f} s "
        f"({verdict} the {TARGET_S:g} s target)"
    )


if __name__ == "__main__":
    main()
