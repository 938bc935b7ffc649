"""The demo's heavy steps against a baseline commit, same machine, same run.

Usage (from the repository root)::

    .venv/bin/python -m benchmarks.speed.demo_speed [--baseline 3454561] [--rounds 3]
        [--steps simulate discrepancy] [--quick]

The baseline's `suds_exp` is exported from git (`git archive`) into a temporary folder
and its simulator kernels compiled there first (not timed). Rounds alternate a worker
process on the baseline and one on the working tree (A B A B ...), so a change in the
machine's load hits both. Each worker runs one step of `suds-exp demo`:

- ``simulate``: the demo's dataset (`simulate_dataset`, the paper's design, seed 0) into a
  temporary folder;
- ``discrepancy``: the demo's last act (`demo_discrepancy`, body_inertia hidden, seed 0:
  simulate, ingest, preprocess, then the discrepancy workflow with its report).

and reports its CPU seconds (user + sys of every thread of the process), its wall seconds
and a sha256 of what it produced (the simulated files; the workflow's result without its
timings), so the table says whether the working tree's output is identical to the
baseline's. Wall seconds are only meaningful on an idle machine; CPU seconds are not
lowered by running on more threads (the simulator's trials run in parallel), wall is.

``--baseline`` may also be a folder (a checkout). ``--quick``: the working tree against
itself, one round of ``simulate`` on a one-trial design of 2 cycles (a smoke run).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile
import time
from pathlib import Path
from statistics import median

from benchmarks._harness import ROOT, baseline_tree, run_in, same, script_parser, speedup, worker

STEPS = ("simulate", "discrepancy")
#: ``--quick``'s design: one trial of two cycles.
QUICK_DESIGN = {"gaits": ("O",), "frequencies_hz": (1.0,), "repeats": 1, "cycles": (2, 2)}


def _simulate(tmp: Path, quick: bool = False) -> str:
    from suds_exp.sim import simulate_dataset

    simulate_dataset(tmp, seed=0, progress=False, **(QUICK_DESIGN if quick else {}))
    h = hashlib.sha256()
    for path in sorted(tmp.rglob("*")):
        if path.is_file():
            h.update(path.name.encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _discrepancy(tmp: Path, quick: bool = False) -> str:
    from suds_exp.workflows.hidden_effects import demo_discrepancy

    found = demo_discrepancy(effect="body_inertia", seed=0, out=tmp / "report")
    found.pop("seconds", None)
    return hashlib.sha256(json.dumps(found, default=repr, sort_keys=True).encode()).hexdigest()[:16]


def measure(step: str, quick: bool = False) -> dict:
    """{cpu, wall, digest, threads, suds_exp} of one run of ``step`` in this process."""
    import numba

    import suds_exp

    run = {"simulate": _simulate, "discrepancy": _discrepancy}[step]
    with tempfile.TemporaryDirectory(prefix="suds-demo-speed-") as tmp:
        c0, w0 = time.process_time(), time.perf_counter()
        digest = run(Path(tmp), quick)
        cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    return {
        "cpu": cpu,
        "wall": wall,
        "digest": digest,
        "threads": numba.get_num_threads(),
        "suds_exp": suds_exp.__file__,
    }


def main(argv=None) -> int:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="3454561")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--steps", nargs="+", choices=STEPS, default=list(STEPS))
    ap.add_argument("--worker", choices=STEPS, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker:
        print(json.dumps(measure(a.worker, a.quick)))
        return 0
    if a.quick:
        a.baseline, a.rounds, a.steps = str(ROOT), 1, ["simulate"]
    quick = ["--quick"] if a.quick else []
    with baseline_tree(a.baseline) as tree:
        run_in(tree, "-m", "suds_exp.sim.precompile")  # its kernels' compile, untimed
        run_in(ROOT, "-m", "suds_exp.sim.precompile")
        runs: dict[str, tuple[list, list]] = {}
        for step in a.steps:
            base, now = runs.setdefault(step, ([], []))
            for _ in range(a.rounds):
                base.append(worker(tree, __spec__.name, step, *quick))
                now.append(worker(ROOT, __spec__.name, step, *quick))
    first = next(iter(runs.values()))
    print(
        f"## Demo steps, {a.rounds} rounds alternating; baseline {a.baseline} "
        f"({first[0][0]['suds_exp']}), now = working tree ({first[1][0]['suds_exp']}), "
        f"{first[1][0]['threads']} numba threads"
    )
    print(
        "| step | baseline CPU s | now CPU s | baseline wall s | now wall s "
        "| wall speed-up (median [min, max]) | output |"
    )
    print("|---|---|---|---|---|---|---|")
    for step, (base, now) in runs.items():
        identical = same(r["digest"] for r in base + now)
        wall = speedup((r["wall"] for r in base), (r["wall"] for r in now))
        print(
            f"| {step} | {median(r['cpu'] for r in base):.1f} | "
            f"{median(r['cpu'] for r in now):.1f} | {median(r['wall'] for r in base):.1f} | "
            f"{median(r['wall'] for r in now):.1f} | {wall} "
            f"| {'identical' if identical else 'DIFFER'} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
