"""Online learners on a changing robot: recovery time, drift-alarm delay, false alarms,
and the cost of one partial_fit against the cycle it learns.

Usage (from the repository root)::

    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.studies.online [--seeds 20]
        [--change flippers=locked@30s] [--cycles 60] [--freq 1] [--models GMR,OnlineGMR]

Data: the physics simulator, gait O at `--freq` Hz, `--cycles` cycles a trial, one trial
per seed with the change and one per seed without (seeds 0..N-1 and 1000..1000+N-1),
samples straight from the truth (r_a = joint angles, r_p = the four flipper angles,
rates by central differences) with Gaussian noise of 1 mm/s on vx, vy and 0.01 rad/s on
wz, as benchmarks/speed/models.py. Each learner runs prequentially (`suds_exp.stream.run_trial`,
10 warm-up cycles, then predict, score, learn each cycle; batch learners stay as the
warm-up left them).

Prints, per learner: median pre-change and post-change RMSE of vx (mm/s); how many
changed trials recovered to x1.25 of the pre-change error within the trial and the median
time that took (s after the change); how many alarmed and the median alarm delay (s);
the false-alarm rate on the unchanged trials (and before the change on changed ones);
the median seconds of one partial_fit of one cycle and its ratio to the cycle's duration.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pandas as pd

from benchmarks._harness import script_parser
from suds_exp.sim.schedule import parse_change
from suds_exp.stream import StreamSettings, run_trial, simulate_stream_samples, summarise

NOISE = {"vx": 1.0, "vy": 1.0, "wz": 0.01}


def noisy(samples: pd.DataFrame, seed: int) -> pd.DataFrame:
    rng = np.random.default_rng([seed, 7])
    out = samples.copy()
    for c, sd in NOISE.items():
        out[c] = out[c] + sd * rng.standard_normal(len(out))
    return out


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--change", default="flippers=locked@30s")
    ap.add_argument("--cycles", type=int, default=60)
    ap.add_argument("--freq", type=float, default=1.0)
    ap.add_argument("--models", default="GMR,OnlineGMR,GMR+SUDS,OnlineGMR+SUDS")
    ap.add_argument("--json", action="store_true", help="also print the summary as JSON")
    args = ap.parse_args(argv)
    if args.quick:
        args.seeds, args.cycles, args.models = 1, 40, "GMR,OnlineGMR"
    change = parse_change(args.change)
    models = [m.strip() for m in args.models.split(",") if m.strip()]
    start = time.perf_counter()
    seeds = list(range(args.seeds))
    changed = simulate_stream_samples("O", args.freq, args.cycles, [change], seeds=seeds)
    steady = simulate_stream_samples(
        "O", args.freq, args.cycles, [], seeds=[1000 + s for s in seeds]
    )
    sim_s = time.perf_counter() - start
    settings = StreamSettings()
    rows = []
    for frame, change_s in ((changed, change.time_s), (steady, None)):
        for tid, trial in frame.groupby("trial_id", sort=True):
            trial = noisy(trial, int(tid))
            for model in models:
                r = run_trial(trial, model, {}, settings)
                r["change_s"] = change_s
                rows.append(r)
    rows = pd.concat(rows, ignore_index=True)
    summary = summarise(rows)
    print(
        f"{args.seeds} seeds x (changed + unchanged) trials of O at {args.freq:g} Hz, "
        f"{args.cycles} cycles, change {change}; simulated in {sim_s:.0f} s, "
        f"learners in {time.perf_counter() - start - sim_s:.0f} s"
    )
    for model in models:
        m = summary["models"][model]
        learn = rows.loc[rows["model"] == model, "learn_seconds"]
        cycle = m["cycle_seconds_median"]
        cost = (
            f"partial_fit median {1000 * learn.median():.1f} ms = "
            f"{learn.median() / cycle:.3f} x the {cycle:.2f} s cycle"
            if learn.max() > 0
            else "batch (no partial_fit)"
        )
        mine = [t for t in summary["trials"] if t["model"] == model]
        changed_rows = [t for t in mine if t["change_s"]]
        steady_rows = [t for t in mine if not t["change_s"]]
        print(
            f"{model:>15}: pre {m['pre_error_median']:.2f} mm/s, post {m['post_error_median']:.2f}"
            f"; recovered {m['recovered']}/{m['trials_with_change']} "
            f"(median {_s(m['recovery_s_median'])}); alarmed {m['alarmed']}/"
            f"{m['trials_with_change']} (median delay {_s(m['alarm_delay_s_median'])}); "
            f"false alarms {sum(t['false_alarm'] for t in steady_rows)}/{len(steady_rows)} "
            "unchanged trials, "
            f"{sum(t['false_alarm'] for t in changed_rows)}/{len(changed_rows)} before the "
            f"change; {cost}"
        )
    if args.json:
        print(json.dumps(summary["models"]))


def _s(x) -> str:
    return "-" if x is None else f"{x:.1f} s"


if __name__ == "__main__":
    main()
