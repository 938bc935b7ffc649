"""Ingest speed: QTM TSV files of the default dataset's size into a fresh database.

Prints the median wall time (over repeats) of `ingest_paths` on N files of F frames x
11 markers, and, as the baseline measured in the same run, the time a bare
``pandas.read_csv`` takes just to parse the same files (no validation, no database).

    .venv/bin/python -m benchmarks.speed.ingest [--files 60] [--frames 4000] [--repeats 3]

``--quick``: 2 files of 200 frames, once (a smoke run, no figure). The QTM text comes
from `suds_exp.testing.synthetic_captures` (random tracks with no truth to keep).
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

import pandas as pd

from benchmarks._harness import script_parser
from suds_exp.ingest import ROLES, ingest_paths
from suds_exp.store import Store
from suds_exp.testing.synthetic_captures import qtm_text, random_track


def main(argv=None) -> None:
    parser = script_parser(__doc__.splitlines()[0])
    parser.add_argument("--files", type=int, default=60)
    parser.add_argument("--frames", type=int, default=4000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    if args.quick:
        args.files, args.frames, args.repeats = 2, 200, 1
    with tempfile.TemporaryDirectory(prefix="suds-ingest-bench-") as tmp:
        measure(Path(tmp), args)


def measure(folder: Path, args) -> None:
    files = []
    for i in range(args.files):
        path = folder / f"t{i:03d}.tsv"
        path.write_text(
            qtm_text(list(ROLES), random_track(args.frames, len(ROLES), seed=i)), newline=""
        )
        files.append(path)
    size = sum(p.stat().st_size for p in files) / 1e6

    ours, baseline = [], []
    for r in range(args.repeats):
        store = Store(folder / f"bench{r}.duckdb")
        store.upgrade()
        t0 = time.perf_counter()
        ingest_paths(store, files, progress=False)
        ours.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        for path in files:
            pd.read_csv(path, sep="\t", skiprows=11)
        baseline.append(time.perf_counter() - t0)
    o, b = statistics.median(ours), statistics.median(baseline)
    rows = args.files * args.frames * len(ROLES)
    print(f"{args.files} files x {args.frames} frames x {len(ROLES)} markers ({size:.0f} MB)")
    rate = rows / o / 1e6
    print(f"ingest_paths (parse, validate, store): median {o:.2f} s ({rate:.2f} M rows/s)")
    print(f"pandas.read_csv parse only (baseline): median {b:.2f} s")
    print(f"ratio ingest / bare parse: {o / b:.2f}x")


if __name__ == "__main__":
    main()
