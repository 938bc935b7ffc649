"""The learner survey on simulated data: cycles to target, data ratio, time per learner.

Usage (from the repository root)::

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python -m benchmarks.studies.survey \
        [--db survey.duckdb] [--gaits O] [--boots 4] [--sweep 1,2,4,8,16,30,48] [--jobs 2] \
        [--campaign survey] [--models survey] [--conditions O@0.5]

Simulates the default dataset's design for ``--gaits`` (default: all five; 4 repeats of
10-30 cycles at 1/3, 1/2 and 1 Hz, seed 0) into ``--db`` unless it already holds trials,
preprocesses it with the default parameters (version ``v1``), runs (or continues: it is
an ordinary campaign, resumable) campaign ``--campaign`` with ``--models`` (default
``survey``: the paper's five and the scikit-learn baselines) on ``--conditions`` (train
and test; default all), and prints

1. cycles to reach x1.25 of each learner's error at the largest sweep size and to reach
   GMR's 30-cycle error, per learner and test frequency (median RMS error of vx over the
   same-condition draws; `suds_exp.analysis.survey.cycles_to_target`);
2. the MLP / GMR data ratio with its 95 % paired-bootstrap interval, at GMR's 30-cycle
   error and at the MLP's own error at each sweep size n (cycles GMR needs to reach the
   MLP's n-cycle error, against n: `efficiency_ratio` with the roles swapped; a ratio
   read at GMR's first sweep size is a lower bound);
3. median fit and predict seconds per learner at 30 cycles, and the survey's learners'
   total against the paper's five (the issue's target: the survey grid no slower than
   3x the five-learner grid).

``--per-condition`` runs one campaign per condition (``CAMPAIGN-GAIT@FREQ``, train = test
= that condition), i.e. the sweep's same-condition pairs only, without the main grid's
cross pairs (which the tables above do not use), and pools their results: the affordable
way to cover every condition with many draws. A campaign decimates its trials to the
smallest samples per cycle among its own conditions, so the samples are decimated first
to the whole dataset's (100 per cycle at 1 Hz and 100 Hz capture), as the paper's grid
over all conditions does. ``--skip-infeasible`` leaves out sizes a condition's trials
cannot supply.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks._data import decimated, ensure_data
from benchmarks._harness import script_parser
from suds_exp.analysis.queries import load_results
from suds_exp.analysis.survey import (
    SURVEY_COLUMNS,
    efficiency_ratio,
    ratio_sentence,
    survey_from_results,
)
from suds_exp.campaign import run_campaign
from suds_exp.commands.campaign import parse_campaign_options
from suds_exp.models.registry import LEARNERS
from suds_exp.store import Store


def all_conditions(store: Store, spec: str | None = None) -> list[str]:
    """The stored trials' conditions named by ``spec`` (None: all), as GAIT@FREQ in one
    spelling (``O@1/3`` and ``O@0.333333`` name the same campaign)."""
    from suds_exp.campaign.conditions import format_condition, select_conditions
    from suds_exp.ingest import list_trials

    t = list_trials(store)[["gait", "frequency_hz"]].drop_duplicates()
    have = [(g, round(float(f), 6)) for g, f in t.itertuples(index=False, name=None)]
    return [format_condition(c) for c in select_conditions(spec, have, "--conditions")]


def main(argv=None) -> None:
    p = script_parser(__doc__.splitlines()[0], "a smoke run: O at 1 Hz, 4 learners")
    p.add_argument("--db", default="survey.duckdb")
    p.add_argument("--gaits", default="S+,S-,O,D-,D+")
    p.add_argument("--boots", type=int, default=4)
    p.add_argument("--sweep", default="1,2,4,8,16,30,48")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--n-boot", type=int, default=1000)
    p.add_argument("--campaign", default="survey")
    p.add_argument("--models", default="survey")
    p.add_argument("--conditions", default=None)
    p.add_argument("--per-condition", action="store_true")
    p.add_argument("--skip-infeasible", action="store_true")
    p.add_argument("--prep", default="v1")
    args = p.parse_args(argv)
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-survey-quick-") as tmp:
            args.db, args.gaits, args.conditions = str(Path(tmp) / "quick.duckdb"), "O", "O@1"
            args.models, args.sweep, args.boots = "phase-only,TLS,GMR,MLP", "2,30", 2
            args.n_boot, args.jobs, args.per_condition = 50, 1, False
            study(args)
        return
    study(args)


def study(args) -> None:
    store = Store(args.db)
    ensure_data(store, args.gaits.split(","))
    samples = None
    if args.per_condition:
        conditions = all_conditions(store, args.conditions)
        names = [f"{args.campaign}-{c}" for c in conditions]
        samples = decimated(store, args.prep)
    else:
        conditions, names = [args.conditions], [args.campaign]
    for name, cond in zip(names, conditions, strict=True):
        options = parse_campaign_options(
            prep=args.prep,
            models=args.models,
            sweep=args.sweep,
            boots=args.boots,
            train_cycles=30,
            train_conditions=cond,
            test_conditions=cond,
            skip_infeasible=args.skip_infeasible or None,
        )
        summary = run_campaign(store, name, options, samples=samples, jobs=args.jobs)
        print(f"{name}: {summary.message()}", flush=True)
        if summary.interrupted:
            # run_campaign turned Ctrl-C / SIGTERM into a clean stop of this campaign; the
            # user meant the whole run, so neither the next campaigns nor the report
            sys.exit(130)
    results = pd.concat(
        [load_results(store, n, columns=SURVEY_COLUMNS) for n in names], ignore_index=True
    )
    t = survey_from_results(results, 30, args.n_boot, "MLP")
    print(f"\n{len(results)} results from {len(names)} campaign(s), {args.boots} draws each")
    with pd.option_context("display.width", 200, "display.max_rows", 200):
        print("\nCycles to target (median RMS error of vx, mm/s, same-condition draws):")
        print(t["cycles"].round(2).to_string(index=False))
        print("\n" + ratio_sentence(t["ratio"], 30))
        if {"MLP", "GMR"} <= set(results["model"]):
            print("MLP / GMR data ratio at the MLP's own error after n cycles:")
            for n in sorted(results["n_cycles"].unique()):
                x = efficiency_ratio(results, "GMR", "MLP", int(n), n_boot=args.n_boot)
                if not np.isfinite(x["cycles_model"]):
                    print(f"  n = {n:>2}: error {x['target']:.2f} mm/s, GMR never reaches it")
                    continue
                lo, hi = (1 / x["high"] if x["high"] > 0 else np.inf), 1 / x["low"]
                print(
                    f"  n = {n:>2}: error {x['target']:.2f} mm/s, GMR reaches it at "
                    f"{x['cycles_model']:.2f} cycles: ratio {1 / x['ratio']:.1f} "
                    f"(95 % {lo:.1f}-{hi:.1f})"
                )
        if "glm" in t:
            n = t["glm"].attrs["n_rows"]
            print(f"\nGLM of 100 ln(RMS error of vx), learner as a factor ({n} rows):")
            print(t["glm"].round(2).to_string(index=False))
        timing = t["timing"]
        at30 = timing[timing["n_cycles"] == 30].assign(
            total=lambda d: d["fit_seconds"] + d["predict_seconds"]
        )
        print("\nMedian seconds per job at 30 cycles:")
        print(at30.round(3).to_string(index=False))
        five = at30[at30["model"].isin(LEARNERS)]["total"].sum()
        if at30["model"].isin(LEARNERS).sum() < len(LEARNERS):
            return  # not the paper's five: no ratio to them
        print(
            f"\nall {len(at30)} learners / the paper's five, per job: "
            f"{at30['total'].sum() / five:.2f}x (target <= 3x)"
        )


if __name__ == "__main__":
    main()
