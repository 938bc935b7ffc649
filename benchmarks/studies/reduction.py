"""Passive coordinates beyond PCA: the SUDS learners on PCA, kernel-PCA and autoencoder r_p.

Usage (from the repository root)::

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python -m benchmarks.studies.reduction \
        --db survey.duckdb \
        [--reductions pca,kernel-pca,autoencoder] [--models TLS+SUDS,GMR+SUDS,GMR] \
        [--conditions O@0.5,D+@0.5,S-@1] [--boots 4] [--jobs 2]

``--db`` must hold ingested trials (e.g. the default dataset: ``suds-exp simulate --out
DIR --ingest``). For each reduction the script makes (or reuses, whatever its name) the
preprocessing version of the default parameters with ``reduction=<reduction>``, then runs the
same campaign on it: every reduction's campaign is run in its own copy of the database
under the same campaign name, so the draws (training cycles, test trial) are identical and
the errors are paired. GMR, which does not use r_p, is the control: its errors must not
change with the reduction.

Prints, per learner and reduction: the median RMS error of vx (mm/s) over all pairs and
over same-condition pairs, and the median over draws of the paired ratio error /
error with PCA, with a 95 % bootstrap interval (draws resampled).
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks._data import QUICK_DESIGN, simulated_database
from benchmarks._harness import script_parser
from suds_exp.analysis.queries import load_results
from suds_exp.campaign import run_campaign
from suds_exp.commands.campaign import parse_campaign_options
from suds_exp.preprocess import preprocess
from suds_exp.store import Store

KEY = ["train_gait", "train_frequency_hz", "test_gait", "test_frequency_hz", "boot"]


def ensure_version(store: Store, reduction: str) -> str:
    """The name of the default version with ``reduction`` (made as r-<reduction> if absent)."""
    r = preprocess(store, name=f"r-{reduction}", params={"reduction": reduction}, progress=False)
    ev = ", ".join(f"{100 * v:.1f}%" for v in r.explained_variance_ratio)
    print(f"version {r.name} ({reduction}): explained {ev}; {r.seconds:.0f} s", flush=True)
    return r.name


def paired_ratio(a: np.ndarray, b: np.ndarray, n_boot: int = 2000, seed: int = 0):
    """Median of a / b over draws and its 95 % percentile-bootstrap interval."""
    r = a / b
    rng = np.random.default_rng(seed)
    meds = np.median(r[rng.integers(0, len(r), (n_boot, len(r)))], axis=1)
    return float(np.median(r)), *np.quantile(meds, [0.025, 0.975])


def main(argv=None) -> None:
    p = script_parser(__doc__.splitlines()[0], "a smoke run on a tiny simulated dataset")
    p.add_argument("--db", help="a database with the dataset (required unless --quick)")
    p.add_argument("--reductions", default="pca,kernel-pca,autoencoder")
    p.add_argument("--models", default="TLS+SUDS,GMR+SUDS,GMR")
    p.add_argument("--conditions", default="O@0.5,D+@0.5,S-@1")
    p.add_argument("--boots", type=int, default=4)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--train-cycles", type=int, default=30)
    args = p.parse_args(argv)
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-reduction-") as tmp:
            args.db = Path(tmp) / "quick.duckdb"
            simulated_database(args.db, QUICK_DESIGN)
            args.reductions, args.models, args.conditions = "pca", "TLS+SUDS", "O@0.5,D+@1"
            args.boots, args.jobs, args.train_cycles = 1, 1, 2
            study(args)
        return
    if args.db is None:
        p.error("--db is required (or --quick)")
    study(args)


def study(args) -> None:
    store = Store(args.db)
    reductions = args.reductions.split(",")
    versions = {r: ensure_version(store, r) for r in reductions}
    frames = []
    with tempfile.TemporaryDirectory() as tmp:
        for r, version in versions.items():
            copy = Path(tmp) / f"{r}.duckdb"
            shutil.copyfile(args.db, copy)
            options = parse_campaign_options(
                prep=version,
                models=args.models,
                boots=args.boots,
                train_cycles=args.train_cycles,
                train_conditions=args.conditions,
                test_conditions=args.conditions,
            )
            summary = run_campaign(Store(copy), "reduction", options, jobs=args.jobs)
            print(f"{r}: {summary.message()}", flush=True)
            frames.append(load_results(Store(copy), "reduction").assign(reduction=r))
    res = pd.concat(frames, ignore_index=True)
    res["same"] = (res.train_gait == res.test_gait) & (
        (res.train_frequency_hz - res.test_frequency_hz).abs() < 1e-9
    )
    wide = res.pivot_table(index=[*KEY, "model"], columns="reduction", values="rmse_vx")
    rows = []
    for model in args.models.split(","):
        for r in reductions:
            sub = res[(res.model == model) & (res.reduction == r)]
            w = wide.xs(model, level="model")[[reductions[0], r]].dropna()
            med, lo, hi = paired_ratio(w[r].to_numpy(), w[reductions[0]].to_numpy())
            rows.append(
                {
                    "learner": model,
                    "reduction": r,
                    "jobs": len(sub),
                    "median RMSE vx, all pairs": sub.rmse_vx.median(),
                    "same-condition": sub[sub.same].rmse_vx.median(),
                    f"paired ratio to {reductions[0]}": med,
                    "95% low": lo,
                    "95% high": hi,
                }
            )
    with pd.option_context("display.width", 200):
        print(f"\n{len(res) // len(reductions)} jobs per reduction ({args.boots} draws a pair)")
        print(pd.DataFrame(rows).round(3).to_string(index=False))


if __name__ == "__main__":
    main()
