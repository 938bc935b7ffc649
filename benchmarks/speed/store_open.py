"""What opening the database costs a command, against a baseline commit, same run.

Usage (from the repository root)::

    .venv/bin/python -m benchmarks.speed.store_open [--baseline b16e0d5] [--rounds 3] [--repeats 15]

Every command opens the DuckDB file for each block it reads or writes; a new database
also gets its migrations. Each worker process (alternating: the baseline's `suds_exp`,
exported with `git archive`, then the working tree's; both read the working tree's
``migrations/`` through ``$SUDS_MIGRATIONS``) times, ``--repeats`` times each:

- ``new database``: `Store.upgrade` on a path where no file is (every migration applied);
- ``first write``: a new `Store` on an existing, migrated file and one empty write block
  (what a writing command does first);
- ``read``: a new `Store` and ``query_df("SELECT 1")`` (a reading command's block);

and prints their medians in milliseconds, with a digest of the schema a new database gets
(every table's columns and types, and the recorded migrations without their time), so the
table says whether both sides create the same database. ``--quick``: baseline HEAD, one
round of two repeats (a smoke run, no figure).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import sys
import tempfile
import time
from pathlib import Path
from statistics import median

from benchmarks._harness import ROOT, alternate, comparison_parser, same, worker

CASES = ("new database", "first write", "read")


def _schema_digest(path: Path) -> str:
    from suds_exp.store import Store

    store = Store(path)
    columns = store.query_df(
        "SELECT table_name, column_name, data_type FROM information_schema.columns ORDER BY ALL"
    )
    applied = store.query_df("SELECT version, name, checksum FROM schema_migrations ORDER BY 1")
    text = columns.to_csv(index=False) + applied.to_csv(index=False)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def measure(repeats: int) -> dict:
    """Median milliseconds of each of `CASES` in this process, and the schema digest."""
    from suds_exp.store import Store

    times: dict[str, list[float]] = {case: [] for case in CASES}
    with tempfile.TemporaryDirectory(prefix="suds-store-open-") as tmp:
        existing = Path(tmp) / "existing.duckdb"
        Store(existing).upgrade()
        for i in range(repeats):
            t0 = time.perf_counter()
            Store(Path(tmp) / f"new-{i}.duckdb").upgrade()
            t1 = time.perf_counter()
            with Store(existing).write():
                pass
            t2 = time.perf_counter()
            Store(existing).query_df("SELECT 1")
            t3 = time.perf_counter()
            for case, dt in zip(CASES, (t1 - t0, t2 - t1, t3 - t2), strict=True):
                times[case].append(1000 * dt)
        digest = _schema_digest(Path(tmp) / "new-0.duckdb")
    import suds_exp

    return {case: median(v) for case, v in times.items()} | {
        "digest": digest,
        "suds_exp": suds_exp.__file__,
    }


def _run(tree: Path, repeats: int) -> dict:
    migrations = str(ROOT / "migrations")
    return worker(tree, __spec__.name, "--repeats", str(repeats), SUDS_MIGRATIONS=migrations)


def main(argv: list[str] | None = None) -> int:
    ap = comparison_parser(__doc__.splitlines()[0], "b16e0d5", 3)
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.quick:
        a.baseline, a.rounds, a.repeats = "HEAD", 1, 2
    if a.worker:
        print(json.dumps(measure(a.repeats)))
        return 0
    base, now = alternate(a.baseline, a.rounds, lambda path: _run(path, a.repeats))
    print(
        f"## Opening the database, {a.rounds} rounds x {a.repeats} repeats alternating; "
        f"baseline {a.baseline}, now = working tree; load average {os.getloadavg()[0]:.2f}"
    )
    print("| block | baseline ms | now ms | speed-up |")
    print("|---|---|---|---|")
    for case in CASES:
        b, n = median(r[case] for r in base), median(r[case] for r in now)
        print(f"| {case} | {b:.1f} | {n:.1f} | {b / n:.2f}x |")
    identical = same(r["digest"] for r in base + now)
    print(f"\nschema of a new database: {'identical' if identical else 'DIFFERS'}")
    return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
