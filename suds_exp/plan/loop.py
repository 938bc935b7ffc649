"""The closed loop: plan a trial, record it on the simulator, learn it, plan again.

Each iteration records what `suds_exp.plan.recommend` asked for (`add_trial_to_version`:
simulate with the trial's seed, ingest, preprocess into the version), refits the learner
with its bootstrap refits, and stores one row of ``plan_iterations`` (migration 022):
the trial and its reason, the cycles recorded so far, the map's error on the target set,
the best recorded gait (the one that went furthest per cycle in its own trials, as
recorded: `measured_forward`) and its predicted and simulator-achieved forward displacement per
cycle, the stopping signal (the map goal's forecast for the next doubling and latched,
the gait goal's the learning curve's: `suds_exp.plan.curve`) and the gait goal's trust radius.

Budget: the cycles the loop records, its warm-up included. A loop starts from a warm-up
recording (`LoopOptions.warmup_gait` at `warmup_frequency_hz`, `warmup_cycles` cycles)
when the database has no preprocessing version, else from the existing version.

Resume: a loop is found again by its name, a hash of its recipe without the budget, so
the same call continues where the stored iterations end (after Ctrl-C or kill -9: each
row is one transaction). An iteration's plan is written to its folder (``plan.json``)
before its trial is recorded, so a loop killed between recording and storing records the
very same trial again, which ingest and preprocessing skip as already done.

Every random number comes from seeds derived from (loop name, iteration).
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd
import sqlalchemy as sa
from filelock import FileLock, Timeout

from suds_exp.errors import ConfigError, PreprocessError, StoreError
from suds_exp.gait.motion import recorded_cycles
from suds_exp.gait.predict import derive_seed
from suds_exp.gait.shape import FourierGait, Gait, NamedGait, read_gait_file
from suds_exp.gait.support import Support
from suds_exp.gait.truth import simulate_gaits
from suds_exp.ingest import stored_design, trial_level_axis
from suds_exp.ingest.added import mark_trials_added
from suds_exp.models import make_model
from suds_exp.models.registry import GMR
from suds_exp.plan.curve import forecast_signal, latched, learning_curve
from suds_exp.plan.ensemble import N_BOOT, MapEnsemble, count_cycles
from suds_exp.plan.recommend import (
    Recommendation,
    Trial,
    bias_variance,
    recommend_gait,
    recommend_map,
)
from suds_exp.plan.record import add_trial_to_version, record_trial
from suds_exp.plan.recorded import recorded_gaits
from suds_exp.plan.target import GOALS, Target, TargetTruth
from suds_exp.preprocess import get_version
from suds_exp.preprocess import preprocess as run_preprocess
from suds_exp.preprocess.params import actuated_dimension
from suds_exp.progress import progress_bar
from suds_exp.robot import GAITS
from suds_exp.sim import SimConfig
from suds_exp.store import Store

#: Trust radius (rad, support metric) of the gait goal's first trial, its cap and factors
#: (the designer's textbook rule on achieved / predicted gain, see `suds_exp.gait.design`).
TRUST0, TRUST_MAX, GROW, GROW_FAST, SHRINK = 0.3, 1.0, 1.5, 2.0, 0.5


@dataclass
class LoopOptions:
    """The recipe of a loop. goal: "gait" or "map"; bound (rad); budget_cycles: cycles the
    loop may record, warm-up included; seed; cycles: of each planned trial; learner;
    target_files / target_frequencies_hz (Hz): the target (default: the fixed unseen
    gaits at 1/2 Hz); warmup_*: the first recording when there is no version; n_boot:
    bootstrap refits; max_evals: map evaluations per start of the gait search."""

    goal: str = "gait"
    bound: float = 1.3
    budget_cycles: int = 50
    seed: int = 0
    cycles: int = 5
    learner: str = GMR
    target_files: tuple[str, ...] = ()
    target_frequencies_hz: tuple[float, ...] = ()
    warmup_gait: str = "O"
    warmup_frequency_hz: float = 0.5
    warmup_cycles: int = 5
    n_boot: int = N_BOOT
    max_evals: int = 150

    def check(self) -> Target:
        """Refuse a bad recipe in one line before anything is read or stored; the target."""
        if self.goal not in GOALS:
            raise ConfigError(
                f"goal {self.goal!r}: expected one of {', '.join(GOALS)}", param="goal"
            )
        if self.budget_cycles <= 0:
            raise ConfigError(
                f"budget_cycles {self.budget_cycles}: must be > 0 recorded cycles",
                param="budget_cycles",
            )
        if self.cycles < 1 or self.warmup_cycles < 1:
            raise ConfigError(f"cycles {self.cycles}: must be >= 1 per trial", param="cycles")
        if self.warmup_gait not in GAITS:
            raise ConfigError(
                f"warmup_gait {self.warmup_gait!r}: expected one of {', '.join(GAITS)}",
                param="warmup_gait",
            )
        if self.n_boot < 2:
            raise ConfigError(
                f"n_boot {self.n_boot}: need >= 2 refits for a spread", param="n_boot"
            )
        make_model(self.learner)  # an unknown learner is refused here
        return Target.of(self.target_files, self.target_frequencies_hz, self.bound)

    def name(self) -> str:
        """The loop's key: a hash of its recipe without the budget (a larger budget
        continues the same loop)."""
        recipe = asdict(self)
        recipe.pop("budget_cycles")
        recipe["target_files"] = [str(Path(p).resolve()) for p in self.target_files]
        text = json.dumps(recipe, sort_keys=True, default=str)
        return "plan-" + hashlib.sha256(text.encode()).hexdigest()[:12]


@dataclass
class LoopIteration:
    """One stored iteration (a row of ``plan_iterations``)."""

    iteration: int
    trial: dict
    reason: str
    score: float | None
    cycles_recorded: int
    cycles_total: int
    map_error: float
    best_gait: Gait
    predicted_forward_mm: float
    achieved_forward_mm: float
    trust_radius: float | None
    stop: bool
    stop_reason: str
    seconds: float
    trial_id: int | None = None

    def to_dict(self) -> dict:
        """The JSON layout of `suds-exp plan loop --json`'s ``iterations``."""
        path = self.best_gait.to_dict()
        return {
            "iteration": self.iteration,
            "cycles_total": self.cycles_total,
            "cycles_recorded": self.cycles_recorded,
            "trial": self.trial,
            "trial_id": self.trial_id,
            "reason": self.reason,
            "best_gait": {
                "name": path["name"],
                "phase_rad": path["phase_rad"],
                "phi1_rad": path["phi1_rad"],
                "phi2_rad": path["phi2_rad"],
            },
            "predicted_forward_mm": round(self.predicted_forward_mm, 3),
            "achieved_forward_mm": round(self.achieved_forward_mm, 3),
            "map_error": round(self.map_error, 4),
        }


@dataclass
class Loop:
    """A loop: its id and name in the store, recipe, iterations and final stop signal."""

    id: int
    name: str
    prep_version: int
    options: LoopOptions
    iterations: list[LoopIteration] = field(default_factory=list)
    budget_left: int = 0

    def stop(self) -> dict:
        """The top-level ``stop`` of the JSON: whether and when the learning curve first
        said stop, and its last sentence."""
        fired = next((it.cycles_recorded for it in self.iterations if it.stop), None)
        last = self.iterations[-1] if self.iterations else None
        return {
            "stop": bool(last.stop) if last else False,
            "first_at_cycles": fired,
            "reason": last.stop_reason if last else "",
            "budget_left_cycles": self.budget_left,
        }

    def to_dict(self) -> dict:
        return {
            "loop_id": self.id,
            "name": self.name,
            "prep_version": self.prep_version,
            "goal": self.options.goal,
            "iterations": [it.to_dict() for it in self.iterations],
            "stop": self.stop(),
        }


class _State:
    """What an iteration needs from the data: the version, its samples, the fitted
    ensemble, the recorded gaits; rebuilt after each recording."""

    def __init__(self, store, version, opts, target, truth, folder, name, it, achieved):
        self.loop_name = name
        self.version = get_version(store, version.id)
        self.samples = self.version.samples()
        seed = derive_seed("plan-fit", name, it)
        # a new gait's spread counts the bias between recorded paths (`MapEnsemble`)
        paths = opts.goal == "gait"
        self.ensemble = MapEnsemble.fit(self.samples, opts.learner, opts.n_boot, seed, paths)
        self.support = Support.of(self.samples)
        known = recorded_gaits(self.samples, folder, store)
        labels, self.gaits = known.labels, known.gaits
        freq = target.frequencies_hz[0]
        preds = [self.ensemble.point.forward(g, freq) for g in self.gaits]
        # the trust rule's baseline: the map's own best, so its gains are the map's
        self.top_predicted = float(max(preds))
        # the best gait is the one that went furthest in its own trials: the map smooths
        # a peak away, and re-ranks recorded gaits as it learns elsewhere
        measured = measured_forward(self.samples, freq)
        score = [measured.get(label, -np.inf) for label in labels]
        i = int(np.argmax(score)) if np.isfinite(max(score)) else int(np.argmax(preds))
        self.best, self.best_predicted = self.gaits[i], float(preds[i])
        if self.best.name not in achieved:
            achieved[self.best.name] = simulate_gaits([self.best], freq)[0].forward_mm
        self.best_achieved = float(achieved[self.best.name])
        self.map_error = truth.map_error(self.ensemble.point)
        self.bias = None
        if opts.goal == "map":
            # the path jackknife is read twice (the signal, the plan): refitted once
            self.bias = bias_variance(self.samples, target, opts.learner, self.ensemble.point)
            self.curve = forecast_signal(
                self.samples, self.ensemble, target, opts.cycles, opts.learner, self.bias, seed
            )
        else:
            self.curve = learning_curve(self.samples, opts.learner, seed)
        # the iteration's own verdict, before the loop's latch (`latched`) reads it
        self.raw_curve = self.curve
        self.cycles_total = version_cycles(self.samples)


class _LazyTruth:
    """`TargetTruth`, simulated when an iteration first needs it (a finished loop that is
    run again needs none)."""

    def __init__(self, target: Target):
        self.target, self._truth = target, None

    def map_error(self, fitted) -> float:
        if self._truth is None:
            self._truth = TargetTruth(self.target)
        return self._truth.map_error(fitted)


def version_cycles(samples: pd.DataFrame) -> int:
    """Cycles recorded in a samples frame (`count_cycles`), rounded."""
    return int(round(count_cycles(samples)))


def measured_forward(samples: pd.DataFrame, frequency_hz: float) -> dict[str, float]:
    """Forward displacement per cycle (mm) each gait label's trials at ``frequency_hz``
    (Hz) recorded: the body twists of each trial integrated over its whole periods from
    its first sample (`suds_exp.gait.motion.recorded_cycles`), averaged over the periods
    of all its trials. Labels with no whole period at that frequency are left out."""
    out: dict[str, list[np.ndarray]] = {}
    for _, trial in samples.groupby("trial_id", sort=True):
        if abs(float(trial["frequency_hz"].iloc[0]) - frequency_hz) > 1e-9:
            continue
        t = trial["t"].to_numpy(float)
        if len(t) < 2:
            continue
        twists = trial[["vx", "vy", "wz"]].to_numpy(float)
        cycles = recorded_cycles(twists, float(np.median(np.diff(t))), 1.0 / frequency_hz)
        if len(cycles):
            out.setdefault(str(trial["gait"].iloc[0]), []).append(cycles[:, 0])
    return {label: float(np.concatenate(parts).mean()) for label, parts in out.items()}


def check_body(version) -> None:
    """Refuse a version whose body the loop cannot pursue a goal for: the planner's
    gaits and the simulator drive two actuated joints."""
    m = actuated_dimension(version.params)
    if m != 2:
        raise ConfigError(
            f"version {version.name}: its body has {m} actuated coordinates; plans drive two "
            "joints (phi1, phi2) on the simulated swimmer",
            param="prep",
        )


def _existing_version(store: Store, prep):
    """The version ``prep`` (None: the only one), or None when the store has none."""
    if not store.path.exists():
        return None
    try:
        return get_version(store, prep)
    except PreprocessError:
        if prep is not None:
            raise
        from suds_exp.preprocess import list_versions

        if len(list_versions(store)):
            raise
        return None


def run_loop(
    store: Store,
    options: LoopOptions | None = None,
    prep=None,
    out: str | Path = "plan-loop",
    config: SimConfig | None = None,
    progress: bool = False,
    on_iteration=None,
) -> Loop:
    """`plan loop`: run (or continue) the closed loop; returns the `Loop` with every
    stored iteration. ``out``: folder of its captures and gait files; ``config``: the
    simulator (default nominal); ``on_iteration``: called with each new `LoopIteration`."""
    opts = options or LoopOptions()
    target = opts.check()
    version = _existing_version(store, prep)
    if version is not None:
        check_body(version)
    if store.path.exists():
        # refused before anything is stored: where the loop's gait-file trials would go
        trial_level_axis(stored_design(store))
    name = opts.name()
    folder = Path(out) / name
    folder.mkdir(parents=True, exist_ok=True)
    owner = FileLock(folder / "owner.lock")
    try:
        owner.acquire(timeout=0)
    except Timeout:
        raise StoreError(f"plan loop {name} is running in another process; wait for it") from None
    try:
        return _run(store, opts, target, version, name, folder, config, progress, on_iteration)
    finally:
        owner.release()


def _run(store, opts, target, version, name, folder, config, progress, on_iteration) -> Loop:
    truth = _LazyTruth(target)
    achieved: dict[str, float] = {}
    loop_id, rows = _find_loop(store, name)
    if loop_id is None:
        started = time.perf_counter()
        warm = None
        if version is None:
            warm = Trial(NamedGait(opts.warmup_gait), opts.warmup_frequency_hz, opts.warmup_cycles)
            seed = derive_seed("plan-record", name, 0) % 2**31
            trial_id = record_trial(store, warm, folder / "it0", seed, config)
            mark_trials_added(store, [trial_id], f"plan loop {name}")
            # The simulator stands in for the robot, whose drawing gives the distance
            # between its motor axes: one gait's warm-up cannot pin it down (O's shape
            # loop is a circle), and the version keeps these segment origins for every
            # trial the loop adds.
            known = (config or SimConfig()).geometry.middle_length_mm
            run_preprocess(
                store, trials=[trial_id], params={"joint_distance_mm": known}, progress=False
            )
            version = get_version(store)
            check_body(version)
        loop_id = _register(store, name, version.id, opts)
        state = _State(store, version, opts, target, truth, folder, name, 0, achieved)
        if warm is not None:
            trial, recorded = warm.to_dict(), warm.cycles
            reason = (
                f"warm-up: {warm.cycles} cycles of {warm.gait.name} at {warm.frequency_hz:g} Hz"
            )
        else:
            trial = {"gait": "existing version", "frequency_hz": 0.0, "cycles": 0}
            recorded, trial_id = 0, None
            reason = f"start: version {version.name}, {state.cycles_total} cycles"
        first = _iteration(0, trial, reason, None, recorded, state, TRUST0, trial_id, started)
        _store_iteration(store, loop_id, first)
        rows = [first]
    else:
        version = get_version(store, _loop_version(store, loop_id))
        state = None
    loop = Loop(loop_id, name, version.id, opts, list(rows))
    recorded = loop.iterations[-1].cycles_recorded
    with progress_bar(
        "Plan loop",
        opts.budget_cycles,
        enabled=progress,
        done=min(recorded, opts.budget_cycles),
        unit="cycles",
    ) as advance:
        while recorded + opts.cycles <= opts.budget_cycles:
            it = len(loop.iterations)
            if state is None:
                state = _State(store, version, opts, target, truth, folder, name, it - 1, achieved)
            started = time.perf_counter()
            trust = loop.iterations[-1].trust_radius or TRUST0
            rec = _plan(state, opts, target, trust, folder / f"it{it}", it)
            # a gait goal's look beyond the trust region starts a new region: its radius
            # is judged afresh from the first one's (the old radius measured the map elsewhere)
            beyond = opts.goal == "gait" and _beyond(state.support, rec.trial.gait, trust)
            seed = derive_seed("plan-record", name, it) % 2**31
            trial_id = add_trial_to_version(
                store,
                state.version,
                rec.trial,
                folder / f"it{it}",
                seed,
                config,
                added_by=f"plan loop {name}",
            )
            before, signal_before = state.top_predicted, state.raw_curve
            state = _State(store, version, opts, target, truth, folder, name, it, achieved)
            if opts.goal == "map":
                fired = any(i.stop for i in loop.iterations)
                state.curve = latched(state.raw_curve, signal_before, fired)
            if opts.goal == "gait":
                trust = _next_trust(TRUST0 if beyond else trust, rec, state, target, before)
            recorded += rec.trial.cycles
            row = _iteration(
                it,
                rec.trial.to_dict(),
                rec.reason,
                rec.score,
                recorded,
                state,
                trust,
                trial_id,
                started,
            )
            _store_iteration(store, loop_id, row)
            loop.iterations.append(row)
            advance(rec.trial.cycles)
            if on_iteration is not None:
                on_iteration(row)
    loop.budget_left = max(0, opts.budget_cycles - recorded)
    return loop


def _plan(state: _State, opts: LoopOptions, target: Target, trust: float, folder: Path, it: int):
    """The iteration's recommendation; read back from ``folder``/plan.json when an
    interrupted run already made it (so the same trial is recorded)."""
    saved = folder / "plan.json"
    if saved.is_file():
        doc = json.loads(saved.read_text())
        file = doc["file"]
        if file is None:
            gait: Gait = NamedGait(doc["gait"])
        else:
            local = folder / Path(file).name
            gait = read_gait_file(local if local.is_file() else file)
        trial = Trial(gait, doc["frequency_hz"], doc["cycles"], doc["file"])
        return Recommendation(
            trial, doc["score"], doc["unit"], doc["reason"], doc["mean"], doc["sd"]
        )
    if opts.goal == "gait":
        rec, _, _ = recommend_gait(
            state.ensemble,
            state.support,
            state.gaits,
            target,
            trust,
            opts.cycles,
            f"{state.loop_name}-it{it}.toml",
            max_evals=opts.max_evals,
        )
    else:
        rec = recommend_map(
            state.ensemble,
            target,
            opts.cycles,
            samples=state.samples,
            learner=opts.learner,
            bias=state.bias,
        )[0]
    folder.mkdir(parents=True, exist_ok=True)
    if isinstance(rec.trial.gait, FourierGait) and rec.trial.file:
        (folder / rec.trial.file).write_text(rec.trial.gait.to_toml())
    doc = {
        "gait": rec.trial.gait.name,
        "file": rec.trial.file,
        "frequency_hz": rec.trial.frequency_hz,
        "cycles": rec.trial.cycles,
        "score": rec.score,
        "unit": rec.unit,
        "reason": rec.reason,
        "mean": rec.predicted_forward_mm,
        "sd": rec.spread_mm,
    }
    saved.write_text(json.dumps(doc))
    return rec


def _beyond(support, gait: Gait, trust: float) -> bool:
    """Whether the planned gait lies beyond the trust radius (rad) of the data it was
    planned on (the search inside it keeps to the radius up to its last rounding)."""
    return support.gait_distance(gait) > 1.01 * trust


def _next_trust(trust, rec, state, target, before) -> float:
    """The textbook trust-region rule on rho = gain the refitted map sees at the recorded
    gait / gain the plan predicted, both over the best recorded gait before it."""
    learned = state.ensemble.point.forward(rec.trial.gait, target.frequencies_hz[0])
    predicted_gain = (rec.predicted_forward_mm or 0.0) - before
    real_gain = learned - before
    if predicted_gain <= 0:
        factor = GROW if real_gain > 0 else SHRINK
    else:
        rho = real_gain / predicted_gain
        factor = (
            (GROW_FAST if rho > 1.5 else GROW) if rho > 0.75 else (1.0 if rho >= 0.25 else SHRINK)
        )
    return float(min(TRUST_MAX, trust * factor))


def _iteration(it, trial, reason, score, recorded, state, trust, trial_id, started):
    return LoopIteration(
        it,
        trial,
        reason,
        score,
        int(recorded),
        state.cycles_total,
        state.map_error,
        state.best,
        state.best_predicted,
        state.best_achieved,
        trust,
        state.curve.stop,
        state.curve.message,
        time.perf_counter() - started,
        trial_id,
    )


def _find_loop(store: Store, name: str) -> tuple[int | None, list[LoopIteration]]:
    if not store.path.exists():
        return None, []
    with store.read() as conn:
        have = conn.execute(
            sa.text(
                "SELECT count(*) FROM information_schema.tables WHERE table_name = 'plan_loops'"
            )
        ).scalar()
        if not have:
            return None, []
        loop_id = conn.execute(
            sa.text("SELECT id FROM plan_loops WHERE name = :n"), {"n": name}
        ).scalar()
        if loop_id is None:
            return None, []
        frame = Store.frame(
            conn, "SELECT * FROM plan_iterations WHERE loop_id = ? ORDER BY iteration", [loop_id]
        )
    return int(loop_id), [_from_row(r) for r in frame.itertuples()]


def _loop_version(store: Store, loop_id: int) -> int:
    with store.read() as conn:
        return int(
            conn.execute(
                sa.text("SELECT prep_version FROM plan_loops WHERE id = :i"), {"i": loop_id}
            ).scalar_one()
        )


def _from_row(r) -> LoopIteration:
    doc = json.loads(r.best_gait)
    if "coefficients" in doc:
        best: Gait = FourierGait.from_vector(doc["coefficients"], doc["name"])
    else:
        best = NamedGait(doc["name"])
    trial = {
        "gait": r.trial_gait,
        "frequency_hz": float(r.trial_frequency_hz),
        "cycles": int(r.trial_cycles),
    }
    return LoopIteration(
        int(r.iteration),
        trial,
        r.reason,
        None if pd.isna(r.score) else float(r.score),
        int(r.cycles_recorded),
        int(r.cycles_total),
        float(r.map_error_mm),
        best,
        float(r.predicted_forward_mm),
        float(r.achieved_forward_mm),
        None if pd.isna(r.trust_radius) else float(r.trust_radius),
        bool(r.stop_signal),
        r.stop_reason,
        float(r.seconds),
        None if pd.isna(r.trial_id) else int(r.trial_id),
    )


def _register(store: Store, name: str, version_id: int, opts: LoopOptions) -> int:
    with store.write() as conn:
        return int(
            conn.execute(
                sa.text(
                    "INSERT INTO plan_loops (name, prep_version, goal, bound_rad, seed, "
                    "definition, created_at) VALUES (:n, :v, :g, :b, :s, :d, :c) RETURNING id"
                ),
                {
                    "n": name,
                    "v": version_id,
                    "g": opts.goal,
                    "b": opts.bound,
                    "s": opts.seed,
                    "d": json.dumps(asdict(opts), sort_keys=True, default=str),
                    "c": datetime.now(UTC).replace(tzinfo=None),
                },
            ).scalar_one()
        )


def _store_iteration(store: Store, loop_id: int, it: LoopIteration) -> None:
    gait = it.best_gait.to_dict()
    if isinstance(it.best_gait, FourierGait):
        gait["coefficients"] = it.best_gait.to_vector().tolist()
    row = {
        "loop_id": loop_id,
        "iteration": it.iteration,
        "trial_id": it.trial_id,
        "trial_gait": it.trial["gait"],
        "trial_frequency_hz": it.trial["frequency_hz"],
        "trial_cycles": it.trial["cycles"],
        "reason": it.reason,
        "score": it.score,
        "cycles_recorded": it.cycles_recorded,
        "cycles_total": it.cycles_total,
        "map_error_mm": it.map_error,
        "best_gait": json.dumps(gait),
        "predicted_forward_mm": it.predicted_forward_mm,
        "achieved_forward_mm": it.achieved_forward_mm,
        "trust_radius": it.trust_radius,
        "stop_signal": it.stop,
        "stop_reason": it.stop_reason,
        "seconds": it.seconds,
    }
    with store.write() as conn:
        Store.insert_df(conn, "plan_iterations", pd.DataFrame([row]))


def load_loop(store: Store, loop_id: int) -> pd.DataFrame:
    """The stored iterations of loop ``loop_id``, in order (one row each)."""
    return store.query_df(
        "SELECT * FROM plan_iterations WHERE loop_id = ? ORDER BY iteration", [int(loop_id)]
    )
