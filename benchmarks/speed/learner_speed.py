"""Learner fit + predict time against a baseline commit, on the same data, same run.

Usage (from the repository root)::

    .venv/bin/python -m benchmarks.speed.learner_speed [--baseline c2aa7be] [--rounds 5]
        [--repeats 5] [--cycles 30] [--models phase-only,TLS,...,MLP,GBT] [--quick]

``--models``: the learners to time (default: the paper's five and the rollout mode);
with the paper's five and more (e.g. the survey's learners) it also prints all learners'
CPU per job over the five's, the survey grid's cost against the paper's.

The baseline's `suds_exp` is exported from git (`git archive`) into a temporary folder;
rounds alternate a worker process on the baseline and one on the working tree (A B A B
...), so a change in the machine's load hits both. Each worker fits and predicts every
learner `--repeats` times, single-threaded BLAS (the campaign runs one job a core), on the
campaign benchmarks' synthetic data (`benchmarks._data.paper_like_samples`, 5 gaits x 3
frequencies x 4 trials, 100 samples a cycle): the first bootstrap draws of its small grid at
`--cycles` training cycles, predicting a different trial of the test condition. It
reports the median CPU seconds of one job (fit + predict) per learner; the table gives
the medians over rounds and the ratio baseline / now per round (its median, min, max).
Each worker also hashes every prediction, so the table says whether the working tree's
predictions are bit-identical to the baseline's. ``--quick``: baseline HEAD, one round, one
repeat of one draw at 5 cycles on 8-cycle trials, two learners (a smoke run, no figure).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from statistics import median

from benchmarks import _data
from benchmarks._harness import alternate, same, script_parser, speedup, worker

PAPER_FIVE = ("phase-only", "TLS", "TLS+SUDS", "GMR", "GMR+SUDS")
CASES = [
    ("phase-only", {}),
    ("TLS", {}),
    ("TLS+SUDS", {}),
    ("GMR", {}),
    ("GMR+SUDS", {}),
    ("GMR+SUDS", {"mode": "rollout"}),
]


def _label(name, params):
    return name + "".join(f" {k}={v}" for k, v in sorted(params.items()))


def cases(models: str | None) -> list[tuple[str, dict]]:
    """`CASES`, or the learners named in ``models`` (comma-separated); a learner outside
    the paper's five gets random_state=0, so its predictions can be compared."""
    if not models:
        return CASES
    return [(n, {} if n in PAPER_FIVE else {"random_state": 0}) for n in models.split(",")]


def measure(
    cycles: int, repeats: int, n_jobs: int, models: str | None = None, trial_cycles: int = 25
) -> dict:
    """{learner: [median CPU s per job, sha256 of its predictions]} in this process."""
    from threadpoolctl import threadpool_limits

    import suds_exp
    from suds_exp.models import make_model

    samples = _data.paper_like_samples(n_cycles=trial_cycles)
    jobs = _data.small_grid_jobs(samples, boots=1, cycles=cycles, limit=n_jobs)
    out = {"suds_exp": [0.0, suds_exp.__file__]}
    with threadpool_limits(limits=1):
        for name, params in cases(models):
            h = hashlib.sha256()
            per_job = []
            for _ in range(repeats):
                c0 = time.process_time()
                for train, test in jobs:
                    p = make_model(name, **params).fit(train).predict(test)
                    h.update(p.to_numpy(dtype=float).tobytes())
                per_job.append((time.process_time() - c0) / len(jobs))
            out[_label(name, params)] = [median(per_job), h.hexdigest()[:16]]
    return out


def _run(tree, a) -> dict:
    args = ["--cycles", str(a.cycles), "--repeats", str(a.repeats), "--jobs", str(a.jobs)]
    args += ["--trial-cycles", str(a.trial_cycles)]
    args += ["--models", a.models] if a.models else []
    return worker(tree, __spec__.name, *args, OMP_NUM_THREADS="1")


def main(argv=None) -> int:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="c2aa7be")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--cycles", type=int, default=30)
    ap.add_argument("--jobs", type=int, default=4, help="bootstrap draws per learner")
    ap.add_argument("--models", default=None, help="learners, comma-separated (default: CASES)")
    ap.add_argument("--trial-cycles", type=int, default=25, help="cycles of each trial")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.quick:
        a.baseline, a.rounds, a.repeats, a.cycles, a.jobs = "HEAD", 1, 1, 5, 1
        a.trial_cycles, a.models = 8, "phase-only,TLS"
    if a.worker:
        print(json.dumps(measure(a.cycles, a.repeats, a.jobs, a.models, a.trial_cycles)))
        return 0
    base, now = alternate(a.baseline, a.rounds, lambda path: _run(path, a))
    print(
        f"## Learner CPU seconds per job (fit + predict), {a.cycles} training cycles, "
        f"{a.jobs} draws x {a.repeats} repeats a worker, {a.rounds} rounds; "
        f"baseline {a.baseline}, now = working tree"
    )
    print(f"baseline from {base[0].pop('suds_exp')[1]}, now from {now[0].pop('suds_exp')[1]}")
    print("| learner | baseline s | now s | speed-up (median [min, max]) | predictions |")
    print("|---|---|---|---|---|")
    for key in base[0]:
        b = [r[key][0] for r in base]
        n = [r[key][0] for r in now]
        identical = same(r[key][1] for r in base + now)
        print(
            f"| {key} | {median(b):.4f} | {median(n):.4f} | {speedup(b, n)} "
            f"| {'bit-identical' if identical else 'DIFFER'} |"
        )
    if set(PAPER_FIVE) <= set(base[0]) and len(base[0]) > len(PAPER_FIVE):
        # the survey's cost against the paper's five: per round, all learners' CPU over
        # the five's (the target: <= 3x)
        for label, runs in (("baseline", base), ("now", now)):
            r = [sum(v[0] for v in x.values()) / sum(x[k][0] for k in PAPER_FIVE) for x in runs]
            print(
                f"{label}: all {len(runs[0])} learners / the paper's five, CPU per job: "
                f"{median(r):.2f}x (median of {len(r)} rounds)"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
