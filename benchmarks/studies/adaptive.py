"""Fewest robot cycles: the planner against the paper's grid, random trials, Bayesian
optimisation directly on the simulator and the designer fed the full grid.

On each dataset seed (the simulator's noise draws of every trial), at equal budgets of
recorded cycles (warm-up included), five ways of spending robot time:

- ``grid``: the paper's design (5 gaits x 3 frequencies x 4 repeats, 10-30 cycles) in its
  own order, learned after every trial;
- ``random``: random order-2 Fourier gaits within the bound (as the ceiling benchmark's
  global look draws them), `--cycles` cycles each at 1/2 Hz, learned after every trial;
- ``plan``: `suds-exp plan loop` (`suds_exp.plan.run_loop`), from 5 cycles of O at 1/2 Hz;
- ``bo``: Bayesian optimisation (`bayesian-optimization`, default settings, 8 random
  starts) of the same Fourier gait's 10 coefficients, each evaluation one trial of
  `--cycles` cycles (within --bo-budget) whose forward displacement per cycle is measured
  on the trial itself (actuator noise included, cycles after the first averaged); no map;
- ``tpe``: the same with `optuna`'s tree-structured Parzen estimator (default settings);
- ``designer`` (with --designer): `gait design --iterations 5 --verify` from the full grid
  (also GMR's error on the unseen gaits learned from the full grid, the map goal's bar).

Every arm's best gait is scored the same way, on the simulator with the gait followed
exactly (`suds_exp.gait.truth`): the gait-goal curve is that forward displacement per
cycle against cycles recorded, as a share of --ceiling (mm per cycle, the global search of
`benchmarks/studies/gait_ceiling.py`: 146.3, the best of its seeds 0 and 1, a gait that
runs its loop twice a cycle; see docs/results/adaptive.md). The best gait of a learning
arm is the recorded gait its map predicts best; of BO, the best evaluation. The map-goal
curve (--map-budget > 0) is GMR's error on the fixed unseen gaits of
`suds_exp.plan.unseen_gaits` (RMS distance of predicted from simulated net displacement
per cycle, mm) for grid, random and the plan loop with --goal map.

Each dataset seed's gait-goal arms are run several times (--repeats for plan and random,
--peer-repeats for bo and tpe; grid and designer have no randomness of their own): run r's
seed is the dataset seed for r = 0 and derived from (arm, dataset seed, r) after, and
drives all of the run's randomness. The summary gives each arm's cycles to 80 % and 90 %
of the ceiling as median and range over the runs, and the plan loop's median over each
peer's (`ratios`; the bar is <= 1/3).

Run: .venv/bin/python -m benchmarks.studies.adaptive --seeds 0,1,2 --budget 50 --bo-budget 150
         [--map-budget 390 --map-arms plan,fullgrid] [--designer] [--out reports/adaptive]
     (--from-curves reports/adaptive/curves.csv [--ceiling MM]: the gait summary of stored
     runs recomputed against another ceiling, nothing run)

For the map goal's plan loop the benchmark also measures where the map-error curve
flattens (the next doubling of cycles lowers the error by less than its bootstrap
spread, GMR refitted on cycle-block resamples) and whether the loop's stopping signal
first fired within 20 % of that count (`flattening`, in summary.json).
Writes curves.csv, summary.json and the figures gait.png (and map.png) to --out.
(`pip install -e '.[bench]'` installs bayesian-optimization and optuna.)
"""

from __future__ import annotations

import argparse
import atexit
import json
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.gait.design import DesignOptions, design_gait
from suds_exp.gait.motion import cycle_motion
from suds_exp.gait.predict import derive_seed, fit_map
from suds_exp.gait.shape import FourierGait, NamedGait, within_bound
from suds_exp.gait.trials import gait_trial_specs
from suds_exp.gait.truth import simulate_forward
from suds_exp.ingest import ingest_paths
from suds_exp.plan import LoopOptions, Target, TargetTruth, run_loop
from suds_exp.plan.compare import (
    PEERS,
    job_seed,
    over_runs,
    ratios,
    read_curves,
    run_entry,
    summary_from_curves,
)
from suds_exp.plan.curve import flattening as curve_flattening
from suds_exp.plan.curve import forecast_signal, latched, within
from suds_exp.plan.ensemble import MapEnsemble, block_draws
from suds_exp.plan.recommend import Trial
from suds_exp.plan.record import record_trial
from suds_exp.preprocess import get_version, preprocess
from suds_exp.sim import SimConfig, simulate_dataset
from suds_exp.sim.dataset import plan_trials, simulate_trials
from suds_exp.store import Store

FREQ = 0.5
ORDER = 2


def random_gait(rng, bound: float, name: str) -> FourierGait:
    """The ceiling benchmark's random look: first harmonic ~ N(0, 1) rad, higher ones
    ~ N(0, 0.3), centre ~ U(-0.3, 0.3), projected into the bound."""
    scale = np.r_[[0.3, 0.3], np.tile([1.0] * 2 + [0.3] * 2 * (ORDER - 1), 2)]
    x = rng.normal(size=2 + 4 * ORDER) * scale
    x[:2] = rng.uniform(-0.3, 0.3, size=2)
    return within_bound(FourierGait.from_vector(x, name), bound)


class Learner:
    """An arm that records trials one by one into its own database and learns after each:
    the curve's rows (cycles, best gait's simulator forward, map error)."""

    def __init__(self, work: Path, truth: TargetTruth):
        self.store = Store(work / "arm.duckdb")
        self.work, self.truth = work, truth
        self.gaits, self.cycles, self.rows, self.version = [], 0, [], None
        self.achieved: dict[str, float] = {}

    def record(self, trial: Trial, seed: int) -> None:
        # one folder a trial: a declared level's folder keeps its repeat number
        trial_id = record_trial(self.store, trial, self.work / f"t{len(self.rows)}", seed)
        if self.version is None:
            preprocess(self.store, trials=[trial_id], progress=False)
            self.version = get_version(self.store)
        else:
            v = self.version
            preprocess(self.store, v.name, params=v.params, trials=[trial_id], progress=False)
        self.cycles += trial.cycles
        if all(g.name != trial.gait.name for g in self.gaits):
            self.gaits.append(trial.gait)
        fitted = fit_map(get_version(self.store).samples())
        preds = [fitted.forward(g, FREQ) for g in self.gaits]
        best = self.gaits[int(np.argmax(preds))]
        if best.name not in self.achieved:
            self.achieved[best.name] = float(simulate_forward([best], FREQ)[0])
        self.rows.append(
            {
                "cycles": self.cycles,
                "best_forward_mm": self.achieved[best.name],
                "map_error_mm": self.truth.map_error(fitted),
            }
        )


def arm_grid(seed: int, budget: int, truth: TargetTruth, work: Path) -> list[dict]:
    arm = Learner(work, truth)
    for spec in plan_trials(seed=seed):
        if arm.cycles + spec.n_cycles > budget:
            break
        arm.record(Trial(NamedGait(spec.gait), spec.frequency_hz, spec.n_cycles), seed)
    return arm.rows


def arm_random(seed: int, budget: int, cycles: int, bound: float, truth, work) -> list[dict]:
    arm = Learner(work, truth)
    rng = np.random.default_rng([seed, 11])
    k = 0
    while arm.cycles + cycles <= budget:
        name = f"random-s{seed}-{k}.toml"
        arm.record(Trial(random_gait(rng, bound, name), FREQ, cycles, name), seed)
        k += 1
    return arm.rows


def arm_plan(
    seed: int, budget: int, goal: str, bound: float, cycles: int, work, truth=None,
    spread_boots: int = 8, stored: dict[int, float] | None = None,
) -> list[dict]:  # fmt: skip
    """The loop's curve rows; for the map goal (``truth`` given) each row also has the
    bootstrap spread of the map error (`error_spread`; taken from ``stored``, cycles to
    spread of an earlier run's curves.csv, where it has the count) and the loop's stop
    signal, recomputed by the library as it is now up to the count where it first fires
    (latched, it says stop from there on)."""
    opts = LoopOptions(goal=goal, bound=bound, budget_cycles=budget, seed=seed, cycles=cycles)
    store = Store(work / "plan.duckdb")
    loop = run_loop(store, opts, out=work / "plan")
    rows = [
        {
            "cycles": it.cycles_recorded,
            "best_forward_mm": it.achieved_forward_mm,
            "map_error_mm": it.map_error,
            "stop": bool(it.stop),
            "trial": f"{it.trial['gait']}@{it.trial['frequency_hz']:g}",
        }
        for it in loop.iterations
    ]
    if truth is not None:
        samples = get_version(store, loop.prep_version).samples()
        trial_ids = [it.trial_id for it in loop.iterations]
        before, fired = None, False
        for k, row in enumerate(rows):
            part = samples[samples["trial_id"].isin(trial_ids[: k + 1])]
            key = derive_seed("flat", seed, k)
            if stored and row["cycles"] in stored:
                row["error_spread_mm"] = stored[row["cycles"]]
            else:
                row["error_spread_mm"] = error_spread(part, truth, key, spread_boots)
            if fired:  # latched: stop for good, whatever a later verdict says
                row["stop"], row["stop_reason"] = True, "stop (said before)"
                continue
            # the stopping signal as the library computes it now, from the stored data
            # (the loop's own ensemble seeds), whatever the loop stored when it ran
            fit_seed = derive_seed("plan-fit", loop.name, k)
            ens = MapEnsemble.fit(part, opts.learner, opts.n_boot, fit_seed)
            now = forecast_signal(part, ens, truth.target, opts.cycles, opts.learner, seed=fit_seed)
            signal = now if k == 0 else latched(now, before, fired)
            before, fired = now, fired or signal.stop
            row["stop"], row["stop_reason"] = bool(signal.stop), signal.message
    return rows


def error_spread(samples: pd.DataFrame, truth: TargetTruth, seed: int, n_boot: int = 8) -> float:
    """Bootstrap standard deviation (mm) of GMR's error on the unseen gaits: GMR refitted
    on ``n_boot`` cycle-block resamples of ``samples`` (`suds_exp.plan.ensemble`)."""
    errors = [truth.map_error(fit_map(f)) for f in block_draws(samples, n_boot, seed)]
    return float(np.std(errors, ddof=1))


def flattening(rows: list[dict]) -> dict:
    """Where the measured map-error curve flattens (`suds_exp.plan.curve.flattening`:
    the first count where the next doubling lowers the error by less than its bootstrap
    spread, and the count from which that holds at every later tested count) and where
    the stop signal first fired; within 20 % when |fired - c| <= 0.2 c. The signal
    targets ``flat_from`` (the latched signal says stop for good)."""
    curve = curve_flattening(
        [r["cycles"] for r in rows], [r["map_error_mm"] for r in rows],
        [r["error_spread_mm"] for r in rows],
    )  # fmt: skip
    flat = None
    if curve.first is not None:
        i = next(i for i, r in enumerate(rows) if r["cycles"] == curve.first)
        later = next(q for q in rows if q["cycles"] >= 2 * rows[i]["cycles"])
        flat = {"cycles": rows[i]["cycles"],
                "drop_mm": rows[i]["map_error_mm"] - later["map_error_mm"],
                "spread_mm": rows[i]["error_spread_mm"], "doubled_at": later["cycles"]}  # fmt: skip
    fired = next((r["cycles"] for r in rows if r["stop"]), None)
    return {"flattens_at": flat, "signal_first_at": fired,
            "within_20_percent": within(fired, curve.first),
            "flat_from": curve.flat_from,
            "within_20_percent_of_flat_from": within(fired, curve.flat_from),
            "tested": curve.tested}  # fmt: skip


def measured_forward(gait, cycles: int, seed: int, config: SimConfig) -> float:
    """Forward displacement per cycle measured on one simulated trial of ``gait`` (the
    actuator's lag and noise included), cycles after the first averaged."""
    (spec,) = gait_trial_specs(gait, (FREQ,), 1, (cycles, cycles), seed)
    (truth,) = simulate_trials([spec], config)
    per = int(round(config.measurement.sample_rate_hz / FREQ))
    poses = np.column_stack([truth[c] for c in ("x", "y", "theta")])
    return cycle_motion(poses, per, range(1, cycles)).forward_mm


class DirectTrials:
    """The objective of a black-box peer: each evaluation records one trial of ``cycles``
    cycles of a Fourier gait (the 10 coefficients of ``x``, projected into the bound) and
    returns its measured forward displacement per cycle; the curve's rows follow the best
    evaluation so far, scored with the gait followed exactly, with its coefficients
    (``best_gait``: a0, cos, sin as `FourierGait.to_vector`, rad) so it can be re-scored."""

    def __init__(self, arm: str, seed: int, cycles: int, bound: float):
        self.arm, self.seed, self.cycles, self.bound = arm, seed, cycles, bound
        self.config, self.n, self.best, self.rows = SimConfig(), 0, -np.inf, []
        self.achieved, self.best_gait = np.nan, ""

    def __call__(self, x: np.ndarray) -> float:
        self.n += 1
        gait = within_bound(FourierGait.from_vector(x, f"{self.arm}-{self.n}"), self.bound)
        noise = derive_seed(self.arm, self.seed, self.n)
        value = measured_forward(gait, self.cycles, noise, self.config)
        if value > self.best:
            self.best = value
            self.achieved = float(simulate_forward([gait], FREQ)[0])
            self.best_gait = " ".join(f"{v:.6g}" for v in gait.to_vector())
        self.rows.append(
            {
                "cycles": self.n * self.cycles,
                "best_forward_mm": self.achieved,
                "best_gait": self.best_gait,
            }
        )
        return value


def coefficient_bounds(bound: float) -> list[tuple[float, float]]:
    """The box the peers search (rad): centre within +/- 0.3, harmonics within the bound."""
    return [(-0.3, 0.3) if i < 2 else (-bound, bound) for i in range(2 + 4 * ORDER)]


def arm_bo(seed: int, budget: int, cycles: int, bound: float) -> list[dict]:
    """GP Bayesian optimisation (`bayesian-optimization`, default settings, 8 random
    starts); ``seed`` is its random state and its trials' noise stream."""
    from bayes_opt import BayesianOptimization

    trials = DirectTrials("bo", seed, cycles, bound)
    box = coefficient_bounds(bound)
    pbounds = {f"x{i}": b for i, b in enumerate(box)}
    n_evals = budget // cycles

    def objective(**kw):
        return trials(np.array([kw[f"x{i}"] for i in range(len(box))]))

    opt = BayesianOptimization(objective, pbounds, random_state=seed, verbose=0)
    opt.maximize(init_points=min(8, n_evals), n_iter=max(0, n_evals - 8))
    return trials.rows


def arm_tpe(seed: int, budget: int, cycles: int, bound: float) -> list[dict]:
    """Tree-structured Parzen estimator (`optuna`'s TPESampler, default settings: 10
    random starts); ``seed`` is its sampler's seed and its trials' noise stream."""
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    trials = DirectTrials("tpe", seed, cycles, bound)
    box = coefficient_bounds(bound)

    def objective(trial):
        return trials(np.array([trial.suggest_float(f"x{i}", *b) for i, b in enumerate(box)]))

    study = optuna.create_study(direction="maximize", sampler=optuna.samplers.TPESampler(seed=seed))
    study.optimize(objective, n_trials=budget // cycles)
    return trials.rows


def arm_designer(seed: int, bound: float, truth: TargetTruth, work: Path) -> dict:
    """The full grid: its GMR map's error on the unseen gaits, then `gait design
    --iterations 5 --verify` from it (the best verified gait)."""
    store = Store(work / "grid.duckdb")
    ds = simulate_dataset(work / "grid", seed=seed)
    ingest_paths(store, [], manifest=ds.manifest, progress=False)
    preprocess(store, progress=False)
    cycles = int(round(sum(s.n_cycles for s in plan_trials(seed=seed))))
    error = truth.map_error(fit_map(get_version(store).samples()))
    opts = DesignOptions(bound=bound, iterations=5, verify=True)
    design = design_gait(store, None, opts, work / "design")
    best = max(it.achieved.forward_mm for it in design.iterations)
    return {
        "cycles": cycles + 5 * opts.cycles,
        "best_forward_mm": best,
        "grid_cycles": cycles,
        "grid_map_error_mm": error,
    }


def arm_fullgrid(seed: int, truth: TargetTruth, work: Path) -> dict:
    """GMR's error on the unseen gaits learned from the paper's full grid (the map goal's
    bar) and the grid's cycles."""
    store = Store(work / "grid.duckdb")
    ds = simulate_dataset(work / "grid", seed=seed)
    ingest_paths(store, [], manifest=ds.manifest, progress=False)
    preprocess(store, progress=False)
    cycles = int(round(sum(s.n_cycles for s in plan_trials(seed=seed))))
    samples = get_version(store).samples()
    error = truth.map_error(fit_map(samples))
    spread = error_spread(samples, truth, derive_seed("flat-grid", seed))
    return {"cycles": cycles, "map_error_mm": error, "error_spread_mm": spread}


#: Arms with no randomness of their own beyond the dataset seed's: one run a seed.
UNREPEATED = ("grid", "designer", "fullgrid")


def run_arm(
    arm: str, goal: str, seed: int, budget: int, args, truth, repeat: int = 0
) -> tuple[list[dict], float]:
    """One arm's curve rows on dataset ``seed`` (run ``repeat``) within ``budget``
    cycles, and its wall s."""
    started = time.perf_counter()
    dataset_seed, seed = seed, job_seed(arm, seed, repeat)
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        if arm == "plan":
            # kept: a plan loop stopped half-way continues where it ended when run again
            tail = f"-r{repeat}" if repeat else ""
            work = args.out / f"work-{goal}-plan-s{dataset_seed}{tail}"
            work.mkdir(parents=True, exist_ok=True)
        if arm == "grid":
            rows = arm_grid(seed, budget, truth, work)
        elif arm == "random":
            rows = arm_random(seed, budget, args.cycles, args.bound, truth, work)
        elif arm == "plan":
            rows = arm_plan(
                seed, budget, goal, args.bound, args.cycles, work,
                truth if goal == "map" else None, args.spread_boots,
                stored_spreads(args.out, seed) if args.reuse_spreads else None,
            )  # fmt: skip
        elif arm == "fullgrid":
            rows = [arm_fullgrid(seed, truth, work)]
        elif arm == "bo":
            rows = arm_bo(seed, args.bo_budget, args.cycles, args.bound)
        elif arm == "tpe":
            rows = arm_tpe(seed, args.bo_budget, args.cycles, args.bound)
        else:
            rows = [arm_designer(seed, args.bound, truth, work)]
    return rows, time.perf_counter() - started


def stored_spreads(out: Path, seed: int) -> dict[int, float]:
    """The map-goal plan loop's error spreads (cycles to mm) of ``seed`` in an earlier
    run's ``out``/curves.csv (empty without one): the loop's data are stored, so the
    spreads of its counts need not be refitted when only the signal changed."""
    path = out / "curves.csv"
    if not path.exists():
        return {}
    frame = pd.read_csv(path)
    part = frame[(frame["goal"] == "map") & (frame["arm"] == "plan") & (frame["seed"] == seed)]
    if "error_spread_mm" not in part:
        return {}
    part = part.dropna(subset=["error_spread_mm"])
    return dict(zip(part["cycles"].astype(int), part["error_spread_mm"].astype(float), strict=True))


def repeats_of(arm: str, args) -> int:
    """Runs a dataset seed of ``arm``: --peer-repeats for the black-box peers (cheap),
    --repeats for the learning arms."""
    return args.peer_repeats if arm in PEERS else args.repeats


def print_gait_table(summary: dict) -> None:
    """Cycles to 80 % / 90 % of the ceiling: median [least-most] over runs, per arm and
    dataset seed ("missed": the median run never reached it within the arm's budget)."""

    def cell(st: dict) -> str:
        if st["min"] is None:
            return "never"
        med = "missed" if st["median"] is None else f"{st['median']:g}"
        high = "never" if st["max"] is None else st["max"]
        return f"{med} [{st['min']}-{high}]" + (f" ({st['missed']} missed)" if st["missed"] else "")

    for arm, per_seed in summary["arms"].items():
        for seed, e in per_seed.items():
            at = e.get("median_share_at_budget")
            print(
                f"{arm:>8} seed {seed} ({e['repeats']} runs): to 80 % {cell(e['cycles_to_80'])}; "
                f"to 90 % {cell(e['cycles_to_90'])}"
                + ("" if at is None else f"; median share at {summary['budget']} cycles {at:.3f}")
                + f", at the end {e['median_share_of_ceiling']:.3f}"
            )
    for peer, per_seed in summary.get("ratios", {}).items():
        for seed, r in per_seed.items():
            text = ", ".join(f"{lv} %: {ratio_text(v)}" for lv, v in r.items())
            print(f"plan / {peer} seed {seed} (ratio of medians): {text}")


def ratio_text(r: dict) -> str:
    """A ratio of medians as printed: '-' when the loop's median run missed, '<= x' when
    the peer's did (x the bound at its budget)."""
    if r["ratio"] is None:
        return "-"
    return ("<= " if r["peer_missed"] else "") + f"{r['ratio']:g}"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--budget", type=int, default=50, help="cycles of the gait-goal arms")
    ap.add_argument("--bo-budget", type=int, default=150, help="cycles of Bayesian optimisation")
    ap.add_argument("--map-budget", type=int, default=0, help="cycles of the map-goal arms")
    ap.add_argument("--cycles", type=int, default=5, help="cycles per planned/random/BO trial")
    ap.add_argument("--bound", type=float, default=1.3, help="joint bound, rad")
    ap.add_argument(
        "--ceiling", type=float, default=146.3,
        help="mm per cycle: the best gait within the bound (benchmarks.studies.gait_ceiling)",
    )  # fmt: skip
    ap.add_argument("--arms", default="grid,random,plan,bo,tpe", help="gait-goal arms ('' none)")
    ap.add_argument("--designer", action="store_true", help="also the designer on the grid")
    ap.add_argument(
        "--repeats", type=int, default=3,
        help="runs a dataset seed of the plan loop and random arms (seeds from the job key)",
    )  # fmt: skip
    ap.add_argument(
        "--peer-repeats", type=int, default=5, help="runs a dataset seed of BO and TPE"
    )  # fmt: skip
    ap.add_argument(
        "--spread-boots", type=int, default=8,
        help="bootstrap refits of the map error's spread (the flattening check)",
    )  # fmt: skip
    ap.add_argument(
        "--reuse-spreads", action="store_true",
        help="take the map error's spreads from --out's curves.csv where it has them",
    )  # fmt: skip
    ap.add_argument(
        "--map-arms", default="grid,random,plan",
        help="map-goal arms (grid, random, plan, fullgrid: the full grid's error alone)",
    )  # fmt: skip
    ap.add_argument("--out", type=Path, default=Path("reports/adaptive"))
    ap.add_argument(
        "--from-curves", default="",
        help="comma-separated curves.csv of earlier runs: recompute their gait summary "
        "against --ceiling (seeds --seeds, budgets --budget and --bo-budget), run nothing",
    )  # fmt: skip
    ap.add_argument("--quick", action="store_true", help="a smoke run at tiny budgets")
    args = ap.parse_args(argv)
    if args.quick:
        args.seeds, args.budget, args.cycles, args.arms = "0", 6, 2, "random,plan"
        args.repeats, args.peer_repeats = 2, 2
        args.map_budget, args.map_arms, args.spread_boots = 6, "random", 2
        args.out = Path(tempfile.mkdtemp(prefix="suds-adaptive-quick-"))
        atexit.register(shutil.rmtree, args.out, True)
    args.out.mkdir(parents=True, exist_ok=True)
    seeds = [int(s) for s in args.seeds.split(",")]
    if args.from_curves:
        frame = read_curves([Path(p) for p in args.from_curves.split(",")])
        frame = frame[frame["seed"].isin(seeds) & (frame["goal"] == "gait")]
        summary = summary_from_curves(frame, args.ceiling, args.budget, args.bo_budget)
        print_gait_table(summary)
        (args.out / "summary-from-curves.json").write_text(json.dumps(summary, indent=2))
        draw(frame, args.ceiling, args.out)
        print(f"wrote {args.out}/summary-from-curves.json and gait.png")
        return
    arms = [a for a in args.arms.split(",") if a]
    truth = TargetTruth(Target.of(bound=args.bound))
    curves, summary = [], {"ceiling_mm": args.ceiling, "seeds": seeds, "arms": {}}
    summary |= {"budget": args.budget, "peer_budget": args.bo_budget}
    for seed in seeds:
        for arm in arms + (["designer"] if args.designer else []):
            runs = []
            for repeat in range(1 if arm in UNREPEATED else repeats_of(arm, args)):
                rows, seconds = run_arm(arm, "gait", seed, args.budget, args, truth, repeat)
                curves += [
                    {"goal": "gait", "arm": arm, "seed": seed, "repeat": repeat} | r for r in rows
                ]
                last = rows[-1]
                entry = {"repeat": repeat, "job_seed": job_seed(arm, seed, repeat)}
                entry |= run_entry(rows, args.ceiling, args.budget)
                entry["seconds"] = round(seconds, 1)
                if arm == "designer":
                    entry["grid_cycles"] = last["grid_cycles"]
                    entry["grid_map_error_mm"] = round(last["grid_map_error_mm"], 3)
                runs.append(entry)
                print(f"gait seed {seed} {arm} run {repeat}: {entry}", flush=True)
                summary["arms"].setdefault(arm, {})[str(seed)] = over_runs(runs)
                summary["ratios"] = ratios(summary["arms"], args.budget, args.bo_budget)
                save(curves, summary, args.out)
        map_arms = [a for a in args.map_arms.split(",") if a]
        for arm in map_arms if args.map_budget > 0 else ():
            rows, seconds = run_arm(arm, "map", seed, args.map_budget, args, truth)
            curves += [{"goal": "map", "arm": arm, "seed": seed} | r for r in rows]
            entry = {
                "cycles": rows[-1]["cycles"],
                "map_error_mm": round(rows[-1]["map_error_mm"], 3),
                "seconds": round(seconds, 1),
            }
            if "error_spread_mm" in rows[-1]:
                entry["error_spread_mm"] = round(rows[-1]["error_spread_mm"], 3)
            if arm == "plan":
                entry["flattening"] = flattening(rows)
            summary.setdefault("map", {}).setdefault(arm, {})[str(seed)] = entry
            print(f"map seed {seed} {arm}: {entry}", flush=True)
            save(curves, summary, args.out)
    print_gait_table(summary)
    draw(pd.DataFrame(curves), args.ceiling, args.out)
    print(f"wrote {args.out}/curves.csv, summary.json and figures")


def save(curves: list[dict], summary: dict, out: Path) -> None:
    """curves.csv and summary.json as they stand (after every arm: a long run that stops
    keeps what it measured)."""
    pd.DataFrame(curves).to_csv(out / "curves.csv", index=False, float_format="%.4f")
    (out / "summary.json").write_text(json.dumps(summary, indent=2))


def draw(frame: pd.DataFrame, ceiling: float, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"grid": "C0", "random": "C1", "plan": "C2", "bo": "C3", "designer": "C4"}
    colours["tpe"] = "C5"
    colours["fullgrid"] = "C0"
    for goal, column, label in (
        ("gait", "best_forward_mm", "best gait on the simulator (share of the ceiling)"),
        ("map", "map_error_mm", "GMR error on the unseen gaits (mm per cycle)"),
    ):
        part = frame[frame["goal"] == goal]
        if part.empty:
            continue
        fig, ax = plt.subplots(figsize=(7, 4.2))
        if "repeat" not in part:
            part = part.assign(repeat=0)
        scale = ceiling if goal == "gait" else 1.0
        for arm, runs in part.groupby("arm", sort=False):
            colour = colours.get(arm, "k")
            for _, rows in runs.groupby(["seed", "repeat"], dropna=False):
                style = "o" if len(rows) == 1 else "-"
                y = rows[column] / scale
                ax.plot(rows["cycles"], y, style, color=colour, lw=0.7, alpha=0.3)
            # the arm's median over every run (seeds and repeats) still within its budget,
            # each run's curve held at its last value between its own counts
            table = runs.pivot_table(
                index="cycles", columns=["seed", "repeat"], values=column, dropna=False
            ).sort_index()
            held = table.ffill().where(table.bfill().notna() | table.notna())
            n = table.shape[1]
            ax.plot(
                held.index, held.median(axis=1) / scale, "o-" if len(held) == 1 else "-",
                color=colour, lw=2.2, label=f"{arm} (median of {n} runs)",
            )  # fmt: skip
        if goal == "gait":
            for level in (0.8, 0.9):
                ax.axhline(level, color="grey", lw=0.6, ls="--")
        ax.set_xscale("log")
        ax.set_xlabel("cycles recorded (warm-up included)")
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / f"{goal}.png", dpi=110)
        plt.close(fig)


if __name__ == "__main__":
    main()
