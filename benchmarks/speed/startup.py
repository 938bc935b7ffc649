"""Start-up time of the small commands against a baseline commit, in the same run.

Usage::

    .venv/bin/python -m benchmarks.speed.startup --baseline bc6c20e --repeats 5

Each command (``--version``, ``--help``, ``trials``, ``sql``, ``status``, on a small
database: one simulated trial, preprocessed, a 10-job campaign) runs as a whole
``python -m suds_exp`` process, ``--repeats`` times, alternating between an export of
``--baseline`` and the working tree; the table gives each side's median wall time.
``--quick``: ``--version`` and ``trials`` once each against HEAD (a smoke run).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from statistics import median

from benchmarks._harness import ROOT, alternate, comparison_parser

COMMANDS = {
    "--version": ["--version"],
    "--help": ["--help"],
    "trials": ["trials"],
    "sql": ["sql", "SELECT count(*) AS n FROM samples"],
    "status": ["status", "c"],
}


def _time(path: Path, args: list[str], db: Path) -> float:
    # -P and the tree alone on the path: the start-up of the command, nothing of benchmarks/
    env = dict(os.environ, PYTHONPATH=str(path), SUDS_DB=str(db))
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, "-P", "-m", "suds_exp", *args],
        env=env,
        cwd=path,
        check=True,
        capture_output=True,
    )
    return time.perf_counter() - started


def _database(folder: Path) -> Path:
    db = folder / "small.duckdb"
    suds = [sys.executable, "-m", "suds_exp"]
    env = dict(os.environ, SUDS_DB=str(db))
    for args in (
        ["simulate", "--out", str(folder / "sim"), "--gaits", "O", "--freqs", "1/2",
         "--repeats", "2", "--cycles", "3", "--ingest", "-q"],
        ["preprocess", "-q"],
        ["run", "c", "--models", "phase-only", "--boots", "2", "--train-cycles", "2", "-q"],
    ):  # fmt: skip
        subprocess.run([*suds, *args], env=env, check=True, capture_output=True, cwd=ROOT)
    return db


def main(argv=None) -> int:
    ap = comparison_parser(__doc__.splitlines()[0], "HEAD", 5, rounds_flag="--repeats")
    a = ap.parse_args(argv)
    commands = COMMANDS
    if a.quick:
        a.baseline, a.repeats = "HEAD", 1
        commands = {k: COMMANDS[k] for k in ("--version", "trials")}

    with tempfile.TemporaryDirectory(prefix="suds-startup-") as tmp:
        db = _database(Path(tmp))

        def run(path: Path) -> dict[str, float]:
            return {name: _time(path, args, db) for name, args in commands.items()}

        base, now = alternate(a.baseline, a.repeats, run)
    print(f"median wall seconds of {a.repeats} runs each (python -m suds_exp ...)")
    print(f"{'command':10} {a.baseline:>10} {'tree':>8}")
    for name in commands:
        b, n = median(r[name] for r in base), median(r[name] for r in now)
        print(f"{name:10} {b:10.2f} {n:8.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
