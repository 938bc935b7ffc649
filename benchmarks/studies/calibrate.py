"""Calibration of the simulator's variability effects against the paper's findings.

For each setting (effect parameters over the nominal robot, always inside their realistic
ranges) it simulates the default design (5 gaits x 3 frequencies x 4 repeats, dataset
``--seed``), ingests and preprocesses it, runs a reduced campaign (the five learners at
their defaults - the learners are never tuned here -, every pair of conditions with
``--boots`` draws at 30 training cycles, and the sweep ``--sweep`` on same-condition
pairs) and measures the paper's findings F1-F10 with `suds_exp.analysis.findings`
(the statistics of the README's "The paper's findings"; ``--n-boot`` replicates). It also
prints, as a diagnosis of the robot's variability, how much of r_a, rp_1 and vx the gait
phase leaves unexplained (RMS deviation from the phase-bin mean / SD, median over conditions).

Settings:

- ``--settings nominal,old``: named ones (`NAMED`);
- ``--search N --rng R``: N settings drawn uniformly from `SEARCH_SPACE` (a few
  variability parameters, each inside its realistic range), reproducible from R;
- ``--ablation``: the chosen setting ``--set ...`` (default ``calibrated``,
  `examples/calibrated_robot.toml`) with each of its effects switched off in turn: which
  effect each finding needs;
- ``--set EFFECT.PARAM=VALUE ...``: one setting.

``--springs 20,100,300`` runs every setting at each stiffness of the flippers' tape hinges
(N mm/rad, `Hinges.spring_n_mm_per_rad`, range 5-300; default the nominal 20 only), the
setting's name then ending in ``@spring=K``.

A reduced campaign takes 1.5-4 min on 2 cores (``--jobs``). Rows are appended to ``--out``
as settings finish (an interrupted run keeps them; a re-run skips them), and a summary
(findings holding, on the paper's side, values) is printed for the settings asked for.

    .venv/bin/python -m benchmarks.studies.calibrate --settings nominal,old --out calib.csv
    .venv/bin/python -m benchmarks.studies.calibrate --search 20 --rng 1 --out calib.csv
    .venv/bin/python -m benchmarks.studies.calibrate --ablation --out calib.csv
    .venv/bin/python -m benchmarks.studies.calibrate --settings nominal,calibrated --springs 20,300
"""

from __future__ import annotations

import json
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks._data import QUICK_DESIGN
from benchmarks._harness import ROOT, script_parser
from suds_exp.analysis.findings import findings
from suds_exp.campaign import CampaignOptions, run_campaign
from suds_exp.ingest import ingest_paths
from suds_exp.preprocess import preprocess
from suds_exp.sim import (
    SimConfig,
    apply_effects,
    config_from_dict,
    effect_library,
    simulate_dataset,
)
from suds_exp.store import Store

#: Effects and their settings that describe a robot's variability.
VARIABILITY_EFFECTS = (
    "servo",
    "bed_depth",
    "bed_heterogeneity",
    "bed_packing",
    "grain_contacts",
    "hinge_friction",
)
#: The parameters the search draws, with the part of each realistic range searched
#: (the 1 Hz gait needs 6.3 rad/s, so slower servos are not searched).
SEARCH_SPACE = {
    "servo.compliance_rad_per_n_m": (0.12, 0.4),
    "servo.stall_torque_n_m": (2.0, 6.0),
    "servo.no_load_speed_rad_s": (10.0, 12.0),
    "bed_depth.cv": (0.2, 0.5),
    "bed_depth.correlation_mm": (50.0, 300.0),
    "grain_contacts.cv": (0.0, 0.3),
    "bed_packing.trial_cv": (0.0, 0.3),
    "hinge_friction.torque_n_mm": (0.0, 30.0),
}
#: The calibrated setting's one home: the example configuration users load with --config.
CALIBRATED = ROOT / "examples" / "calibrated_robot.toml"


def effect_items(path: Path) -> list[str]:
    """The ``EFFECT.PARAM=VALUE`` items of a configuration file that sets effects only
    (``[effects.NAME]`` tables), so a file setting can be ablated item by item."""
    doc = tomllib.loads(path.read_text())
    if set(doc) - {"effects"}:
        raise SystemExit(f"{path}: only [effects.*] tables can be read as a setting")
    return [
        f"{e}.{k}={v}" for e, params in doc.get("effects", {}).items() for k, v in params.items()
    ]


#: Settings by name: the robot without variability effects, the nominal one and the
#: calibrated one (`CALIBRATED`).
NAMED = {
    "old": [f"{e}=off" for e in VARIABILITY_EFFECTS],
    "nominal": [],
    "calibrated": effect_items(CALIBRATED),
}
FINDINGS = ("F1", "F2", "F3", "F4", "F5", "F6", "F7", "F8a", "F8b", "F9a", "F9b", "F9c", "F10")


def check_space() -> None:
    """Refuse a search space reaching outside a parameter's realistic range."""
    ranges = {
        p["config_key"].removeprefix("effects."): p["range"]
        for e in effect_library()
        for p in e["parameters"]
    }
    for key, (lo, hi) in SEARCH_SPACE.items():
        low, high = ranges[key]
        if not low <= lo <= hi <= high:
            raise SystemExit(f"SEARCH_SPACE[{key!r}] = {lo}..{hi} leaves its range {low}..{high}")


def draw(rng: np.random.Generator) -> list[str]:
    return [f"{k}={rng.uniform(lo, hi):.3g}" for k, (lo, hi) in SEARCH_SPACE.items()]


def ablation(items: list[str]) -> dict[str, list[str]]:
    """``items`` and, per variability effect on in that setting, the same with that
    effect switched off."""
    state = {e["name"]: e["state"] for e in effect_library(apply_effects(SimConfig(), items))}
    plan = {"all": items}
    for e in VARIABILITY_EFFECTS:
        if state[e] == "on":
            plan[f"without_{e}"] = items + [f"{e}=off"]
    return plan


def phase_explained(store: Store, prep: str) -> dict[str, float]:
    """Median over conditions of RMS(signal - its phase-bin mean) / SD(signal)."""
    s = store.query_df(
        "SELECT t.gait, t.frequency_hz, s.phase, s.ra_1, s.ra_2, s.rp_1, s.vx "
        "FROM samples s JOIN trials t ON t.id = s.trial_id "
        "JOIN prep_versions v ON v.id = s.version_id WHERE v.name = ?",
        [prep],
    )
    s["bin"] = np.floor((s["phase"] % (2 * np.pi)) / (2 * np.pi) * 32).astype(int)
    out: dict[str, list[float]] = {"ra": [], "rp_1": [], "vx": []}
    for _, g in s.groupby(["gait", "frequency_hz"]):
        for key, cols in (("ra", ["ra_1", "ra_2"]), ("rp_1", ["rp_1"]), ("vx", ["vx"])):
            dev = g[cols] - g.groupby("bin")[cols].transform("mean")
            out[key].append(
                float(np.sqrt((dev**2).to_numpy().mean() / g[cols].var().to_numpy().mean()))
            )
    return {f"phase_resid_{k}": float(np.median(v)) for k, v in out.items()}


def run_setting(name: str, items: list[str], args, spring: float | None = None) -> dict:
    cfg = apply_effects(SimConfig(), items, param="--set")
    if spring is not None:
        cfg = config_from_dict({"hinges": {"spring_n_mm_per_rad": spring}}, base=cfg)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="suds-calibrate-") as tmp:
        ds = simulate_dataset(Path(tmp) / "data", cfg, seed=args.seed, **args.design)
        store = Store(Path(tmp) / "calib.duckdb")
        ingest_paths(store, [Path(tmp) / "data"], ds.manifest, None, progress=False)
        prep = preprocess(store, progress=False).name
        opts = CampaignOptions(
            prep=prep,
            boots=args.boots,
            train_cycles=args.train_cycles,
            sweep=[int(c) for c in args.sweep.split(",")],
            skip_infeasible=True,
        )
        run_campaign(store, "calib", opts, jobs=args.jobs, progress=False)
        row = {"setting": name, "items": json.dumps(items), "seed": args.seed}
        row.update(phase_explained(store, prep))
        table = findings(store, "calib", n_boot=args.n_boot)
    for r in table.itertuples():
        row[f"value_{r.id}"] = r.value
        row[f"verdict_{r.id}"] = r.verdict
    row["seconds"] = time.perf_counter() - started
    return row


def summary(table: pd.DataFrame) -> str:
    verdicts = table[[f"verdict_{f}" for f in FINDINGS]]
    out = pd.DataFrame(
        {
            "setting": table.setting,
            "seed": table.seed,
            "hold": (verdicts == "holds").sum(axis=1),
            "side": verdicts.isin(["holds", "unclear"]).sum(axis=1),
            "ra/rp1/vx left": [
                f"{a:.2f}/{b:.2f}/{c:.2f}"
                for a, b, c in zip(
                    table.phase_resid_ra, table.phase_resid_rp_1, table.phase_resid_vx, strict=True
                )
            ],
        }
    )
    for f in FINDINGS:
        out[f] = table[f"value_{f}"].map(lambda v: f"{v:.2f}")
    return out.sort_values(["side", "hold"], ascending=False).to_string(index=False)


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0], "a smoke run on a tiny design")
    ap.add_argument("--settings", default="", help="named settings: " + ", ".join(NAMED))
    ap.add_argument("--search", type=int, default=0, help="draw this many settings")
    ap.add_argument("--rng", type=int, default=0, help="seed of the search's draws")
    ap.add_argument("--ablation", action="store_true", help="switch each effect off in turn")
    ap.add_argument("--set", nargs="*", default=None, help="one setting (EFFECT.PARAM=V)")
    ap.add_argument("--seed", type=int, default=0, help="dataset seed")
    ap.add_argument("--boots", type=int, default=2)
    ap.add_argument("--sweep", default="2,5,10,30")
    ap.add_argument("--n-boot", type=int, default=100, help="bootstrap replicates")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("bench-calibrate.csv"))
    ap.add_argument("--springs", default="", help="hinge springs, N mm/rad (default nominal)")
    ap.add_argument("--train-cycles", type=int, default=30)
    args = ap.parse_args(argv)
    args.design = {}
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-calibrate-quick-") as tmp:
            args.settings, args.boots, args.sweep, args.n_boot, args.jobs = "nominal", 1, "2", 20, 1
            args.train_cycles, args.design, args.out = 2, QUICK_DESIGN, Path(tmp) / "quick.csv"
            study(args)
        return
    study(args)


def study(args) -> None:
    check_space()
    plan: dict[str, list[str]] = {}
    for name in [n for n in args.settings.split(",") if n]:
        if name not in NAMED:
            raise SystemExit(f"--settings: unknown {name!r}; expected {', '.join(NAMED)}")
        plan[name] = NAMED[name]
    if args.ablation:
        base = args.set if args.set is not None else NAMED["calibrated"]
        plan.update(ablation(base))
    elif args.set is not None:
        plan["custom:" + ",".join(args.set)] = list(args.set)
    rng = np.random.default_rng(args.rng)
    for i in range(args.search):
        plan[f"search{args.rng}-{i}"] = draw(rng)
    springs = [float(k) for k in args.springs.split(",") if k]
    if springs:
        plan = {f"{name}@spring={k:g}": (items, k) for name, items in plan.items() for k in springs}
    else:
        plan = {name: (items, None) for name, items in plan.items()}
    done = pd.read_csv(args.out) if args.out.exists() else pd.DataFrame()
    have = set(zip(done.get("setting", []), done.get("seed", []), strict=False))
    for name, (items, spring) in plan.items():
        if (name, args.seed) in have:
            continue
        row = run_setting(name, items, args, spring)
        print(json.dumps({k: row[k] for k in ("setting", "items", "seconds")}), flush=True)
        pd.DataFrame([row]).to_csv(args.out, mode="a", header=not args.out.exists(), index=False)
    table = pd.read_csv(args.out)
    print(summary(table[table.setting.isin(plan) & (table.seed == args.seed)]))


if __name__ == "__main__":
    main()
