"""`plan next`: from a version (and a target), the next trial or trials to record, each
with its reason, and the learning curve's stopping signal."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from suds_exp.errors import ConfigError
from suds_exp.gait.predict import derive_seed
from suds_exp.gait.support import Support
from suds_exp.models import make_model
from suds_exp.models.registry import GMR
from suds_exp.plan.curve import StopSignal, forecast_signal, learning_curve
from suds_exp.plan.ensemble import N_BOOT, MapEnsemble
from suds_exp.plan.loop import TRUST0, check_body, version_cycles
from suds_exp.plan.recommend import (
    Recommendation,
    bias_variance,
    recommend_gait,
    recommend_map,
)
from suds_exp.plan.recorded import recorded_gaits
from suds_exp.plan.target import GOALS, Target
from suds_exp.preprocess import get_version
from suds_exp.store import Store


@dataclass
class Advice:
    """What `plan_next` returns: the version, its cycles, the recommendations (best
    first) and the stopping signal. The gait goal also names the recorded gaits it
    compared with (``recorded_gaits``) and, in ``notes``, the recorded gait files it could
    not find."""

    prep_version: int
    goal: str
    cycles_total: int
    recommendations: list[Recommendation] = field(default_factory=list)
    stop: StopSignal | None = None
    files: list[str] = field(default_factory=list)
    recorded_gaits: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {
            "prep_version": self.prep_version,
            "goal": self.goal,
            "cycles_total": self.cycles_total,
            "recommendations": [r.to_dict() for r in self.recommendations],
            "files": self.files,
            "recorded_gaits": self.recorded_gaits,
            "notes": self.notes,
            "stop": self.stop.to_dict() if self.stop else None,
        }


def plan_next(
    store: Store,
    prep=None,
    goal: str = "map",
    target: Target | None = None,
    n: int = 1,
    cycles: int = 5,
    out: str | Path = "plan-next",
    learner: str = GMR,
    n_boot: int = N_BOOT,
    trust: float = TRUST0,
    seed: int = 0,
    max_evals: int = 150,
) -> Advice:
    """Recommend the next ``n`` trials of ``cycles`` cycles for ``goal`` ("map": reduce
    the target's prediction uncertainty; "gait": improve the best forward displacement per
    cycle within ``target.bound``) on version ``prep``. A gait goal's new Fourier gait is
    written to ``out``/NAME.toml; ``trust`` (rad) bounds its distance from the recorded
    data; ``max_evals``: map evaluations per start of the gait search. Seeds derive from
    (``seed``, the version, the goal)."""
    if goal not in GOALS:
        raise ConfigError(f"goal {goal!r}: expected one of {', '.join(GOALS)}", param="goal")
    if n < 1:
        raise ConfigError(f"n {n}: must be >= 1 trial", param="n")
    if cycles < 1:
        raise ConfigError(f"cycles {cycles}: must be >= 1 per trial", param="cycles")
    if n_boot < 2:
        raise ConfigError(f"n_boot {n_boot}: need >= 2 refits for a spread", param="n_boot")
    make_model(learner)
    target = target or Target()
    version = get_version(store, prep)
    check_body(version)
    samples = version.samples()
    if samples.empty:
        raise ConfigError(
            f"version {version.name} has no samples; preprocess trials first", step="preprocess"
        )
    key = derive_seed("plan-next", seed, version.id, goal, len(samples))
    ensemble = MapEnsemble.fit(samples, learner, n_boot, key, paths=goal == "gait")
    advice = Advice(version.id, goal, version_cycles(samples))
    if goal == "map":
        bias = bias_variance(samples, target, learner, ensemble.point)
        advice.recommendations = recommend_map(ensemble, target, cycles, n, samples, learner, bias)
    else:
        out = Path(out)
        name = f"plan-v{version.id}-{key % 10**6:06d}.toml"
        known = recorded_gaits(samples, out, store)
        advice.recorded_gaits = known.labels
        if known.missing:
            advice.notes.append(
                f"recorded gait file(s) not found in {out} or beside their captures, so not "
                f"compared with: {', '.join(known.missing)}"
            )
        rec, _, _ = recommend_gait(
            ensemble,
            Support.of(samples),
            known.gaits,
            target,
            trust,
            cycles,
            name,
        )
        out.mkdir(parents=True, exist_ok=True)
        path = out / name
        path.write_text(rec.trial.gait.to_toml())
        rec.trial.file = str(path)
        advice.recommendations = [rec]
        advice.files = [str(path)]
    if goal == "map":
        advice.stop = forecast_signal(samples, ensemble, target, cycles, learner, bias, key)
    else:
        advice.stop = learning_curve(samples, learner, key)
    return advice
