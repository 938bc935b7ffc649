"""Memory and time of the findings bootstrap against a baseline commit, same numbers.

Usage::

    .venv/bin/python -m benchmarks.speed.findings_memory --baseline bc6c20e --draws 100 --boot 400

Each side runs in its own process (the baseline from a `git archive` of ``--baseline``,
alternating with the working tree, ``--rounds`` times): synthetic labelled results
(`suds_exp.testing.synthetic_results`, ``--draws`` draws per pair at 3, 10 and 30
training cycles: 3,375 rows per draw) through `findings_table` with ``--boot``
replicates. It prints each side's median peak resident memory (MB), median seconds, and
a digest of the table, which must agree. ``--quick``: baseline HEAD, one round, 2 draws
and 20 replicates (a smoke run, no figure).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import resource
import time
from pathlib import Path
from statistics import median

from benchmarks._harness import alternate, same, script_parser, worker


def measure(draws: int, boot: int) -> dict:
    from suds_exp.analysis.findings import findings_table
    from suds_exp.testing.synthetic_results import synthetic_results

    results = synthetic_results("bench", n_boot=draws, n_cycles=(3, 10, 30))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    started = time.perf_counter()
    table = findings_table(results, n_boot=boot, seed=1)
    seconds = time.perf_counter() - started
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    digest = hashlib.sha256(table.to_csv().encode()).hexdigest()[:16]
    return {
        "rows": len(results),
        "seconds": seconds,
        "peak_mb": peak,
        "data_mb": before,
        "digest": digest,
    }


def main(argv=None) -> int:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="HEAD", help="commit to compare against")
    ap.add_argument("--draws", type=int, default=100, help="draws per pair")
    ap.add_argument("--boot", type=int, default=400, help="bootstrap replicates")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.quick:
        a.baseline, a.rounds, a.draws, a.boot = "HEAD", 1, 2, 20
    if a.worker:
        print(json.dumps(measure(a.draws, a.boot)))
        return 0

    def run(tree: Path) -> dict:
        args = ["--draws", str(a.draws), "--boot", str(a.boot)]
        return worker(tree, __spec__.name, *args, OMP_NUM_THREADS="1")

    base, now = alternate(a.baseline, a.rounds, run)
    print(f"{now[0]['rows']:,} results, {a.boot} replicates, {a.rounds} rounds (medians)")
    print("side      peak MB  (data loaded)  seconds  digest")
    for label, runs in ((a.baseline, base), ("tree", now)):
        print(
            f"{label:9} {median(r['peak_mb'] for r in runs):7.0f}  "
            f"({median(r['data_mb'] for r in runs):5.0f})        "
            f"{median(r['seconds'] for r in runs):7.1f}  {runs[0]['digest']}"
        )
    digests = [r["digest"] for r in base + now]
    identical = same(digests)
    print("same table on both sides" if identical else f"TABLES DIFFER: {sorted(set(digests))}")
    return 0 if identical else 1


if __name__ == "__main__":
    raise SystemExit(main())
