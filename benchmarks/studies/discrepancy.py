"""Benchmark of the discrepancy workflow: confusion matrix over hidden effects x seeds,
null control, and the workflow's time on the default dataset.

Every run simulates "measured" data with one effect hidden (its parameter drawn from the
realistic range with the run's seed), sends it through files -> ingest -> preprocess and
runs the workflow from the nominal model. A hit: the hidden effect is named first, its
interval covers the true value and the held-out gap at least halves.

    .venv/bin/python -m benchmarks.studies.discrepancy --seeds 3 --null-seeds 4 --out bench-disc.csv
    .venv/bin/python -m benchmarks.studies.discrepancy --timing-only     # default dataset timing
    .venv/bin/python -m benchmarks.studies.discrepancy --withheld --seeds 5 --out bench-withheld.csv

`--withheld`: each effect is hidden in the data AND excluded from the candidates
(`--exclude-candidates`); per effect it prints the wrong-name rate (anything named), the
rate at which the gap is reported as unexplained by the library, the held-out gap closed
by the discovered correction, and its leading features.

`--detection EFFECT --values V1,V2,... --detection-seeds S1,S2,...`: the detection limit
of one effect on the slow tests' design: the effect hidden at each fixed value of its
parameter (no draw), run at each seed; per value it prints how often the effect is named
first, the candidate's held-out p (raw and adjusted for the other candidates), the
held-out loss it removes, its fitted value and the gap. For example the spoke oscillation's edge:

    .venv/bin/python -m benchmarks.studies.discrepancy --detection spoke_oscillation \
        --values 1.3,1.4,1.5 --detection-seeds 11,14,15 --out bench-detect.csv

`--form-mismatch`: the same on the effects whose nearest candidate has the same mechanism
but another form (`FORM_MISMATCH`: dry hinge friction, approximated by viscous hinge
damping; a drag that grows with distance, approximated by a constant drag scale): the
near candidate may be kept as a partial explanation, the rest discovered; the summary
says how much each part closed (`median_closed_by_partial`, `median_gap_closed` of what
remained, `median_closed_total`).

Rows are appended to --out as runs finish, so an interrupted benchmark keeps its results
(and a re-run skips the rows already there).
"""

from __future__ import annotations

import functools
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks._harness import script_parser
from suds_exp.robot import GAITS
from suds_exp.workflows.hidden_effects import HIDDEN, draw_hidden, hidden_effect_run

DESIGN = dict(gaits=("S+", "O", "D+"), frequencies_hz=(1 / 3, 0.5, 1.0), repeats=4, cycles=(4, 6))
#: ``--quick``'s design (a smoke run).
QUICK_DESIGN = dict(gaits=("O", "D+"), frequencies_hz=(0.5, 1.0), repeats=2, cycles=(3, 3))


def one_run(effect: str | None, seed: int, design: dict = DESIGN) -> dict:
    rng = np.random.default_rng(seed)
    hidden = {} if effect is None else {effect: draw_hidden(effect, rng)}
    started = time.perf_counter()
    run = hidden_effect_run(hidden, seed=seed, **design)
    res = run.result
    # an effect found partial (its strength not constant) is not named as the cause
    named = [n for n in res.named if n.get("role", "cause") == "cause"]
    first = named[0] if named else None
    truth = run.truth(effect) if effect else None
    covers = (
        bool(first and first["ci"] and first["ci"][0] <= truth <= first["ci"][1])
        if (effect and first and first["effect"] == effect)
        else False
    )
    halved = res.gap_after <= 0.5 * res.gap_before
    return {
        "hidden": effect or "none",
        "seed": seed,
        "truth": truth,
        "first_named": first["effect"] if first else "nothing",
        "all_named": ";".join(n["candidate"] for n in named),
        "partial": ";".join(n["candidate"] for n in res.named if n.get("role") == "partial"),
        "value": first["value"] if first else None,
        "ci_low": first["ci"][0] if first and first["ci"] else None,
        "ci_high": first["ci"][1] if first and first["ci"] else None,
        "covers": covers,
        "gap_before": res.gap_before,
        "gap_after": res.gap_after,
        "halved": halved,
        "hit": (first is not None and first["effect"] == effect and covers and halved)
        if effect
        else not named,
        # a learned correction added (the null control must not discover anything)
        "discovered": bool(res.discovery is not None and res.discovery.significant),
        "workflow_seconds": res.seconds,
        "total_seconds": time.perf_counter() - started,
    }


#: Physics the discovered term should resemble when an effect is withheld (simple forms).
EXPECTED_PHYSICS = {
    "body_inertia": "inertia",
    "hinge_damping": "damping",
    "medium_compaction": "compaction",
    "asymmetric_drag": "asymmetric drag",
}


#: Hidden effects and the library candidate that can only approximate each one's form.
FORM_MISMATCH = {"hinge_friction": "hinge_damping", "medium_compaction": "drag_anisotropy"}


def withheld_run(effect: str, seed: int) -> dict:
    """Hide ``effect`` and exclude it from the candidates; what does the workflow say?"""
    from suds_exp.discrepancy import DiscrepancyOptions

    rng = np.random.default_rng(seed)
    hidden = {effect: draw_hidden(effect, rng)}
    started = time.perf_counter()
    opts = DiscrepancyOptions(seed=seed, exclude=(effect,))
    res = hidden_effect_run(hidden, seed=seed, options=opts, **DESIGN).result
    d = res.discovery
    causes = [n["candidate"] for n in res.named if n["role"] == "cause"]
    partial = [n["candidate"] for n in res.named if n["role"] == "partial"]
    return {
        "withheld": effect,
        "seed": seed,
        "truth": run_truth(hidden, effect),
        "named": ";".join(causes) or "nothing",
        "wrong_name": bool(causes),
        "partial": ";".join(partial),
        # the share of the held-out gap the partial candidates closed before the correction
        "gap_closed_by_partial": 1 - res.gap_after / res.gap_before if partial else 0.0,
        "gap_closed_total": 1 - res.gap_after_correction / res.gap_before,
        "unexplained": d is not None or bool(partial),
        "discovered": bool(d is not None and d.significant),
        "gap_before": res.gap_before,
        "gap_model": res.gap_after,
        "gap_corrected": res.gap_after_correction,
        "gap_closed_by_term": d.improvement if d is not None else 0.0,
        "p_term": d.p_value if d is not None else None,
        "physics": d.physics if d is not None else "",
        "physics_body": d.physics_by_part["body"] if d is not None else "",
        "physics_passive": d.physics_by_part["passive"] if d is not None else "",
        "expected": EXPECTED_PHYSICS.get(effect, ""),
        "leading": ";".join(d.leading[:3]) if d is not None else "",
        "equations": " | ".join(d.equations()) if d is not None else "",
        "workflow_seconds": res.seconds,
        "total_seconds": time.perf_counter() - started,
    }


def run_truth(hidden: dict, effect: str) -> float:
    _, param = HIDDEN[effect]
    return float(hidden[effect][param])


def withheld_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per withheld effect: seeds, wrong-name rate (a candidate named as the cause), rate
    and share closed of candidates reported as partial explanations, unexplained rate,
    gap closed by the discovered term (median, of the gap it was given; 0 when none was
    added), total gap closed, physics-match rates (over all channels, the body velocity's
    and the passive shape's terms; NaN for a table written before the last two were
    recorded), leading features."""
    rows = []
    for effect, g in table.groupby("withheld"):
        expected = g["expected"].notna().all() and g["expected"].astype(str).ne("").all()
        closed = np.where(g["discovered"], g["gap_closed_by_term"], 0.0)
        lead = g["leading"].fillna("").str.split(";").str[0]
        part = g["partial"].astype("string").fillna("")
        rows.append(
            {
                "withheld": effect,
                "seeds": len(g),
                "wrong_name_rate": g["wrong_name"].mean(),
                "partial_rate": float((part != "").mean()),
                "partial_named": ", ".join(
                    f"{k} ({v})" for k, v in part[part != ""].value_counts().items()
                ),
                "median_closed_by_partial": float(np.median(g["gap_closed_by_partial"])),
                "median_closed_total": float(np.median(g["gap_closed_total"])),
                "unexplained_rate": g["unexplained"].mean(),
                "added_rate": g["discovered"].mean(),
                "median_gap_closed": float(np.median(closed)),
                "closed_ge_50pct": float(np.mean(closed >= 0.5)),
                **{
                    f"{col}_match": float((g[col] == g["expected"]).mean())
                    if expected and col in g
                    else np.nan
                    for col in ("physics", "physics_body", "physics_passive")
                },
                "leading_features": ", ".join(
                    f"{k} ({v})" for k, v in lead[lead != ""].value_counts().items()
                ),
            }
        )
    return pd.DataFrame(rows)


def default_timing(seed: int = 0, withheld: bool = False) -> dict:
    """The workflow on the default dataset (5 gaits x 3 frequencies x 4 repeats, 10-30
    cycles) with body inertia hidden; ``withheld``: also excluded from the candidates, so
    the run ends with the learned correction (discovery)."""
    from suds_exp.discrepancy import DiscrepancyOptions

    rng = np.random.default_rng(seed)
    hidden = {"body_inertia": draw_hidden("body_inertia", rng)}
    opts = DiscrepancyOptions(seed=seed, exclude=("body_inertia",) if withheld else ())
    cpu = time.process_time()
    run = hidden_effect_run(
        hidden, seed=seed, gaits=GAITS, repeats=4, cycles=(10, 30), options=opts
    )
    d = run.result.discovery
    return {
        "hidden": hidden,
        "withheld": withheld,
        "discovery_seconds": d.seconds if d is not None else None,
        "discovered": bool(d is not None and d.significant),
        "named": [n["candidate"] for n in run.result.named],
        "workflow_seconds": run.result.seconds,
        "workflow_cpu_seconds": run.result.cpu_seconds,
        "cpu_seconds_incl_simulation_and_preprocessing": time.process_time() - cpu,
        "n_trials": len(run.result.train_trials) + len(run.result.test_trials),
    }


def detection_run(effect: str, value: float, seed: int) -> dict:
    """One run with ``effect`` hidden at ``value`` of its parameter: the first step's
    verdict on that effect's candidate."""
    fixed, param = HIDDEN[effect]
    run = hidden_effect_run({effect: {**fixed, param: value}}, seed=seed, **DESIGN)
    res = run.result
    cand = next(
        c
        for c in res.steps[0].candidates
        if c.candidate.effect == effect and c.candidate.param == param
    )
    ci = cand.ci or (np.nan, np.nan)
    return {
        "effect": effect,
        "value": value,
        "seed": seed,
        "named_first": bool(res.named and res.named[0]["effect"] == effect),
        "p": cand.p_value,
        "p_adjusted": cand.p_adjusted,
        "removed": cand.improvement,
        "fitted": cand.value,
        "ci_lo": ci[0],
        "ci_hi": ci[1],
        "gap": res.gap_before,
    }


def detection(effect: str, values: list[float], seeds: list[int], out: Path) -> None:
    """Run `detection_run` over values x seeds (rows already in ``out`` are kept and
    skipped) and print the per-value summary."""
    plan = [(value, seed) for value in values for seed in seeds]
    table = run_plan(plan, out, "value", lambda value, seed: detection_run(effect, value, seed))
    table = table[table["effect"] == effect]
    summary = table.groupby("value").agg(
        seeds=("seed", "size"),
        named_first=("named_first", "mean"),
        p_min=("p", "min"),
        p_max=("p", "max"),
        p_adjusted_min=("p_adjusted", "min"),
        p_adjusted_max=("p_adjusted", "max"),
        removed_median=("removed", "median"),
        fitted_median=("fitted", "median"),
        gap_median=("gap", "median"),
    )
    print(f"\ndetection of {effect} ({HIDDEN[effect][1]}) on the slow tests' design")
    print(summary.to_string())


def run_plan(plan, out: Path, key: str, run) -> pd.DataFrame:
    """Run ``run(item, seed)`` for each planned pair not yet in ``out`` (column ``key``
    holds the item: the effect, "none" for None, or a parameter value), appending each
    row as it finishes."""
    done = pd.read_csv(out) if out.exists() else pd.DataFrame()
    have = set(zip(done.get(key, []), done.get("seed", []), strict=False))
    for effect, seed in plan:
        if ("none" if effect is None else effect, seed) in have:
            continue
        row = run(effect, seed)
        print(row, flush=True)
        pd.DataFrame([row]).to_csv(out, mode="a", header=not out.exists(), index=False)
    return pd.read_csv(out)


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0], "a smoke run: one small hidden run")
    ap.add_argument("--seeds", type=int, default=3, help="seeds per hidden effect")
    ap.add_argument("--first-seed", type=int, default=0, help="start at seed 100 + this")
    ap.add_argument(
        "--summary-only",
        nargs="*",
        type=Path,
        help="print the summary of these result files (of parallel runs) and stop",
    )
    ap.add_argument("--null-seeds", type=int, default=4, help="seeds of the null control")
    ap.add_argument("--effects", default=",".join(sorted(HIDDEN)))
    ap.add_argument("--out", type=Path, default=Path("bench-discrepancy.csv"))
    ap.add_argument("--timing-only", action="store_true")
    ap.add_argument("--no-timing", action="store_true")
    ap.add_argument("--timing-repeats", type=int, default=1, help="default-dataset runs")
    ap.add_argument(
        "--timing-withheld",
        action="store_true",
        help="time with body inertia also excluded from the candidates (discovery runs)",
    )
    ap.add_argument(
        "--withheld", action="store_true", help="hide each effect and exclude it from candidates"
    )
    ap.add_argument(
        "--form-mismatch",
        action="store_true",
        help="--withheld on the effects of FORM_MISMATCH (a near candidate of another form)",
    )
    ap.add_argument("--detection", metavar="EFFECT", help="detection limit of this effect")
    ap.add_argument("--values", help="with --detection: parameter values, comma-separated")
    ap.add_argument("--detection-seeds", default="11,12,13", help="with --detection")
    args = ap.parse_args(argv)
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-discrepancy-quick-") as tmp:
            quick_run = functools.partial(one_run, design=QUICK_DESIGN)
            table = run_plan([("body_inertia", 100)], Path(tmp) / "quick.csv", "hidden", quick_run)
        print(f"workflow time {table['workflow_seconds'].median():.1f} s")
        return
    if args.detection:
        if args.detection not in HIDDEN:
            ap.error(f"--detection {args.detection}: expected one of {', '.join(sorted(HIDDEN))}")
        if not args.values:
            ap.error("--detection needs --values, e.g. --values 1.3,1.4,1.5")
        values = [float(v) for v in (args.values or "").split(",") if v]
        seeds = [int(v) for v in args.detection_seeds.split(",") if v]
        detection(args.detection, values, seeds, args.out)
        return
    if args.form_mismatch:
        args.withheld, args.effects = True, ",".join(FORM_MISMATCH)
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    if args.withheld:
        # seed-major: an interrupted run still covers every effect
        plan = [(e, 100 + s) for s in seeds for e in args.effects.split(",")]
        if args.summary_only is not None:
            table = pd.concat([pd.read_csv(f) for f in args.summary_only], ignore_index=True)
        else:
            table = run_plan(plan, args.out, "withheld", withheld_run)
        print("\nwithheld effects (hidden in the data, excluded from the candidates)")
        print(withheld_summary(table).to_string(index=False))
        print(f"median workflow time per run {table['workflow_seconds'].median():.1f} s")
        return
    if not args.timing_only:
        plan = [(e, 100 + s) for e in args.effects.split(",") if e for s in seeds]
        plan += [(None, 500 + s) for s in range(args.null_seeds)]
        if args.summary_only is not None:
            table = pd.concat([pd.read_csv(f) for f in args.summary_only], ignore_index=True)
        else:
            table = run_plan(plan, args.out, "hidden", one_run)
        print("\nconfusion matrix (rows: hidden effect, columns: first named; counts of seeds)")
        print(pd.crosstab(table["hidden"], table["first_named"]).to_string())
        eff = table[table["hidden"] != "none"]
        null = table[table["hidden"] == "none"]
        print("\nper effect: hit rate (named first, interval covers truth, gap halved)")
        print(eff.groupby("hidden")[["hit", "covers", "halved"]].mean().to_string())
        if len(eff):
            print(f"overall hit rate {eff['hit'].mean():.3f} over {len(eff)} runs")
        if len(null):
            print(f"null control: nothing named in {null['hit'].mean():.3f} of {len(null)} seeds")
            if "discovered" in null:
                clean = (~null["discovered"].fillna(False).astype(bool)).mean()
                print(f"null control: no correction discovered in {clean:.3f} of {len(null)} seeds")
        print(f"median workflow time per run {table['workflow_seconds'].median():.1f} s")
    # a summary of stored results is not a new measurement: no timing run behind it
    if not args.no_timing and args.summary_only is None:
        runs = [default_timing(seed, args.timing_withheld) for seed in range(args.timing_repeats)]
        for t in runs:
            print(f"\ndefault dataset: {t}")
        wall = np.median([t["workflow_seconds"] for t in runs])
        cpu = np.median([t["workflow_cpu_seconds"] for t in runs])
        print(f"median workflow time on the default dataset: {wall:.0f} s wall, {cpu:.0f} s CPU")


if __name__ == "__main__":
    main()
