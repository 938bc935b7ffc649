"""A campaign's CPU cost per job against a baseline commit, and its results compared.

Usage (from the repository root)::

    .venv/bin/python -m benchmarks.speed.campaign_cost [--baseline 3454561] [--rounds 3]
        [--boots 1] [--sweep 1,4,16,30,48] [--writes N] [--quick]

The baseline's `suds_exp` is exported from git (`git archive`) into a temporary folder;
rounds alternate a worker process on the baseline and one on the working tree (A B A B
...), so a change in the machine's load hits both. CPU time, not wall time: the machine
this was written on is shared, and CPU seconds of a single-threaded process (BLAS on
one thread, as a campaign's workers run) do not depend much on how many others run.

Each worker, on the campaign benchmarks' synthetic data (`benchmarks._data`: 5
gaits x 3 frequencies x 4 trials, 100 samples a cycle), runs in-process (``jobs=1``):

1. the small grid of `benchmarks._data` (O@1/3, O@1, D+@0.5, S-@1, train x test,
   the paper's five learners, ``--boots`` draws, 30 training cycles and the ``--sweep``
   sizes on the same-condition pairs) as a campaign on a new database: process CPU s;
2. the same call again with every job done: the fixed cost a run pays once (lock,
   definition, bank, finished keys, run record);
3. the same jobs' make_model + fit + predict in a bare loop on frames built beforehand:
   the learners' own CPU s.

``--writes N``: instead, the CPU and wall seconds of one batch write of the runner
(``BATCH_ROWS`` = 500 rows into `results`, one transaction) into a table that grows by a
batch each time, median of N writes, on the working tree only.

Framework CPU per job = (1 - 2 - 3) / jobs; learners' CPU per job = 3 / jobs. The results
table of each run is reduced to a sha256 of its rows (key columns and the three RMSEs,
sorted; timing columns left out): "identical" means every worker on both sides wrote the
same table bit for bit. Medians over rounds.

``--quick``: a smoke run (baseline HEAD, one round, 8-cycle trials, 5 training cycles, no
sweep, two learners); its figures mean nothing.
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

from benchmarks import _data
from benchmarks._harness import alternate, comparison_parser, same, worker

#: A smoke run's sizes: trial cycles, training cycles, learners.
QUICK = (8, 5, ["phase-only", "TLS"])


def measure(boots: int, sweep: list[int], quick: bool = False) -> dict:
    """CPU seconds of the three steps and the results table's digest, in this process."""
    from threadpoolctl import threadpool_limits

    import suds_exp
    from suds_exp.campaign import CampaignOptions, run_campaign
    from suds_exp.campaign.definition import resolve_models
    from suds_exp.models import make_model
    from suds_exp.models.registry import LEARNERS

    trial_cycles, cycles, learners = QUICK if quick else (25, _data.CYCLES, list(LEARNERS))
    samples = _data.paper_like_samples(n_cycles=trial_cycles)
    options = CampaignOptions(
        models=learners,
        boots=boots,
        train_cycles=cycles,
        train_conditions=_data.SMALL,
        test_conditions=_data.SMALL,
        sweep=sweep,
    )
    out = {"suds_exp": suds_exp.__file__}
    with tempfile.TemporaryDirectory() as folder:
        store = _data.fresh_store(Path(folder), "cost")
        c0 = time.process_time()
        s = run_campaign(store, "bench", options, samples=samples, jobs=1, progress=False)
        out["campaign_cpu"] = time.process_time() - c0
        assert s.failed_now == 0, s
        out["jobs"] = s.done_now
        c0 = time.process_time()
        run_campaign(store, "bench", samples=samples, jobs=1, progress=False)
        out["fixed_cpu"] = time.process_time() - c0
        rows = store.query_df(
            "SELECT campaign, train_gait, train_frequency_hz, test_gait, test_frequency_hz, "
            "boot, n_cycles, model, train_ranges, test_range, rmse_vx, rmse_vy, rmse_wz, "
            "n_test, error FROM results ORDER BY ALL"
        )
        out["results_sha"] = hashlib.sha256(
            rows.to_csv(index=False, float_format="%.17g").encode()
        ).hexdigest()[:16]
        out["rmse_vx_sum"] = float(rows["rmse_vx"].sum())
    models = resolve_models(learners, "measured")
    jobs = _data.small_grid_jobs(samples, boots, cycles, sweep)
    c0 = time.process_time()
    with threadpool_limits(limits=1):
        for train, test in jobs:
            for name, params in models.items():
                make_model(name, **params).fit(train).predict(test)
    out["learners_cpu"] = time.process_time() - c0
    assert len(jobs) * len(models) == out["jobs"], (len(jobs), out["jobs"])
    return out


def write_cost(n_writes: int) -> str:
    """Median CPU and wall seconds of one 500-row batch write, as the runner makes it."""
    import pandas as pd

    from suds_exp.campaign import CampaignOptions, run_campaign
    from suds_exp.campaign.runner import BATCH_ROWS
    from suds_exp.models.registry import LEARNERS

    with tempfile.TemporaryDirectory() as folder:
        store = _data.fresh_store(Path(folder), "writes")
        samples = _data.paper_like_samples()
        small = CampaignOptions(
            models=list(LEARNERS),
            boots=_data.BOOTS,
            train_cycles=_data.CYCLES,
            train_conditions=_data.SMALL,
            test_conditions=_data.SMALL,
        )
        run_campaign(store, "bench", small, samples=samples, progress=False)
        rows = store.query_df("SELECT * FROM results")
        copies = -(-BATCH_ROWS // len(rows))
        batch = pd.concat([rows.assign(boot=rows.boot + 100 * i) for i in range(copies)])
        batch = batch.iloc[:BATCH_ROWS].reset_index(drop=True)
        cpu, wall = [], []
        for k in range(n_writes):
            b = batch.assign(campaign=f"writes-{k}")
            c0, t0 = time.process_time(), time.perf_counter()
            with store.write() as conn:
                store.insert_df(conn, "results", b)
            cpu.append(time.process_time() - c0)
            wall.append(time.perf_counter() - t0)
        total = int(store.query_df("SELECT count(*) AS n FROM results").n[0])
    return (
        f"one {BATCH_ROWS}-row write of `results` (table growing to {total} rows): "
        f"{median(cpu):.4f} CPU s, {median(wall):.4f} wall s (medians of {n_writes})"
    )


def _run(tree: Path, a) -> dict:
    args = ["--boots", str(a.boots), "--sweep", a.sweep] + (["--quick"] if a.quick else [])
    return worker(tree, __spec__.name, *args, OMP_NUM_THREADS="1")


def _figures(r: dict) -> dict:
    n = r["jobs"]
    return {
        "total ms/job": 1e3 * (r["campaign_cpu"] - r["fixed_cpu"]) / n,
        "learners ms/job": 1e3 * r["learners_cpu"] / n,
        "framework ms/job": 1e3 * (r["campaign_cpu"] - r["fixed_cpu"] - r["learners_cpu"]) / n,
        "fixed s": r["fixed_cpu"],
    }


def main(argv=None) -> int:
    ap = comparison_parser(__doc__.splitlines()[0], "3454561", 3)
    ap.add_argument("--boots", type=int, default=1)
    ap.add_argument("--sweep", default="1,4,16,30,48")
    ap.add_argument("--writes", type=int, default=0, help="time N batch writes instead")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.quick and not a.worker:
        a.baseline, a.rounds, a.sweep = "HEAD", 1, ""
    if a.writes:
        print(write_cost(a.writes))
        return 0
    sweep = [int(x) for x in a.sweep.split(",") if x]
    if a.worker:
        print(json.dumps(measure(a.boots, sweep, a.quick)))
        return 0
    base, now = alternate(a.baseline, a.rounds, lambda path: _run(path, a))
    n = base[0]["jobs"]
    print(
        f"## Campaign CPU per job, small grid ({n} jobs: {a.boots} draw(s), sweep {a.sweep}), "
        f"in-process, {a.rounds} rounds; baseline {a.baseline}, now = working tree"
    )
    print(f"baseline from {base[0]['suds_exp']}, now from {now[0]['suds_exp']}")
    print("| figure | baseline | now | baseline / now (median [min, max]) |")
    print("|---|---|---|---|")
    fb, fn = [_figures(r) for r in base], [_figures(r) for r in now]
    for key in fb[0]:
        b, m = [f[key] for f in fb], [f[key] for f in fn]
        ratios = sorted(x / y for x, y in zip(b, m, strict=True) if y > 0)
        spread = f"{median(ratios):.2f}x [{ratios[0]:.2f}, {ratios[-1]:.2f}]" if ratios else "-"
        print(f"| {key} | {median(b):.2f} | {median(m):.2f} | {spread} |")
    share = [f["framework ms/job"] / f["learners ms/job"] for f in fn]
    print(f"framework / learners, now: {100 * median(share):.1f} % (median of the rounds)")
    digests = [r["results_sha"] for r in base + now]
    print(
        "results table: "
        + ("identical" if same(digests) else f"DIFFER ({sorted(set(digests))})")
        + f" in all {len(base) + len(now)} runs (sha256 of the sorted rows, timing left out; "
        f"sum of rmse_vx {now[0]['rmse_vx_sum']!r})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
