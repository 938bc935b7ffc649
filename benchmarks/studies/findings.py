"""The paper's findings F1-F10 on simulated datasets: run (or read) a campaign, print the table.

Usage::

    # read a campaign already run
    .venv/bin/python -m benchmarks.studies.findings --db demo.duckdb --campaign paper
    # on fresh simulated datasets, one database per dataset seed, at the paper's scale
    .venv/bin/python -m benchmarks.studies.findings --seeds 0,1,2 --out bench-findings --jobs 2
    # a quick look at a reduced scale
    .venv/bin/python -m benchmarks.studies.findings --seeds 0 --boots 2 --sweep 1-3,30
    # another robot: a simulator config file, effects over it
    .venv/bin/python -m benchmarks.studies.findings --seeds 0 \
        --config examples/calibrated_robot.toml

For each dataset seed (``--seeds``): simulate the paper's design with the default
simulator (`simulate_dataset`; the robot of ``--config`` with the effects of ``--set``),
ingest, preprocess (default options), run the campaign ``--campaign`` with ``--boots``
draws per pair, 30 training cycles and the sweep ``--sweep`` (default the paper's,
``paper``: 21,000 jobs), leaving out cells the data cannot supply when
``--skip-infeasible`` is given. Every step is resumable: a database that already holds
the data, the version or finished jobs is reused. Then the findings table
(`suds_exp.analysis.findings`, ``--boot`` replicates) is printed as Markdown per seed,
and a last table sets the verdicts of all seeds side by side with the count that hold.
With ``--db`` instead of ``--seeds`` nothing is simulated or run: the campaign is read.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

from benchmarks._harness import script_parser
from suds_exp.analysis.findings import (
    findings,
    findings_display,
    findings_headline,
    findings_summary,
)
from suds_exp.analysis.formatting import to_markdown
from suds_exp.campaign import run_campaign
from suds_exp.commands.campaign import parse_campaign_options
from suds_exp.store import Store


def prepare(db: Path, seed: int, effects: list[str] = (), config: Path | None = None) -> str:
    """Simulate and ingest dataset ``seed`` into ``db`` (unless it holds trials already),
    with the robot of ``config`` (a simulator config file; default nominal) changed by
    ``effects`` (``EFFECT.PARAM=VALUE`` items), preprocess it (idempotent); returns the
    preprocessing version's name."""
    from suds_exp.ingest import ingest_paths
    from suds_exp.preprocess import preprocess
    from suds_exp.sim import SimConfig, apply_effects, load_config, simulate_dataset

    base = load_config(config) if config is not None else SimConfig()
    cfg = apply_effects(base, effects, param="--set")

    store = Store(db)
    store.upgrade()
    if store.query_df("SELECT count(*) AS n FROM trials").n[0] == 0:
        with tempfile.TemporaryDirectory(prefix="suds-findings-") as tmp:
            data = simulate_dataset(tmp, cfg, seed=seed)
            ingest_paths(store, [Path(tmp)], manifest=data.manifest, progress=False)
    return preprocess(store, progress=False).name


def main(argv=None) -> None:
    parser = script_parser(
        __doc__.split("\n")[0], "a smoke run: the table of 2 synthetic draws a pair"
    )
    parser.add_argument("--db", type=Path, help="read --campaign from this database")
    parser.add_argument("--seeds", help="dataset seeds to simulate, e.g. 0,1,2")
    parser.add_argument("--out", type=Path, default=Path("bench-findings"))
    parser.add_argument("--campaign", default="paper")
    parser.add_argument("--boots", type=int, default=10, help="draws per (train, test) pair")
    parser.add_argument("--sweep", default="paper")
    parser.add_argument("--skip-infeasible", action="store_true")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--boot", type=int, default=400, help="bootstrap replicates")
    parser.add_argument("--json", action="store_true", help="one JSON document at the end")
    parser.add_argument(
        "--set",
        nargs="*",
        default=[],
        help="simulator effects over the robot, EFFECT.PARAM=VALUE (with --seeds)",
    )
    parser.add_argument(
        "--config", type=Path, help="simulator config file of the robot (default nominal)"
    )
    args = parser.parse_args(argv)
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-findings-quick-") as tmp:
            args.db, args.boot = Path(tmp) / "quick.duckdb", 20
            _synthetic_campaign(args.db, args.campaign)
            study(args)
        return
    if (args.db is None) == (args.seeds is None):
        parser.error("give exactly one of --db (read a campaign) or --seeds (simulate and run)")
    study(args)


def _synthetic_campaign(db: Path, campaign: str) -> None:
    """A database whose ``results`` hold a synthetic campaign (2 draws a pair)."""
    from suds_exp.testing.synthetic_results import synthetic_results

    store = Store(db)
    store.upgrade()
    with store.write() as conn:
        store.insert_df(conn, "results", synthetic_results(campaign, n_boot=2))


def study(args) -> None:

    tables: dict[str, pd.DataFrame] = {}
    if args.db is not None:
        targets = [(args.db.stem, args.db, None)]
    else:
        args.out.mkdir(parents=True, exist_ok=True)
        seeds = [int(s) for s in args.seeds.split(",") if s.strip()]
        targets = [(f"seed {s}", args.out / f"seed{s}.duckdb", s) for s in seeds]
    for label, db, seed in targets:
        store = Store(db)
        if seed is not None:
            t0 = time.perf_counter()
            prep = prepare(db, seed, args.set, args.config)
            t1 = time.perf_counter()
            options = parse_campaign_options(
                prep=prep, boots=args.boots, sweep=args.sweep, train_cycles=30
            )
            options.skip_infeasible = args.skip_infeasible or None
            run = run_campaign(store, args.campaign, options, jobs=args.jobs, progress=False)
            print(
                f"{label}: data {t1 - t0:.0f} s; {run.message()} "
                f"(total {time.perf_counter() - t1:.0f} s)",
                file=sys.stderr,
            )
        t0 = time.perf_counter()
        table = findings(store, args.campaign, n_boot=args.boot)
        seconds = time.perf_counter() - t0
        tables[label] = table
        print(f"\n## {label}: campaign {args.campaign} ({db})\n")
        print(to_markdown(findings_display(table)))
        print(f"{findings_headline(table)}; measured in {seconds:.1f} s\n")

    verdicts = pd.DataFrame(
        {label: findings_summary(t).set_index("finding")["verdict"] for label, t in tables.items()}
    )
    held = (verdicts == "holds").sum()
    verdicts.loc["holds (of 10)"] = held.astype(str)
    print("## verdicts by dataset\n")
    print(to_markdown(verdicts.reset_index().rename(columns={"index": "finding"})))
    if args.json:
        print(
            json.dumps(
                {
                    label: t.astype(object).where(t.notna(), None).to_dict(orient="records")
                    for label, t in tables.items()
                },
                default=str,
            )
        )


if __name__ == "__main__":
    main()
