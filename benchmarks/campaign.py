"""Campaign benchmarks: framework overhead, 2-worker speed-up, resume time with 100k
finished jobs, projected paper-scale time and peak memory.

Usage::

    .venv/bin/python benchmarks/campaign.py [--repeats 3] [--no-projection] [--json]

Data: the models' synthetic swimmer (`suds_exp.models.synthetic.make_samples`), 5 gaits
x 3 frequencies x 4 trials x 25 cycles captured at 100 Hz, so after decimation every
cycle has 100 samples as in the paper's data. Figures:

- overhead: wall time of `run_campaign` (in-process, fresh database: definition, sample
  bank, sampling, frames, database writes) over the time of the same jobs' make_model +
  fit + predict in a bare loop on frames built beforehand; 4 conditions, 16 pairs, all five
  learners, 30 training cycles as in the paper. Target <= 5 %.
- speed-up: the same campaign on 2 loky workers vs in-process (workers warmed up first).
  Target >= 1.8x. The machine is shared: the load average is printed beside it.
- resume: a campaign of 100,125 jobs (15 conditions, 89 draws, 5 learners) whose rows
  are all finished (inserted as synthetic rows): time of `run_campaign` to load the
  definition, check it, read the finished keys and find nothing left. Target <= 2 s.
- projection: a slice of the paper grid (train = test = O at 1/3, 1/2, 1 Hz, 1 draw,
  30 training cycles, the paper's sweep: 240 jobs) on 2 workers; the paper grid's CPU
  time is the sum over its 21,000 jobs of the slice's mean fit+predict time for that
  learner and number of cycles, and the projected wall time divides it by the slice's
  measured parallel throughput (CPU time / wall time). Target <= 30 min.
- memory: peak resident set of the parent and of each loky worker (ru_maxrss).
  Target <= 2 GiB each.

Medians over ``--repeats`` runs, interleaved so that load changes hit both sides.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from suds_exp.campaign import CampaignOptions, SampleBank, enumerate_draws, run_campaign  # noqa: E402
from suds_exp.campaign.bank import rounded_conditions  # noqa: E402
from suds_exp.campaign.conditions import PAPER_SWEEP, select_conditions  # noqa: E402
from suds_exp.campaign.definition import LEARNERS, resolve_models  # noqa: E402
from suds_exp.campaign.job import RESULT_COLUMNS  # noqa: E402
from suds_exp.campaign.sampling import draw_sample  # noqa: E402
from suds_exp.models import make_model  # noqa: E402
from suds_exp.models.synthetic import make_samples  # noqa: E402
from suds_exp.store import Store  # noqa: E402

GAITS = ("S+", "S-", "O", "D-", "D+")
FREQS = (1 / 3, 1 / 2, 1.0)
SMALL = "O@1/3,O@1,D+@0.5,S-@1"
BOOTS = 1
CYCLES = 30


def paper_like_samples(seed: int = 0) -> pd.DataFrame:
    """5 gaits x 3 frequencies x 4 trials x 25 cycles at 100 Hz (synthetic swimmer)."""
    frames, tid = [], 1
    for g in GAITS:
        for f in FREQS:
            s = make_samples(
                n_cycles=25,
                gait=g,
                frequency_hz=f,
                n_trials=4,
                samples_per_cycle=int(round(100 / f)),
                velocity="finsler",
                substeps=2,
                first_trial_id=tid,
                seed=seed + tid,
            )
            frames.append(s)
            tid += 4
    return pd.concat(frames, ignore_index=True)


def fresh_store(folder: Path, tag: str) -> Store:
    """A new, migrated database: creating the schema is a once-per-database cost."""
    store = Store(folder / f"{tag}_{time.perf_counter_ns()}.duckdb")
    store.upgrade()
    return store


def small_options() -> CampaignOptions:
    return CampaignOptions(
        models=list(LEARNERS),
        boots=BOOTS,
        train_cycles=CYCLES,
        train_conditions=SMALL,
        test_conditions=SMALL,
    )


def bare_loop(samples: pd.DataFrame) -> float:
    """Seconds of make_model + fit + predict over the small campaign's jobs."""
    chosen = select_conditions(SMALL, rounded_conditions(samples), "--x")
    bank = SampleBank.build(samples, chosen)
    models = resolve_models(list(LEARNERS), "measured")
    jobs = []
    for d in enumerate_draws("bench", chosen, chosen, BOOTS, CYCLES, []):
        s = draw_sample(bank, d, CYCLES)
        train = bank.frame([bank.rows(*r) for r in s.train])
        test = bank.frame([bank.rows(*s.test)])
        jobs.append((train, test))
    t0 = time.perf_counter()
    with threadpool_limits(limits=1):
        for train, test in jobs:
            for name, params in models.items():
                make_model(name, **params).fit(train).predict(test)
    return time.perf_counter() - t0


def campaign_seconds(samples, folder, jobs) -> float:
    store = fresh_store(folder, f"j{jobs}")
    t0 = time.perf_counter()
    s = run_campaign(store, "bench", small_options(), samples=samples, jobs=jobs, progress=False)
    elapsed = time.perf_counter() - t0
    assert s.done_now == s.total_jobs == 16 * BOOTS * len(LEARNERS) and s.failed_now == 0, s
    return elapsed


def overhead_and_speedup(samples, folder, repeats):
    campaign_seconds(samples, folder, 2)  # spawn and warm the loky workers
    bare, one, two = [], [], []
    for _ in range(repeats):
        bare.append(bare_loop(samples))
        one.append(campaign_seconds(samples, folder, 1))
        two.append(campaign_seconds(samples, folder, 2))
    ratios = [o / b - 1 for o, b in zip(one, bare, strict=True)]
    return {
        "bare_loop_s": statistics.median(bare),
        "campaign_1_worker_s": statistics.median(one),
        "campaign_2_workers_s": statistics.median(two),
        "overhead_fraction": statistics.median(ratios),
        "speedup_2_over_1": statistics.median(one) / statistics.median(two),
        "jobs": 16 * BOOTS * len(LEARNERS),
        "overhead_ms_per_job": 1000
        * (statistics.median(one) - statistics.median(bare))
        / (16 * BOOTS * len(LEARNERS)),
    }


def resume_seconds(samples, folder, repeats):
    store = fresh_store(folder, "resume")
    options = CampaignOptions(models=list(LEARNERS), boots=89, train_cycles=30)
    have = rounded_conditions(samples)
    draws = enumerate_draws("big", have, have, 89, 30, [])
    n = len(draws) * len(LEARNERS)
    keys = [(d, m) for d in draws for m in LEARNERS]
    rows = pd.DataFrame(
        {
            "campaign": "big",
            "model": [m for _, m in keys],
            "train_gait": [d.train[0] for d, _ in keys],
            "train_frequency_hz": [d.train[1] for d, _ in keys],
            "test_gait": [d.test[0] for d, _ in keys],
            "test_frequency_hz": [d.test[1] for d, _ in keys],
            "boot": [d.boot for d, _ in keys],
            "n_cycles": 30,
            "train_trials": "[1]",
            "train_ranges": "[[1, 1, 30]]",
            "test_trial": 2,
            "test_range": "[1, 30]",
            "rmse_vx": np.random.default_rng(0).uniform(1, 10, n),
            "rmse_vy": 1.0,
            "rmse_wz": 0.1,
            "n_test": 3000,
            "fit_seconds": 0.1,
            "predict_seconds": 0.01,
            "finished_at": datetime(2026, 1, 1),
            "error": None,
        }
    )[list(RESULT_COLUMNS)]
    with store.write() as conn:
        store.insert_df(conn, "results", rows)
    first = run_campaign(store, "big", options, samples=samples, progress=False)
    assert first.total_jobs == n and first.done_now == 0 and first.remaining == 0, first
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        s = run_campaign(store, "big", samples=samples, progress=False)
        times.append(time.perf_counter() - t0)
        assert s.done_before == n and s.remaining == 0
    return {"finished_jobs": n, "resume_s": statistics.median(times), "resume_runs_s": times}


def projection(samples, folder):
    store = fresh_store(folder, "slice")
    spec = "O"
    options = CampaignOptions(
        models=list(LEARNERS),
        boots=1,
        train_cycles=30,
        sweep=list(PAPER_SWEEP),
        train_conditions=spec,
        test_conditions=spec,
    )
    t0 = time.perf_counter()
    s = run_campaign(store, "slice", options, samples=samples, jobs=2, progress=False)
    wall = time.perf_counter() - t0
    res = store.query_df(
        "SELECT model, n_cycles, fit_seconds + predict_seconds AS cpu FROM results"
    )
    mean = res.groupby(["model", "n_cycles"]).cpu.mean()
    main = 225 * 10 * sum(mean[(m, 30)] for m in LEARNERS)
    sweep = 15 * 10 * sum(mean[(m, n)] for m in LEARNERS for n in PAPER_SWEEP if n != 30)
    throughput = res.cpu.sum() / wall
    per_model_30 = {m: float(mean[(m, 30)]) for m in LEARNERS}
    return {
        "slice_jobs": s.done_now,
        "slice_wall_s": wall,
        "slice_parallel_throughput": throughput,
        "paper_jobs": 5 * 225 * 10 + 5 * 15 * 10 * (len(PAPER_SWEEP) - 1),
        "paper_cpu_s": main + sweep,
        "paper_projected_wall_s": (main + sweep) / throughput,
        "mean_fit_predict_s_at_30_cycles": per_model_30,
        "failed": s.failed_now,
    }


def worker_peak_rss():
    from joblib import Parallel, delayed

    def probe(_):
        time.sleep(0.05)
        return os.getpid(), resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024

    found = dict(Parallel(n_jobs=2)(delayed(probe)(i) for i in range(16)))
    return sorted(found.values())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-projection", action="store_true")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    folder = Path(tempfile.mkdtemp(prefix="suds_bench_campaign_"))
    t0 = time.perf_counter()
    samples = paper_like_samples()
    out = {"samples_rows": len(samples), "samples_seconds": time.perf_counter() - t0}
    out["load_average_before"] = os.getloadavg()
    out["overhead"] = overhead_and_speedup(samples, folder, args.repeats)
    out["resume"] = resume_seconds(samples, folder, args.repeats)
    if not args.no_projection:
        out["projection"] = projection(samples, folder)
    out["parent_peak_rss_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    out["worker_peak_rss_bytes"] = worker_peak_rss()
    out["load_average_after"] = os.getloadavg()
    if args.json:
        print(json.dumps(out, default=float))
        return
    o, r = out["overhead"], out["resume"]
    gib = 2**30
    print(f"load average before/after: {out['load_average_before']} / {out['load_average_after']}")
    print(
        f"framework overhead ({o['jobs']} jobs, {CYCLES} cycles, in-process): "
        f"{100 * o['overhead_fraction']:.1f} %, {o['overhead_ms_per_job']:.1f} ms/job  "
        f"(bare {o['bare_loop_s']:.2f} s, campaign "
        f"{o['campaign_1_worker_s']:.2f} s; target <= 5 %)"
    )
    print(
        f"speed-up 2 workers over 1: {o['speedup_2_over_1']:.2f}x  "
        f"({o['campaign_1_worker_s']:.2f} s -> {o['campaign_2_workers_s']:.2f} s; target >= 1.8x)"
    )
    print(f"resume with {r['finished_jobs']} finished jobs: {r['resume_s']:.2f} s (target <= 2 s)")
    if "projection" in out:
        p = out["projection"]
        print(
            f"paper-scale projection ({p['paper_jobs']} jobs): "
            f"{p['paper_projected_wall_s'] / 60:.1f} min on 2 workers (target <= 30 min); "
            f"slice {p['slice_jobs']} jobs in {p['slice_wall_s']:.1f} s, throughput "
            f"{p['slice_parallel_throughput']:.2f} CPU-s/s"
        )
        print(
            "  mean fit+predict at 30 cycles: "
            + ", ".join(f"{m} {v:.3f} s" for m, v in p["mean_fit_predict_s_at_30_cycles"].items())
        )
    print(
        f"peak memory: parent {out['parent_peak_rss_bytes'] / gib:.2f} GiB, workers "
        + ", ".join(f"{b / gib:.2f} GiB" for b in out["worker_peak_rss_bytes"])
        + " (target <= 2 GiB each)"
    )


if __name__ == "__main__":
    main()
