"""`suds-exp gait design` against a baseline commit, same machine, same run, same outputs.

Usage (from the repository root)::

    .venv/bin/python -m benchmarks.speed.gait_design_speed [--baseline 650de56] [--rounds 3]
        [--cases "GMR verify" GMR "GMR+SUDS verify"] [--quick]

The baseline's `suds_exp` and `cli.py` are exported from git (`git archive`) into a
temporary folder and its simulator kernels compiled there first (not timed). Rounds
alternate the baseline and the working tree (each round: every case's worker process on
the baseline, then on the working tree), so a change in the machine's load hits both.
Each worker, in its own code:

- builds the small dataset of `tests/test_gait_design.py` (``suds-exp simulate --gaits
  O,D+ --freqs 1/2 --repeats 2 --cycles 6 --ingest``, then ``preprocess``; not timed);
- runs ``suds-exp gait design --bound 1.3 --iterations 2 --order 1 --json`` with the
  case's learner, with or without ``--verify`` (in-process, through the CLI's runner:
  the command less the interpreter's start), timed in wall and CPU seconds;
- hashes what the design produced: the JSON it printed and the stored rows of
  ``gait_designs`` and ``gait_design_iterations`` (every column at full precision but
  the timings), so the table says whether the working tree's designed gaits,
  predicted and achieved motions and stored iterations are identical to the baseline's.

Exit status 1 if any case's outputs differ (the check that results did not drift).
``--baseline`` may also be a folder (a checkout). ``--quick``: the working tree against
itself, one round of the ``GMR`` case (a smoke run).
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

from benchmarks._harness import ROOT, alternate, comparison_parser, run_in, same, speedup, worker

#: The design's options beside the learner and --verify (the default test's design).
DESIGN = ["--bound", "1.3", "--iterations", "2", "--order", "1"]
CASES = {
    "GMR verify": ["--model", "GMR", "--verify"],
    "GMR": ["--model", "GMR"],
    "GMR+SUDS verify": ["--model", "GMR+SUDS", "--verify"],
    "GMR+SUDS": ["--model", "GMR+SUDS"],
}
DEFAULT_CASES = ("GMR verify", "GMR", "GMR+SUDS verify")
#: Timings, which differ run to run: left out of the digest.
TIMING_KEYS = ("seconds", "created_at")


def _invoke(app, args: list[str]) -> str:
    from typer.testing import CliRunner

    r = CliRunner().invoke(app, args)
    if r.exit_code != 0:
        raise SystemExit(f"suds-exp {' '.join(args)}: exit {r.exit_code}\n{r.output}")
    return r.stdout


def _strip_timings(value):
    if isinstance(value, dict):
        return {k: _strip_timings(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [_strip_timings(v) for v in value]
    return value


def _digest(printed: str, db: Path) -> str:
    """sha256 of the printed JSON and the stored design rows, timings left out."""
    import numpy as np

    from suds_exp.store import Store

    h = hashlib.sha256(json.dumps(_strip_timings(json.loads(printed)), sort_keys=True).encode())
    store = Store(db)
    for table in ("gait_designs", "gait_design_iterations"):
        frame = store.query_df(f"SELECT * FROM {table} ORDER BY ALL")
        for col in frame.columns:
            if col in TIMING_KEYS:
                continue
            values = frame[col].to_numpy()
            h.update(col.encode())
            if values.dtype.kind == "f":
                h.update(np.ascontiguousarray(values, dtype=float).tobytes())
            else:
                h.update(repr(values.tolist()).encode())
    return h.hexdigest()[:16]


def measure(case: str) -> dict:
    """{wall, cpu, digest, suds_exp} of one design of ``case`` in this process."""
    import suds_exp
    from cli import app

    with tempfile.TemporaryDirectory(prefix="suds-gait-design-") as tmp:
        db = Path(tmp) / "small.duckdb"
        _invoke(
            app,
            [
                *("simulate", "--out", str(Path(tmp) / "d"), "--gaits", "O,D+", "--freqs"),
                *("1/2", "--repeats", "2", "--cycles", "6", "--ingest", "--db", str(db), "-q"),
            ],
        )
        _invoke(app, ["preprocess", "--db", str(db), "-q"])
        args = ["gait", "design", *DESIGN, *CASES[case], "--out", str(Path(tmp) / "out")]
        c0, w0 = time.process_time(), time.perf_counter()
        printed = _invoke(app, [*args, "--db", str(db), "--json"])
        cpu, wall = time.process_time() - c0, time.perf_counter() - w0
        digest = _digest(printed.replace(tmp, "<tmp>"), db)  # the report's path
    return {"cpu": cpu, "wall": wall, "digest": digest, "suds_exp": suds_exp.__file__}


def _runner(cases: list[str]):
    """``run(tree)`` for `alternate`: every case's worker on ``tree``; a baseline's kernels
    are compiled on its first use, untimed."""

    compiled = {ROOT}

    def run(tree: Path) -> dict:
        if tree not in compiled:
            run_in(tree, "-m", "suds_exp.sim.precompile")
            compiled.add(tree)
        return {case: worker(tree, __spec__.name, case) for case in cases}

    return run


def main(argv=None) -> int:
    ap = comparison_parser(__doc__.splitlines()[0], "650de56", 3)
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(DEFAULT_CASES))
    ap.add_argument("--worker", choices=list(CASES), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker:
        print(json.dumps(measure(a.worker)))
        return 0
    if a.quick:
        a.baseline, a.rounds, a.cases = str(ROOT), 1, ["GMR"]
    run_in(ROOT, "-m", "suds_exp.sim.precompile")  # the kernels' compile, untimed
    base, now = alternate(a.baseline, a.rounds, _runner(a.cases))
    runs = {case: ([r[case] for r in base], [r[case] for r in now]) for case in a.cases}
    first = runs[a.cases[0]]
    print(
        f"## suds-exp gait design {' '.join(DESIGN)}, {a.rounds} rounds alternating; "
        f"baseline {a.baseline} ({first[0][0]['suds_exp']}), now = working tree "
        f"({first[1][0]['suds_exp']}); load average {os.getloadavg()[0]:.2f} at the end"
    )
    print(
        "| case | baseline wall s | now wall s | baseline CPU s | now CPU s "
        "| wall speed-up (median [min, max]) | outputs |"
    )
    print("|---|---|---|---|---|---|---|")
    drift = False
    for case, (base, now) in runs.items():
        identical = same(r["digest"] for r in base + now)
        drift |= not identical
        print(
            f"| {case} | {median(r['wall'] for r in base):.2f} | "
            f"{median(r['wall'] for r in now):.2f} | {median(r['cpu'] for r in base):.2f} | "
            f"{median(r['cpu'] for r in now):.2f} | "
            f"{speedup((b['wall'] for b in base), (n['wall'] for n in now))} | "
            f"{'identical (' + base[0]['digest'] + ')' if identical else 'DIFFER'} |"
        )
    return 1 if drift else 0


if __name__ == "__main__":
    sys.exit(main())
