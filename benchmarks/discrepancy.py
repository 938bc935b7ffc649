"""Benchmark of the discrepancy workflow: confusion matrix over hidden effects x seeds,
null control, and the workflow's time on the default dataset.

Every run simulates "measured" data with one effect hidden (its parameter drawn from the
realistic range with the run's seed), sends it through files -> ingest -> preprocess and
runs the workflow from the nominal model. A hit: the hidden effect is named first, its
interval covers the true value and the held-out gap at least halves.

    .venv/bin/python benchmarks/discrepancy.py --seeds 3 --null-seeds 4 --out bench-disc.csv
    .venv/bin/python benchmarks/discrepancy.py --timing-only     # default dataset timing
    .venv/bin/python benchmarks/discrepancy.py --withheld --seeds 5 --out bench-withheld.csv

`--withheld`: each effect is hidden in the data AND excluded from the candidates
(`--exclude-candidates`); per effect it prints the wrong-name rate (anything named), the
rate at which the gap is reported as unexplained by the library, the held-out gap closed
by the discovered correction, and its leading features.

Rows are appended to --out as runs finish, so an interrupted benchmark keeps its results
(and a re-run skips the rows already there).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.robot import GAITS
from suds_exp.testing.hidden_effects import HIDDEN, draw_hidden, hidden_effect_run

DESIGN = dict(gaits=("S+", "O", "D+"), frequencies_hz=(1 / 3, 0.5, 1.0), repeats=4, cycles=(4, 6))


def one_run(effect: str | None, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    hidden = {} if effect is None else {effect: draw_hidden(effect, rng)}
    started = time.perf_counter()
    run = hidden_effect_run(hidden, seed=seed, **DESIGN)
    res = run.result
    named = res.named
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


def withheld_run(effect: str, seed: int) -> dict:
    """Hide ``effect`` and exclude it from the candidates; what does the workflow say?"""
    from suds_exp.discrepancy import DiscrepancyOptions

    rng = np.random.default_rng(seed)
    hidden = {effect: draw_hidden(effect, rng)}
    started = time.perf_counter()
    opts = DiscrepancyOptions(seed=seed, exclude=(effect,))
    res = hidden_effect_run(hidden, seed=seed, options=opts, **DESIGN).result
    d = res.discovery
    return {
        "withheld": effect,
        "seed": seed,
        "truth": run_truth(hidden, effect),
        "named": ";".join(n["candidate"] for n in res.named) or "nothing",
        "wrong_name": bool(res.named),
        "unexplained": d is not None,
        "discovered": bool(d is not None and d.significant),
        "gap_before": res.gap_before,
        "gap_model": res.gap_after,
        "gap_corrected": res.gap_after_correction,
        "gap_closed_by_term": d.improvement if d is not None else 0.0,
        "p_term": d.p_value if d is not None else None,
        "physics": d.physics if d is not None else "",
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
    """Per withheld effect: seeds, wrong-name rate, unexplained rate, gap closed by the
    discovered term (median; 0 when none was added), physics-match rate, leading features."""
    rows = []
    for effect, g in table.groupby("withheld"):
        closed = np.where(g["discovered"], g["gap_closed_by_term"], 0.0)
        lead = g["leading"].fillna("").str.split(";").str[0]
        rows.append(
            {
                "withheld": effect,
                "seeds": len(g),
                "wrong_name_rate": g["wrong_name"].mean(),
                "unexplained_rate": g["unexplained"].mean(),
                "added_rate": g["discovered"].mean(),
                "median_gap_closed": float(np.median(closed)),
                "closed_ge_50pct": float(np.mean(closed >= 0.5)),
                "physics_match": float((g["physics"] == g["expected"]).mean())
                if g["expected"].fillna("").ne("").all()
                else np.nan,
                "leading_features": ", ".join(
                    f"{k} ({v})" for k, v in lead[lead != ""].value_counts().items()
                ),
            }
        )
    return pd.DataFrame(rows)


def default_timing(seed: int = 0) -> dict:
    """The workflow on the default dataset (5 gaits x 3 frequencies x 4 repeats, 10-30
    cycles) with body inertia hidden."""
    rng = np.random.default_rng(seed)
    hidden = {"body_inertia": draw_hidden("body_inertia", rng)}
    cpu = time.process_time()
    run = hidden_effect_run(
        hidden, seed=seed, gaits=GAITS, repeats=4, cycles=(10, 30)
    )
    return {
        "hidden": hidden,
        "named": [n["candidate"] for n in run.result.named],
        "workflow_seconds": run.result.seconds,
        "workflow_cpu_seconds": run.result.cpu_seconds,
        "cpu_seconds_incl_simulation_and_preprocessing": time.process_time() - cpu,
        "n_trials": len(run.result.train_trials) + len(run.result.test_trials),
    }


def run_plan(plan, out: Path, key: str, run) -> pd.DataFrame:
    """Run ``run(effect, seed)`` for each planned pair not yet in ``out`` (column ``key``
    holds the effect, "none" for None), appending each row as it finishes."""
    done = pd.read_csv(out) if out.exists() else pd.DataFrame()
    have = set(zip(done.get(key, []), done.get("seed", []), strict=False))
    for effect, seed in plan:
        if ((effect or "none"), seed) in have:
            continue
        row = run(effect, seed)
        print(row, flush=True)
        pd.DataFrame([row]).to_csv(out, mode="a", header=not out.exists(), index=False)
    return pd.read_csv(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3, help="seeds per hidden effect")
    ap.add_argument("--null-seeds", type=int, default=4, help="seeds of the null control")
    ap.add_argument("--effects", default=",".join(sorted(HIDDEN)))
    ap.add_argument("--out", type=Path, default=Path("bench-discrepancy.csv"))
    ap.add_argument("--timing-only", action="store_true")
    ap.add_argument("--no-timing", action="store_true")
    ap.add_argument("--timing-repeats", type=int, default=1, help="default-dataset runs")
    ap.add_argument(
        "--withheld", action="store_true", help="hide each effect and exclude it from candidates"
    )
    args = ap.parse_args()
    if args.withheld:
        # seed-major: an interrupted run still covers every effect
        plan = [(e, 100 + s) for s in range(args.seeds) for e in args.effects.split(",")]
        table = run_plan(plan, args.out, "withheld", withheld_run)
        print("\nwithheld effects (hidden in the data, excluded from the candidates)")
        print(withheld_summary(table).to_string(index=False))
        print(f"median workflow time per run {table['workflow_seconds'].median():.1f} s")
        return
    if not args.timing_only:
        plan = [(e, 100 + s) for e in args.effects.split(",") for s in range(args.seeds)]
        plan += [(None, 500 + s) for s in range(args.null_seeds)]
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
    if not args.no_timing:
        runs = [default_timing(seed) for seed in range(args.timing_repeats)]
        for t in runs:
            print(f"\ndefault dataset: {t}")
        wall = np.median([t["workflow_seconds"] for t in runs])
        cpu = np.median([t["workflow_cpu_seconds"] for t in runs])
        print(f"median workflow time on the default dataset: {wall:.0f} s wall, {cpu:.0f} s CPU")


if __name__ == "__main__":
    main()
