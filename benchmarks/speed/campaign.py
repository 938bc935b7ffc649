"""Campaign benchmarks: framework overhead, 2-worker speed-up, resume time with 100k
finished jobs, projected paper-scale time and peak memory.

Usage::

    .venv/bin/python -m benchmarks.speed.campaign [--repeats 3] [--no-projection] [--json]
    .venv/bin/python -m benchmarks.speed.campaign --baseline /tmp/base [--rounds 5]

Data: the models' synthetic swimmer (`suds_exp.testing.synthetic_swimmer.make_samples`), 5 gaits
x 3 frequencies x 4 trials x 25 cycles captured at 100 Hz, so after decimation every
cycle has 100 samples as in the paper's data. Figures:

- overhead: wall time of `run_campaign` (in-process, fresh database: definition, sample
  bank, sampling, frames, database writes) over the time of the same jobs' make_model +
  fit + predict in a bare loop on frames built beforehand; 4 conditions, 16 pairs x 3 draws,
  all five learners, 30 training cycles as in the paper. Target: <= 3 % at
  paper scale, where the fixed cost of a run is paid once for 21,000 jobs.
- overhead is given two ways: over the learners' own fit + predict time recorded in the
  same run (immune to load changes between runs), and over a separate bare loop.
- speed-up: the same campaign on 2 loky workers vs in-process (workers warmed up first).
  Target >= 1.9x. The machine is shared, so beside it: how many cores this workload got
  from two processes at the time (2 x time of one bare loop alone / time of two bare loops
  run at once in two processes, no campaign code involved),
  and the speed-up the CPU times imply for two idle cores: CPU time of the in-process run
  / max(CPU time of the busier worker, (CPU of both workers + parent) / 2).
- resume: a campaign of 100,125 jobs (15 conditions, 89 draws, 5 learners) whose rows
  are all finished (inserted as synthetic rows): time of `run_campaign` to load the
  definition, check it, read the finished keys and find nothing left. Target <= 2 s.
- projection: a slice of the paper grid (train = test = O at 1/3, 1/2, 1 Hz, 1 draw,
  30 training cycles, the paper's sweep: 240 jobs) on 2 workers; the paper grid's CPU
  time is the sum over its 21,000 jobs of the slice's mean fit+predict time for that
  learner and number of cycles, and the projected wall time divides it by the slice's
  measured parallel throughput (CPU time / wall time). Target <= 30 min. The framework
  overhead at that scale follows from the fixed and per-job costs measured above.
- memory: peak resident set of the parent and of each loky worker (ru_maxrss).
  Target <= 2 GiB each.

Medians over ``--repeats`` runs, interleaved so that load changes hit both sides.

``--baseline PATH_OR_COMMIT``: instead, the framework overhead only, of a baseline (a
checkout's folder, e.g. a `git worktree add` of main, or a commit exported with `git
archive`) and of this working tree, each in its own process, alternating (A B A B ...)
``--rounds`` times with two measured campaigns a process after a warm-up one. Per side:
the overhead over the learners' own time in the same run (small grid, as above), split
into the fixed cost of a run, the batch writes and the rest per job, and the overhead
at paper scale: (fixed cost + per-job cost x 21,000 jobs) / (learners' time per job x
21,000 jobs), the per-job figures measured on the small grid. With ``--paper-boots N``
the measured campaign is the paper's grid itself (15 x 15 pairs and the sweep on the
synthetic data's 15 conditions) with N draws a cell (2,100 jobs for N = 1), one a process.

``--quick``: a smoke run at tiny sizes (8-cycle trials, 5 training cycles, one draw, two
learners, one repeat, a resume of 2 draws, no projection); its figures mean nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from joblib import parallel_config
from threadpoolctl import threadpool_limits

from benchmarks._data import SMALL, fresh_store, paper_like_samples, small_grid_jobs
from benchmarks._harness import alternate, script_parser, worker
from suds_exp.campaign import CampaignOptions, enumerate_draws, run_campaign
from suds_exp.campaign.bank import rounded_conditions
from suds_exp.campaign.conditions import PAPER_SWEEP
from suds_exp.campaign.definition import resolve_models
from suds_exp.campaign.job import RESULT_COLUMNS
from suds_exp.models import make_model
from suds_exp.models.registry import LEARNERS
from suds_exp.testing.synthetic_results import finished_rows

#: The sizes of a run; `_quick` shrinks them for a smoke run.
BOOTS = 3
CYCLES = 30
TRIAL_CYCLES = 25
MODELS = list(LEARNERS)
RESUME_BOOTS = 89


def _quick() -> None:
    global BOOTS, CYCLES, TRIAL_CYCLES, MODELS, RESUME_BOOTS
    BOOTS, CYCLES, TRIAL_CYCLES, MODELS, RESUME_BOOTS = 1, 5, 8, ["phase-only", "TLS"], 2


def small_options() -> CampaignOptions:
    return CampaignOptions(
        models=MODELS,
        boots=BOOTS,
        train_cycles=CYCLES,
        train_conditions=SMALL,
        test_conditions=SMALL,
    )


def bare_loop(samples: pd.DataFrame) -> float:
    """Seconds of make_model + fit + predict over the small campaign's jobs."""
    models = resolve_models(MODELS, "measured")
    jobs = small_grid_jobs(samples, BOOTS, CYCLES)
    t0 = time.perf_counter()
    with threadpool_limits(limits=1):
        for train, test in jobs:
            for name, params in models.items():
                make_model(name, **params).fit(train).predict(test)
    return time.perf_counter() - t0


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def campaign_seconds(
    samples, folder, jobs, cpu: dict | None = None, options: CampaignOptions | None = None
) -> tuple[float, float]:
    """(wall s, s spent in the learners' fit + predict as recorded in `results`) of the
    campaign of ``options`` (default: the small grid); fills ``cpu`` with the CPU seconds
    of the parent and of each worker during the run."""
    store = fresh_store(folder, f"j{jobs}")
    before = worker_usage() if cpu is not None and jobs > 1 else {}
    c0, t0 = _cpu(), time.perf_counter()
    s = run_campaign(
        store, "bench", options or small_options(), samples=samples, jobs=jobs, progress=False
    )
    elapsed = time.perf_counter() - t0
    if cpu is not None:
        cpu["parent"] = _cpu() - c0
        after = worker_usage() if jobs > 1 else {}
        cpu["workers"] = [after[p][0] - before.get(p, (0.0, 0))[0] for p in after]
    expected = s.total_jobs if options else 16 * BOOTS * len(MODELS)
    assert s.done_now == s.total_jobs == expected and s.failed_now == 0, s
    learners = store.query_df("SELECT sum(fit_seconds + predict_seconds) AS s FROM results").s[0]
    if cpu is not None:
        # the same call with every job done: the per-run cost (lock, definition, bank,
        # finished keys, run record) that a long campaign pays once
        t1 = time.perf_counter()
        run_campaign(store, "bench", samples=samples, jobs=jobs, progress=False)
        cpu["fixed_s"] = time.perf_counter() - t1
        cpu["writes_s"] = s.flush_seconds
        cpu["jobs"] = s.done_now
    return elapsed, float(learners)


_SAMPLES: pd.DataFrame | None = None


def _bare_in_process(_) -> float:
    global _SAMPLES
    if _SAMPLES is None:
        _SAMPLES = paper_like_samples(n_cycles=TRIAL_CYCLES)
    return bare_loop(_SAMPLES)


def machine_capacity() -> float:
    """How many cores this workload gets right now from two processes (2.0 on an idle
    2-core machine): 2 x time of the bare loop alone / time of two bare loops at once,
    each in its own process."""
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(2) as pool:
        list(pool.map(_bare_in_process, [0, 1]))  # samples and imports in both processes
        alone = pool.submit(_bare_in_process, 0).result()
        pair = max(pool.map(_bare_in_process, [0, 1]))
    return 2 * alone / pair


def overhead_and_speedup(samples, folder, repeats):
    campaign_seconds(samples, folder, 2)  # spawn and warm the loky workers
    bare, one, two, inside, capacity, cpu_speedup, fixed, per_job = ([] for _ in range(8))
    n = 16 * BOOTS * len(MODELS)

    for _ in range(repeats):
        bare.append(bare_loop(samples))
        cpu1, cpu2 = {}, {}
        wall, learners = campaign_seconds(samples, folder, 1, cpu1)
        one.append(wall)
        inside.append(wall / learners - 1)
        fixed.append(cpu1["fixed_s"])
        per_job.append((wall - learners - cpu1["fixed_s"]) / n)
        two.append(campaign_seconds(samples, folder, 2, cpu2)[0])
        capacity.append(machine_capacity())
        # On two idle cores the 2-worker run would take as long as its busier worker,
        # or half the CPU time of workers + parent if that is longer.
        idle_wall = max(max(cpu2["workers"]), (sum(cpu2["workers"]) + cpu2["parent"]) / 2)
        cpu_speedup.append(cpu1["parent"] / idle_wall)
    return {
        "jobs": n,
        "bare_loop_s": statistics.median(bare),
        "campaign_1_worker_s": statistics.median(one),
        "campaign_2_workers_s": statistics.median(two),
        "overhead_vs_bare_loop": statistics.median(
            o / b - 1 for o, b in zip(one, bare, strict=True)
        ),
        "overhead_vs_own_learner_time": statistics.median(inside),
        "overhead_ms_per_job": 1000
        * statistics.median(w * f / (1 + f) for w, f in zip(one, inside, strict=True))
        / n,
        "fixed_cost_per_run_s": statistics.median(fixed),
        "paper_scale_overhead": statistics.median(
            paper_scale(w / (1 + f) / n, fx, pj)
            for w, f, fx, pj in zip(one, inside, fixed, per_job, strict=True)
        ),
        "overhead_ms_per_job_beyond_fixed": 1000 * statistics.median(per_job),
        "mean_learner_ms_per_job": 1000
        * statistics.median(w / (1 + f) for w, f in zip(one, inside, strict=True))
        / n,
        "speedup_2_over_1": statistics.median(o / t for o, t in zip(one, two, strict=True)),
        "machine_capacity_cores": statistics.median(capacity),
        "speedup_from_cpu_times": statistics.median(cpu_speedup),
    }


def paper_jobs() -> int:
    """Jobs of the paper campaign: 15 x 15 pairs x 10 draws, and the same-condition sweep
    (15 conditions x 10 draws x 13 sizes besides 30), five learners each."""
    return 5 * 225 * 10 + 5 * 15 * 10 * (len(PAPER_SWEEP) - 1)


def paper_scale(learner_s_per_job: float, fixed_s: float, overhead_s_per_job: float) -> float:
    """Framework overhead over the learners' own time of a campaign of `paper_jobs` jobs
    that pays ``fixed_s`` once and ``overhead_s_per_job`` for each job."""
    n = paper_jobs()
    return (fixed_s + overhead_s_per_job * n) / (learner_s_per_job * n)


def paper_options(boots: int) -> CampaignOptions:
    """The paper's grid (every condition as train and test, the paper's sweep) with
    ``boots`` draws a cell instead of 10."""
    return CampaignOptions(
        models=list(LEARNERS), boots=boots, train_cycles=CYCLES, sweep=list(PAPER_SWEEP)
    )


def overhead_rounds(samples, folder, rounds: int, paper_boots: int = 0) -> list[dict]:
    """``rounds`` in-process runs of the small campaign (or, given ``paper_boots``, of
    `paper_options`), after a warm-up one of the small grid: for each, the wall s, the
    learners' own s, the batch writes' s and the fixed cost of a run."""
    campaign_seconds(samples, folder, 1)
    options = paper_options(paper_boots) if paper_boots else None
    out = []
    for _ in range(rounds):
        cpu: dict = {}
        wall, learners = campaign_seconds(samples, folder, 1, cpu, options)
        out.append(
            {
                "jobs": cpu["jobs"],
                "wall_s": wall,
                "learners_s": learners,
                "fixed_s": cpu["fixed_s"],
                "writes_s": cpu["writes_s"],
            }
        )
    return out


def overhead_figures(r: dict) -> dict:
    """One round's overhead figures (see the module docstring)."""
    n = r["jobs"]
    per_job = (r["wall_s"] - r["learners_s"] - r["fixed_s"]) / n
    return {
        "overhead %": 100 * (r["wall_s"] / r["learners_s"] - 1),
        "fixed s per run": r["fixed_s"],
        "writes ms per job": 1000 * r["writes_s"] / n,
        "rest ms per job": 1000 * (per_job - r["writes_s"] / n),
        "learners ms per job": 1000 * r["learners_s"] / n,
        "paper-scale overhead %": 100 * paper_scale(r["learners_s"] / n, r["fixed_s"], per_job),
    }


def compare_with_baseline(baseline: str, rounds: int, per_process: int, paper_boots: int) -> None:
    """Print the overhead of ``baseline`` (a folder or a commit) and of this tree."""

    def run(tree: Path) -> list[dict]:
        args = [str(per_process), "--paper-boots", str(paper_boots)]
        args += ["--quick"] if CYCLES != 30 else []
        return worker(tree, __spec__.name, *args, OMP_NUM_THREADS="1")

    load = os.getloadavg()
    base, now = alternate(baseline, rounds, run)
    fb = [overhead_figures(r) for rs in base for r in rs]
    fn = [overhead_figures(r) for rs in now for r in rs]
    grid = (
        f"the paper's grid with {paper_boots} draw(s) a cell (sweep included)"
        if paper_boots
        else f"small grid ({CYCLES} cycles)"
    )
    print(
        f"## Framework overhead, {grid}: {base[0][0]['jobs']} jobs, in-process, "
        f"{rounds} rounds x {per_process} runs a side; baseline {baseline}, now = working tree"
    )
    print(f"baseline from {base[0][0]['suds_exp']}, now from {now[0][0]['suds_exp']}")
    print(f"load average before {load}, after {os.getloadavg()}")
    print("| figure (median) | baseline | now |")
    print("|---|---|---|")
    for key in fb[0]:
        b, m = statistics.median(f[key] for f in fb), statistics.median(f[key] for f in fn)
        print(f"| {key} | {b:.3f} | {m:.3f} |")


def resume_seconds(samples, folder, repeats):
    store = fresh_store(folder, "resume")
    options = CampaignOptions(models=MODELS, boots=RESUME_BOOTS, train_cycles=CYCLES)
    have = rounded_conditions(samples)
    draws = enumerate_draws("big", have, have, RESUME_BOOTS, CYCLES, [])
    n = len(draws) * len(MODELS)
    keys = [(d, m) for d in draws for m in MODELS]
    rmse_vx = np.random.default_rng(0).uniform(1, 10, n)
    rows = finished_rows(keys, "big", CYCLES, rmse_vx)[list(RESULT_COLUMNS)]
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
        "paper_jobs": paper_jobs(),
        "paper_cpu_s": main + sweep,
        "paper_projected_wall_s": (main + sweep) / throughput,
        "mean_fit_predict_s_at_30_cycles": per_model_30,
        "failed": s.failed_now,
    }


def _probe(_):
    time.sleep(0.05)
    r = resource.getrusage(resource.RUSAGE_SELF)
    return os.getpid(), (r.ru_utime + r.ru_stime, r.ru_maxrss * 1024)


def worker_usage() -> dict[int, tuple[float, int]]:
    """pid -> (CPU seconds used so far, peak RSS bytes) of each loky worker."""
    from joblib import Parallel, delayed

    with parallel_config(backend="loky", n_jobs=2):
        return dict(Parallel()(delayed(_probe)(i) for i in range(16)))


def worker_peak_rss():
    return sorted(rss for _, rss in worker_usage().values())


def main(argv=None):
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-projection", action="store_true")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--baseline", help="compare the overhead with this folder or commit")
    ap.add_argument("--rounds", type=int, default=5, help="with --baseline: processes a side")
    ap.add_argument(
        "--paper-boots",
        type=int,
        default=0,
        help="with --baseline: measure on the paper's grid with this many draws a cell",
    )
    ap.add_argument("--worker", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.quick:
        _quick()
        args.repeats, args.no_projection = 1, True
    if args.baseline:
        per_process = 1 if args.paper_boots else 2
        compare_with_baseline(args.baseline, args.rounds, per_process, args.paper_boots)
        return
    folder = Path(tempfile.mkdtemp(prefix="suds_bench_campaign_"))
    if args.worker:
        import suds_exp

        samples = paper_like_samples(n_cycles=TRIAL_CYCLES)
        rounds = overhead_rounds(samples, folder, args.worker, args.paper_boots)
        print(json.dumps([r | {"suds_exp": suds_exp.__file__} for r in rounds]))
        return
    t0 = time.perf_counter()
    samples = paper_like_samples(n_cycles=TRIAL_CYCLES)
    out = {"samples_rows": len(samples), "samples_seconds": time.perf_counter() - t0}
    out["load_average_before"] = os.getloadavg()
    out["overhead"] = overhead_and_speedup(samples, folder, args.repeats)
    out["resume"] = resume_seconds(samples, folder, args.repeats)
    if not args.no_projection:
        out["projection"] = p = projection(samples, folder)
        o = out["overhead"]
        # the measured fixed cost once plus the measured per-job cost for every job,
        # against the learners' own time over the paper grid
        p["paper_overhead_fraction"] = (
            o["fixed_cost_per_run_s"]
            + o["overhead_ms_per_job_beyond_fixed"] / 1000 * p["paper_jobs"]
        ) / p["paper_cpu_s"]
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
        f"{100 * o['overhead_vs_own_learner_time']:.1f} % over the learners' own time in the "
        f"same run ({o['overhead_ms_per_job']:.1f} ms/job), "
        f"{100 * o['overhead_vs_bare_loop']:.1f} % over a separate bare loop "
        f"(bare {o['bare_loop_s']:.2f} s, campaign "
        f"{o['campaign_1_worker_s']:.2f} s)"
    )
    print(
        f"  of which fixed per run {o['fixed_cost_per_run_s']:.2f} s and "
        f"{o['overhead_ms_per_job_beyond_fixed']:.2f} ms per job "
        f"(learners {o['mean_learner_ms_per_job']:.1f} ms per job here); at paper scale "
        f"({paper_jobs()} jobs, the fixed cost paid once): "
        f"{100 * o['paper_scale_overhead']:.1f} %; target <= 3 %"
    )
    print(
        f"speed-up 2 workers over 1: {o['speedup_2_over_1']:.2f}x "
        f"({o['campaign_1_worker_s']:.2f} s -> {o['campaign_2_workers_s']:.2f} s; target >= 1.9x);"
        f" two bare loops in two processes got {o['machine_capacity_cores']:.2f} cores meanwhile;"
        f" from CPU times (idle 2 cores): {o['speedup_from_cpu_times']:.2f}x"
    )
    print(f"resume with {r['finished_jobs']} finished jobs: {r['resume_s']:.2f} s (target <= 2 s)")
    if "projection" in out:
        p = out["projection"]
        print(
            f"paper-scale projection ({p['paper_jobs']} jobs): "
            f"{p['paper_projected_wall_s'] / 60:.1f} min on 2 workers (target <= 30 min); "
            f"slice {p['slice_jobs']} jobs in {p['slice_wall_s']:.1f} s, throughput "
            f"{p['slice_parallel_throughput']:.2f} CPU-s/s; framework overhead there "
            f"{100 * p['paper_overhead_fraction']:.1f} %"
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
