"""Time and peak memory of the analysis and bookkeeping commands against campaign size.

Usage::

    .venv/bin/python -m benchmarks.speed.scale --sizes 0.1,1,5,10 --folder /tmp/scale [--rounds 3]

For each size (millions of results) a database is built once in ``--folder`` (kept and
reused by later runs): a finished campaign ``scale`` of the paper's grid (15 x 15
conditions, the five learners, 30 training cycles, ``ceil(rows / 1125)`` draws a pair),
whose rows come from the project's generator (`suds_exp.testing.synthetic_results`, in
slices of draws, each slice its own seed) and whose definition is stored by
`run_campaign` on synthetic-swimmer samples of the same 15 conditions (so a re-run is a
real resume that finds nothing left).

Then each command runs in its own process, ``--rounds`` times, and its wall time, CPU
time (user + system, every thread: less sensitive than wall time to a shared machine's
load) and peak resident memory (the process's ru_maxrss) are recorded:

- ``report``: ``suds-exp report scale --out DIR`` (its default bootstrap);
- ``findings``: ``suds-exp findings scale --boots B`` (``--findings-boots``, default 400);
- ``status``: ``suds-exp status scale``;
- ``sql``: ``suds-exp sql`` of a count by learner;
- ``resume``: `run_campaign` on the finished campaign (Python API: the samples are the
  benchmark's, not a stored preprocessing version), timed around the call; its peak
  includes the process's samples.

It prints medians per size and the growth exponent of time and of memory between
consecutive sizes (log(t2/t1) / log(n2/n1); 1 is linear, 0 flat). ``--json`` writes the
figures as one JSON document. ``--quick``: one round at 0.001M results in a new temporary
folder, the findings with 20 replicates (a smoke run, no figure).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks._data import paper_like_samples
from benchmarks._harness import ROOT, script_parser

CAMPAIGN = "scale"
PAIRS_X_LEARNERS = 15 * 15 * 5
#: Draws generated and inserted at a time (about 450k rows).
SLICE_BOOTS = 400
COMMANDS = ("report", "findings", "status", "sql", "resume")


def scale_samples():
    """Synthetic-swimmer samples of the 15 paper conditions (`benchmarks._data`)."""
    return paper_like_samples()


def options(boots: int):
    from suds_exp.campaign import CampaignOptions
    from suds_exp.models.registry import LEARNERS

    return CampaignOptions(models=list(LEARNERS), boots=boots, train_cycles=30)


def build(path: Path, rows: int) -> int:
    """A database at ``path`` with the finished campaign ``scale`` of about ``rows``
    results; returns its number of rows."""
    from suds_exp.campaign import run_campaign
    from suds_exp.store import Store
    from suds_exp.testing.synthetic_results import synthetic_results

    boots = max(1, math.ceil(rows / PAIRS_X_LEARNERS))
    partial = path.with_suffix(".part.duckdb")
    partial.unlink(missing_ok=True)
    store = Store(partial)
    store.upgrade()
    for start in range(0, boots, SLICE_BOOTS):
        n = min(SLICE_BOOTS, boots - start)
        frame = synthetic_results(CAMPAIGN, n_boot=n, n_cycles=(30,), seed=start)
        frame["boot"] += start
        with store.write() as conn:
            store.insert_df(conn, "results", frame)
        print(f"  {path.name}: {start + n} / {boots} draws", file=sys.stderr)
    summary = run_campaign(store, CAMPAIGN, options(boots), samples=scale_samples(), progress=False)
    if summary.remaining or summary.done_now:
        raise SystemExit(f"{path}: the synthetic rows are not the campaign's grid: {summary}")
    partial.rename(path)
    return summary.total_jobs


def resume_worker(db: Path) -> dict:
    from suds_exp.campaign import run_campaign
    from suds_exp.store import Store

    samples = scale_samples()
    t0, c0 = time.perf_counter(), time.process_time()
    summary = run_campaign(Store(db), CAMPAIGN, samples=samples, progress=False)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    assert summary.remaining == 0 and summary.done_now == 0, summary
    return {"seconds": seconds, "cpu_s": cpu, "jobs": summary.total_jobs}


def command(name: str, db: Path, out: Path, findings_boots: int) -> list[str]:
    cli = [sys.executable, "-m", "suds_exp"]
    if name == "report":
        return [*cli, "report", CAMPAIGN, "--out", str(out), "--db", str(db)]
    if name == "findings":
        return [*cli, "findings", CAMPAIGN, "--boots", str(findings_boots), "--db", str(db)]
    if name == "status":
        return [*cli, "status", CAMPAIGN, "--db", str(db)]
    if name == "sql":
        query = "SELECT model, count(*), avg(rmse_vx) FROM results GROUP BY model"
        return [*cli, "sql", query, "--db", str(db)]
    return [sys.executable, "-m", __spec__.name, "--resume-worker", str(db)]


def run_measured(argv: list[str]) -> dict:
    """`measure` with the child's own ru_maxrss: Popen reaps the child, so the peak is
    read from a wrapper that reports it."""
    wrapped = [sys.executable, "-m", __spec__.name, "--measure", json.dumps(argv)]
    out = subprocess.run(wrapped, capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"{' '.join(argv)} failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.splitlines()[-1])


def measure_child(argv: list[str]) -> dict:
    """Wall seconds and peak RSS (MB) of the process ``argv``, run as this process's
    only child (for the resume worker, seconds of the `run_campaign` call alone)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out, err = proc.communicate()
    wall = time.perf_counter() - t0
    if proc.returncode:
        sys.stderr.write(err.decode(errors="replace")[-3000:])
        raise SystemExit(proc.returncode)
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    peak = usage.ru_maxrss / 1024
    # CPU time (all threads) says less about the machine's load than wall time
    figures = {"seconds": wall, "cpu_s": usage.ru_utime + usage.ru_stime, "peak_mb": peak}
    if "--resume-worker" in argv:
        figures.update(json.loads(out.decode().splitlines()[-1]))
    return figures


def exponent(n1: float, v1: float, n2: float, v2: float) -> float:
    return math.log(v2 / v1) / math.log(n2 / n1)


def main(argv=None) -> int:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="0.1,1,5,10", help="millions of results, comma-separated")
    ap.add_argument("--folder", type=Path, default=Path(tempfile.gettempdir()) / "suds_scale")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--commands", default=",".join(COMMANDS))
    ap.add_argument("--findings-boots", type=int, default=400)
    ap.add_argument("--json", type=Path, default=None, help="also write the figures here")
    ap.add_argument("--resume-worker", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--measure", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.resume_worker:
        print(json.dumps(resume_worker(a.resume_worker)))
        return 0
    if a.measure:
        print(json.dumps(measure_child(json.loads(a.measure))))
        return 0

    if a.quick:
        a.sizes, a.rounds, a.findings_boots = "0.001", 1, 20
        a.folder = Path(tempfile.mkdtemp(prefix="suds_scale_quick_"))
    # the commands' processes import this PYTHONPATH's suds_exp (this tree's by default),
    # the measuring wrapper this tree's benchmarks
    paths = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    os.environ["PYTHONPATH"] = os.pathsep.join(
        [*paths, str(ROOT)] if str(ROOT) not in paths else paths
    )
    a.folder.mkdir(parents=True, exist_ok=True)
    sizes = [float(s) for s in a.sizes.split(",")]
    commands = a.commands.split(",")
    table: dict = {}
    for size in sizes:
        db = a.folder / f"scale_{size:g}M.duckdb"
        if not db.exists():
            t0 = time.perf_counter()
            rows = build(db, int(size * 1e6))
            print(
                f"built {db} ({rows:,} results) in {time.perf_counter() - t0:.0f} s",
                file=sys.stderr,
            )
        table[size] = {}
        for name in commands:
            runs = []
            for _ in range(a.rounds):
                out = a.folder / f"report_{size:g}M"
                figures = run_measured(command(name, db, out, a.findings_boots))
                runs.append(figures)
                print(
                    f"  {size:g}M {name}: {figures['seconds']:.1f} s "
                    f"(CPU {figures['cpu_s']:.1f} s), {figures['peak_mb']:.0f} MB",
                    file=sys.stderr,
                )
            table[size][name] = {
                "seconds": statistics.median(r["seconds"] for r in runs),
                "cpu_s": statistics.median(r["cpu_s"] for r in runs),
                "peak_mb": statistics.median(r["peak_mb"] for r in runs),
                "runs": runs,
            }
    print(f"medians of {a.rounds} rounds; time in s, peak RSS in MB")
    print(f"{'command':10}" + "".join(f"{s:>16g}M" for s in sizes) + "   exponents (time; memory)")
    for name in commands:
        cells = "".join(
            f"{table[s][name]['seconds']:8.1f} {table[s][name]['peak_mb']:7.0f}" + " " * 1
            for s in sizes
        )
        exps = []
        for s1, s2 in zip(sizes, sizes[1:], strict=False):
            f1, f2 = table[s1][name], table[s2][name]
            exps.append(
                f"{s1:g}->{s2:g}M {exponent(s1, f1['seconds'], s2, f2['seconds']):.2f}; "
                f"{exponent(s1, f1['peak_mb'], s2, f2['peak_mb']):.2f}"
            )
        print(f"{name:10}{cells}   " + ", ".join(exps))
    if a.json:
        a.json.write_text(json.dumps({str(k): v for k, v in table.items()}, indent=1))
    if a.quick:
        shutil.rmtree(a.folder)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
