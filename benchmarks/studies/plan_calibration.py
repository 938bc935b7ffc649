"""How far to trust the gait goal's "predicted X +/- Y": each planned trial's prediction
against what the trial then did.

Every gait-goal iteration of `suds-exp plan loop` recommends a gait with a predicted
forward displacement per cycle (the GMR map's point prediction, mm) and a spread
(`suds_exp.plan.MapEnsemble.forward`, mm), both kept in the iteration's ``plan.json``.
The trial is then recorded; what it did is its measured forward displacement per cycle
(`suds_exp.plan.loop.measured_forward`: its own body twists over its whole periods).
For each planned trial this reads

    z = (measured - predicted) / spread

and reports, per loop and pooled, the RMS of z (1 for a calibrated spread), the share of
trials within 1 and 2 spreads (68 % and 95 % for a calibrated normal one), the median of
measured - predicted, and the share of trials that went further than every gait recorded
before them; separately for trials inside the trust region and looks beyond it.

It reads the loops the adaptive benchmark stored (its ``--out`` folders, each with
``work-gait-plan-*/plan.duckdb``) and runs nothing but the measurement of what they
recorded::

    python -m benchmarks.studies.plan_calibration --runs /tmp/lead/r3a,/tmp/lead/r3b

``--quick`` runs one tiny loop (warm-up and two planned trials) into a temporary folder
and reads it.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks._harness import script_parser, table
from suds_exp.plan import LoopOptions, load_loop, run_loop
from suds_exp.plan.loop import measured_forward
from suds_exp.preprocess import get_version
from suds_exp.store import Store


def planned_trials(work: Path) -> pd.DataFrame:
    """One row a planned trial of the gait-goal loop stored in ``work`` (plan.duckdb and
    plan/<loop>/it<k>/plan.json): predicted and spread (mm per cycle, from plan.json),
    measured (mm per cycle), beyond (a look beyond the trust region), best_before (the
    furthest any earlier trial of the loop went, mm per cycle)."""
    store = Store(work / "plan.duckdb")
    loops = store.query_df("SELECT id, name, prep_version FROM plan_loops WHERE goal = 'gait'")
    rows = []
    for loop in loops.itertuples():
        iterations = load_loop(store, int(loop.id))
        samples = get_version(store, int(loop.prep_version)).samples()
        measured = measured_forward(samples, 0.5)
        best = -math.inf
        for it in iterations.itertuples():
            got = measured.get(str(it.trial_gait), math.nan)
            plan = work / "plan" / loop.name / f"it{it.iteration}" / "plan.json"
            if it.iteration > 0 and plan.is_file():
                doc = json.loads(plan.read_text())
                rows.append(
                    {
                        "loop": f"{work.name}",
                        "iteration": int(it.iteration),
                        "predicted": float(doc["mean"]),
                        "spread": float(doc["sd"]),
                        "measured": got,
                        "beyond": "beyond the trust radius" in doc["reason"],
                        "best_before": best,
                    }
                )
            if not math.isnan(got):
                best = max(best, got)
    return pd.DataFrame(rows)


def calibration(trials: pd.DataFrame) -> dict:
    """The summary of `planned_trials` rows: n, rms_z, within_1 and within_2 (shares),
    median_error_mm (measured - predicted), improved (share that went further than every
    earlier trial)."""
    t = trials.dropna(subset=["measured"])
    if t.empty:
        return {"n": 0}
    z = (t["measured"] - t["predicted"]) / t["spread"]
    return {
        "n": int(len(t)),
        "rms_z": round(float(np.sqrt(np.mean(z**2))), 2),
        "within_1": round(float(np.mean(np.abs(z) <= 1)), 3),
        "within_2": round(float(np.mean(np.abs(z) <= 2)), 3),
        "median_error_mm": round(float(np.median(t["measured"] - t["predicted"])), 2),
        "improved": round(float(np.mean(t["measured"] > t["best_before"])), 3),
    }


def _row(label: str, c: dict) -> list:
    if not c["n"]:
        return [label, 0, "", "", "", "", ""]
    share = [f"{100 * c[k]:.0f} %" for k in ("within_1", "within_2")]
    return [label, c["n"], c["rms_z"], *share, c["median_error_mm"], f"{100 * c['improved']:.0f} %"]


def report(trials: pd.DataFrame) -> dict:
    """Print the table (each loop, then pooled: all, inside the trust region, beyond it)
    and return the pooled summaries."""
    rows = [_row(name, calibration(part)) for name, part in trials.groupby("loop")]
    pooled = {
        "all": calibration(trials),
        "inside": calibration(trials[~trials["beyond"]]),
        "beyond": calibration(trials[trials["beyond"]]),
    }
    rows += [_row(f"pooled: {k}", c) for k, c in pooled.items()]
    header = ["loop", "trials", "RMS z", "within 1", "within 2", "median error mm", "improved"]
    print(table(header, rows))
    return pooled


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0], "one tiny loop, read back")
    ap.add_argument("--runs", default="", help="comma-separated adaptive --out folders")
    ap.add_argument("--out", type=Path, default=None, help="write calibration.json here")
    args = ap.parse_args(argv)
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-calibration-quick-") as tmp:
            work = Path(tmp) / "work-gait-plan-s0"
            work.mkdir()
            opts = LoopOptions(budget_cycles=9, cycles=2, n_boot=2, max_evals=20)
            run_loop(Store(work / "plan.duckdb"), opts, out=work / "plan")
            report(planned_trials(work))
        return
    folders = [Path(p) for p in args.runs.split(",") if p]
    works = sorted(w for f in folders for w in f.glob("work-gait-plan-*") if w.is_dir())
    if not works:
        ap.error("--runs: no work-gait-plan-* folder with a stored loop in " + args.runs)
    trials = pd.concat([planned_trials(w) for w in works], ignore_index=True)
    pooled = report(trials)
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "calibration.json").write_text(json.dumps(pooled, indent=2))


if __name__ == "__main__":
    main()
