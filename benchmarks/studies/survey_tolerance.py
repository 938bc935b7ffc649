"""The survey baselines' own randomness, and faster recipes judged against it.

Usage (from the repository root)::

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python -m benchmarks.studies.survey_tolerance \
        [--db tolerance.duckdb] [--gaits O] [--conditions O@0.5,O@1] [--boots 3] \
        [--sweep 1,2,4,8,16,30,48] [--seeds 5] [--recipes all] [--rows rows.csv] [--jobs 1]

Protocol (docs/results/speed.md, "Session 15: the survey's baselines"):

1. Draws: the same-condition sweep of ``--conditions`` (train = test condition, every size
   of ``--sweep``, ``--boots`` draws each), made exactly as a per-condition survey
   campaign makes them (`benchmarks.studies.survey --per-condition`: the default simulated
   dataset's ``--gaits``, preprocessed as ``v1``, decimated to the whole dataset's samples
   per cycle; a draw's seed is its key's hash).
2. Seeds: seed 0 of a learner on a draw is the campaign's own (`Draw.model_seed(name)`);
   seed k > 0 is `Draw.model_seed(name + "|seed" + k)`. Every recipe of a learner gets
   the same seeds on the same draws (paired).
3. Tolerance of learner L at size n: m_s(n) = median over the draws of rmse_vx with seed
   s (the survey's statistic, with one seed); tol(n) = 2 x the standard deviation
   (ddof 1) of m_s(n) over the seeds, old recipe.
4. A candidate recipe is accepted when at every size |M_cand(n) - M_old(n)| <= tol(n),
   M = median of rmse_vx over draws and seeds; for the MLP also when its MLP / GMR data
   ratio (`efficiency_ratio`, seed 0) lies in the old recipe's 95 % bootstrap
   interval, and its cycles-to-target cells are printed beside the old ones.

Every job's row (rmse_vx, CPU seconds of fit + predict) goes to ``--rows`` (CSV); a
second run reads it and fits only what is missing, so the tables can be re-printed
without refitting (``--jobs 0``: only print).
"""

from __future__ import annotations

import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pandas as pd

from benchmarks._data import decimated, ensure_data
from benchmarks._harness import script_parser
from suds_exp.models.baselines import JUDGED_RECIPES

CANDIDATES = {
    "MLP": {
        "max_iter=100": {"max_iter": 100},
        "max_iter=150": {"max_iter": 150},
        "tol=1e-3": {"tol": 1e-3},
        "hidden=32x32": {"hidden_layer_sizes": [32, 32]},
        "hidden=32x32,max_iter=100": {"hidden_layer_sizes": [32, 32], "max_iter": 100},
    },
    "GBT": {
        "lr=0.2,max_iter=100": {"learning_rate": 0.2, "max_iter": 100},
        "max_bins=63": {"max_bins": 63},
        "max_leaf_nodes=15": {"max_leaf_nodes": 15},
        "n_iter_no_change=5": {"n_iter_no_change": 5},
    },
    "KRR": {"n_components=150": {"n_components": 150}},
}
LEARNERS = ("MLP", "MLP+SUDS", "GBT", "KRR")


def base_of(learner: str) -> str:
    return learner.removesuffix("+SUDS")


def recipes(which: str) -> list[tuple[str, str, dict]]:
    """(learner, recipe label, parameters) to run; GMR once as the headline's reference."""
    out = [("GMR", "old", {})]
    for learner in LEARNERS:
        old = JUDGED_RECIPES[base_of(learner)]  # the "old" recipe: what candidates change
        out.append((learner, "old", dict(old)))
        if which == "all":
            for label, params in CANDIDATES[base_of(learner)].items():
                out.append((learner, label, {**old, **params}))
    return out


_STATE: dict = {}


def _init(samples: pd.DataFrame, conditions: list, boots: int, sweep: list[int]) -> None:
    from suds_exp.campaign import SampleBank, enumerate_draws
    from suds_exp.campaign.sampling import infeasible_cells

    draws, banks = [], {}
    for cond in conditions:
        bank = SampleBank.build(samples, [cond])
        skip = infeasible_cells(bank, [cond], [cond], 30, sweep)
        name = f"survey-{cond[0]}@{cond[1]:g}"
        for d in enumerate_draws(name, [cond], [cond], boots, 30, sweep, skip=skip):
            draws.append(d)
            banks[d] = bank
    _STATE.update(draws=draws, banks=banks)


def _task(learner: str, label: str, params: dict, seed: int) -> list[dict]:
    """Rows of one (recipe, seed) on every draw."""
    from threadpoolctl import threadpool_limits

    from suds_exp.campaign.job import run_draw

    rows = []
    with threadpool_limits(limits=1):
        for d in _STATE["draws"]:
            p = dict(params)
            if learner != "GMR":
                tag = learner if seed == 0 else f"{learner}|seed{seed}"
                p["random_state"] = d.model_seed(tag)
            c0 = time.process_time()
            (row,) = run_draw(_STATE["banks"][d], d, [learner], {learner: p}, 30)
            cpu = time.process_time() - c0
            rows.append(
                {
                    "learner": learner,
                    "recipe": label,
                    "seed": seed,
                    "train_gait": row["train_gait"],
                    "train_frequency_hz": row["train_frequency_hz"],
                    "test_gait": row["test_gait"],
                    "test_frequency_hz": row["test_frequency_hz"],
                    "boot": row["boot"],
                    "n_cycles": row["n_cycles"],
                    "rmse_vx": row["rmse_vx"],
                    "cpu_s": cpu,
                    "error": row["error"],
                }
            )
    return rows


def load_samples(db: str, gaits: list[str], spec: str):
    """The default dataset's ``gaits`` (simulated into ``db`` if empty), decimated as a
    per-condition survey does it, and the conditions of ``spec``."""
    from suds_exp.campaign.bank import rounded_conditions
    from suds_exp.campaign.conditions import select_conditions
    from suds_exp.store import Store

    store = Store(db)
    ensure_data(store, gaits)
    samples = decimated(store, "v1")
    conditions = select_conditions(spec, rounded_conditions(samples), "--conditions")
    return samples, conditions


def tolerance(rows: pd.DataFrame, learner: str) -> pd.DataFrame:
    """`seed_tolerance` of the old recipe, and the median per-draw range over seeds."""
    from suds_exp.analysis.survey import seed_tolerance

    old = rows[(rows["learner"] == learner) & (rows["recipe"] == "old")]
    per_draw = old.groupby(["n_cycles", "train_frequency_hz", "boot"])["rmse_vx"]
    draw_range = (per_draw.max() - per_draw.min()).groupby("n_cycles").median()
    return seed_tolerance(old).assign(draw_range=draw_range)


def judge(rows: pd.DataFrame, learner: str, tol: pd.DataFrame) -> pd.DataFrame:
    """One row per recipe: median rmse_vx minus the old recipe's per size, whether every
    size is within tol, CPU seconds of a 30-cycle job (median) and the speed-up."""
    from suds_exp.analysis.survey import within_seed_tolerance

    out = []
    mine = rows[rows["learner"] == learner]
    old_cpu = mine[(mine["recipe"] == "old") & (mine["n_cycles"] == 30)]["cpu_s"].median()
    for label, r in mine.groupby("recipe", sort=False):
        diff, ok = within_seed_tolerance(r, tol)
        cpu30 = r[r["n_cycles"] == 30]["cpu_s"].median()
        out.append(
            {
                "recipe": label,
                **{f"d{n}": v for n, v in diff.items()},
                "worst/tol": float((diff.abs() / tol["tol"]).max()),
                "within": ok,
                "cpu30": cpu30,
                "speed-up": old_cpu / cpu30,
                "seeds": r["seed"].nunique(),
            }
        )
    return pd.DataFrame(out)


def headline(rows: pd.DataFrame, n_boot: int) -> pd.DataFrame:
    """MLP / GMR data ratio (seed 0) and its interval per MLP recipe; cycles to GMR's
    30-cycle error per test frequency."""
    from suds_exp.analysis.survey import cycles_to_target, efficiency_ratio

    gmr = rows[rows["learner"] == "GMR"]
    out = []
    mlp = rows[(rows["learner"] == "MLP") & (rows["seed"] == 0)]
    for label, r in mlp.groupby("recipe", sort=False):
        res = pd.concat([gmr, r]).rename(columns={"learner": "model"})
        res["model"] = res["model"].astype(str)
        x = efficiency_ratio(res, "MLP", "GMR", 30, n_boot=n_boot)
        cyc = cycles_to_target(res, 30)
        cyc = cyc[cyc["model"] == "MLP"]
        out.append(
            {
                "recipe": label,
                "ratio": x["ratio"],
                "low": x["low"],
                "high": x["high"],
                "unreached": x["unreached"],
                **{
                    f"to GMR30 @{f:g}Hz": v
                    for f, v in zip(cyc["frequency_hz"], cyc.iloc[:, -1], strict=True)
                },
            }
        )
    return pd.DataFrame(out)


def main(argv=None) -> int:
    ap = script_parser(__doc__.splitlines()[0], "a smoke run: O at 1 Hz, GMR and MLP")
    ap.add_argument("--db", default="tolerance.duckdb")
    ap.add_argument("--gaits", default="O")
    ap.add_argument("--conditions", default="O@0.5,O@1")
    ap.add_argument("--boots", type=int, default=3)
    ap.add_argument("--sweep", default="1,2,4,8,16,30,48")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--recipes", choices=("all", "old"), default="all")
    ap.add_argument("--only", default=None, help="learners to run, comma-separated")
    ap.add_argument("--rows", default="tolerance_rows.csv")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--n-boot", type=int, default=1000)
    a = ap.parse_args(argv)
    if a.quick:
        with tempfile.TemporaryDirectory(prefix="suds-tolerance-quick-") as tmp:
            a.db, a.rows = str(Path(tmp) / "quick.duckdb"), str(Path(tmp) / "rows.csv")
            a.gaits, a.conditions, a.boots, a.sweep, a.seeds = "O", "O@1", 1, "2,30", 2
            a.recipes, a.only, a.jobs, a.n_boot = "old", "GMR,MLP", 1, 50
            return study(a)
    return study(a)


def study(a) -> int:
    sweep = [int(x) for x in a.sweep.split(",")]
    path = Path(a.rows)
    rows = pd.read_csv(path) if path.exists() else pd.DataFrame()
    done = set()
    if len(rows):
        done = set(rows[["learner", "recipe", "seed"]].itertuples(index=False, name=None))
    only = set(a.only.split(",")) if a.only else None
    todo = [
        (learner, label, params, s)
        for learner, label, params in recipes(a.recipes)
        if only is None or learner in only
        for s in range(1 if learner == "GMR" else a.seeds)
        if (learner, label, s) not in done
    ]
    if a.jobs > 0 and todo:
        samples, conditions = load_samples(a.db, a.gaits.split(","), a.conditions)
        with ProcessPoolExecutor(
            a.jobs, initializer=_init, initargs=(samples, conditions, a.boots, sweep)
        ) as pool:
            futures = [pool.submit(_task, *t) for t in todo]
            for t, f in zip(todo, futures, strict=True):
                new = pd.DataFrame(f.result())
                rows = pd.concat([rows, new], ignore_index=True)
                rows.to_csv(path, index=False)
                print(f"done {t[0]} {t[1]} seed {t[3]}: {new['cpu_s'].sum():.1f} CPU s", flush=True)
    errors = rows[rows["error"].notna()]
    if len(errors):
        failed = errors[["learner", "recipe", "error"]].drop_duplicates()
        print(f"{len(errors)} failed jobs:\n{failed.to_string(index=False)}")
    with pd.option_context("display.width", 250, "display.max_columns", 40):
        for learner in LEARNERS:
            if learner not in set(rows["learner"]):
                continue
            tol = tolerance(rows, learner)
            print(f"\n## {learner}: old recipe, rmse_vx (mm/s) per size")
            # 3 significant digits: KRR's spread is ~1e-7 mm/s
            print(tol.to_string(float_format=lambda v: f"{v:.3g}"))
            print(f"\n{learner}: median rmse_vx - the old recipe's per size; within: |d| <= tol")
            print(judge(rows, learner, tol).round(4).to_string(index=False))
        if {"MLP", "GMR"} <= set(rows["learner"]):
            print("\n## MLP / GMR data ratio at GMR's 30-cycle error (seed 0, 95 % bootstrap)")
            print(headline(rows, a.n_boot).round(3).to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
