"""Design a gait from a learned motility map, and verify it: the data-driven loop.

Each iteration fits the learner on the version's samples, then maximises the predicted
forward displacement per cycle over the Fourier coefficients of every actuated joint of
the version's body (1 to 8; order ``order``) subject to

- the joint bound: |angle| <= bound (rad) at every joint, and
- the trust region: the gait's distance from the training data in the
  (shape, direction of shape velocity) metric of `suds_exp.gait.support` is at most the
  trust radius. A learned map interpolates; far from its data it guesses. The radius
  starts small and follows the textbook trust-region rule on the verified step
  (``radius_rule="ratio"``): rho = achieved gain / predicted gain over the best verified
  gait; it grows (x `grow`, x `grow_fast` when rho > 1.5) when rho > 0.75, shrinks
  (x `shrink`) when rho < 0.25. A map that was too cautious is not punished for it.
  ``radius_rule="error"`` (the first rule) grows when the simulator achieved the
  prediction within `accept_error` and shrinks when it did not, either way.

With ``verify`` each designed gait is run on the simulator as a new trial (10 cycles at
the design frequency through the actuator, like any capture), ingested and preprocessed
into the same version, so the next iteration's map has seen it: the support grows where
the designer is going. Its gait becomes an added level of the stored experiment design
(`suds_exp.ingest.add_trial_levels`), so campaigns and reports take it as a condition.
Its achieved motion is measured on the simulator by
`suds_exp.gait.truth` (the same measurement as the ceiling benchmark). Without
``verify`` the data never change and each iteration only widens the trust radius.

Every iteration is stored in ``gait_design_iterations`` (migration 017).

The optimiser is Nelder-Mead with penalties (a fitted map is cheap, a few ms a gait, but
not smooth enough for gradients), started from the best gait so far and from the paper's
circle O, plain and tilted either way (`LAGS_RAD`), and from the best gait traced 2 ..
``order`` times a cycle (`traced_starts`: from a loop traced once, the search keeps the
zero harmonics near zero); on a body of m joints the circle is the travelling wave it
generalises (`circle`). When none of these fits the trust region,
the search also starts from the data's mean path (`data_gait`).

``verify`` runs the swimmer simulator, so only a swimmer's version can be verified; any
other body is refused in one line before anything is stored.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd
import sqlalchemy as sa
from scipy.optimize import minimize

from suds_exp.errors import ConfigError
from suds_exp.gait.joints import describe, is_swimmer, version_joints
from suds_exp.gait.motion import CycleMotion
from suds_exp.gait.predict import decimate, derive_seed, fit_map
from suds_exp.gait.shape import SWIMMER_JOINTS, FourierGait, check_bound, within_bound
from suds_exp.gait.support import Support
from suds_exp.gait.trials import simulate_gait_file
from suds_exp.gait.truth import simulate_gaits
from suds_exp.ingest import add_trial_levels, stored_design, trial_level_axis
from suds_exp.models import make_model
from suds_exp.models.registry import GMR
from suds_exp.preprocess import get_version
from suds_exp.preprocess import preprocess as run_preprocess
from suds_exp.sim import SimConfig
from suds_exp.store import Store

#: Joint lags (rad) of the multi-start circles: the one-harmonic gaits span amplitude and
#: lag; a local search from the circle alone stays near it, so the search also starts
#: from the circle tilted either way (each pulled inside the trust region first).
LAGS_RAD = (-0.6, 0.0, 0.6)
#: Amplitudes of the multi-start circles, as fractions of the joint bound, beside the
#: paper's circle O (1 rad): the forward displacement grows with the enclosed area, and a
#: local search from 1 rad alone rarely widens the gait to the bound.
AMPLITUDES_OF_BOUND = (0.95,)

#: Penalty (mm of forward displacement) per rad beyond the bound or the trust radius.
PENALTY_MM_PER_RAD = 500.0


@dataclass
class DesignOptions:
    """The recipe of a design run (stored as its definition).

    bound (rad, every joint), frequency_hz (Hz), order (Fourier harmonics a joint), trust0
    (rad, first trust radius), trust_max (rad), grow / grow_fast / shrink (radius factors),
    accept_error (relative prediction error that counts as trusted), max_evals (map
    evaluations per start), cycles (of a verify trial), amplitude_starts (how many of
    `AMPLITUDES_OF_BOUND` to start from), radius_rule ("error": grow or shrink on the
    verified prediction's
    relative error; "ratio": the textbook rule on achieved / predicted gain).
    """

    learner: str = GMR
    bound: float = 1.3
    iterations: int = 5
    verify: bool = False
    frequency_hz: float = 0.5
    order: int = 2
    trust0: float = 0.15
    trust_max: float = 0.4
    grow: float = 1.5
    grow_fast: float = 2.0
    shrink: float = 0.5
    accept_error: float = 0.2
    max_evals: int = 400
    cycles: int = 10
    amplitude_starts: int = 1
    radius_rule: str = "ratio"

    def check(self) -> None:
        if not 0 < self.bound <= 3.0:
            raise ConfigError(f"bound {self.bound}: expected 0 < bound <= 3 rad", param="bound")
        if self.iterations < 1:
            raise ConfigError(f"iterations {self.iterations}: must be >= 1", param="iterations")
        if not 1 <= self.order <= 5:
            raise ConfigError(f"order {self.order}: expected 1..5 harmonics", param="order")
        if not self.frequency_hz > 0:
            raise ConfigError(f"frequency {self.frequency_hz}: must be > 0 Hz", param="freq")
        if self.radius_rule not in ("error", "ratio"):
            raise ConfigError(
                f"radius_rule {self.radius_rule!r}: expected 'error' or 'ratio'",
                param="radius_rule",
            )


@dataclass
class Iteration:
    """One design iteration: the gait, its predicted and (verify) achieved motion."""

    iteration: int
    gait: FourierGait
    predicted: CycleMotion
    achieved: CycleMotion | None
    trust_radius: float
    support_distance: float
    support: dict
    trial_id: int | None
    seconds: float

    def to_dict(self) -> dict:
        out = {"iteration": self.iteration} | self.gait.to_dict()
        out["coefficients"] = self.gait.to_vector().round(6).tolist()
        out["predicted"] = self.predicted.to_dict()
        if self.achieved is not None:
            out["achieved"] = self.achieved.to_dict()
        out |= {
            "trust_radius": round(self.trust_radius, 4),
            "support_distance": round(self.support_distance, 4),
            "support": self.support,
            "trial_id": self.trial_id,
            "seconds": round(self.seconds, 2),
        }
        return out


@dataclass
class Design:
    """A design run: its id in the store, options, the version's actuated joints and
    the iterations."""

    id: int
    prep_version: int
    options: DesignOptions
    iterations: list[Iteration] = field(default_factory=list)
    joints: tuple[str, ...] = SWIMMER_JOINTS

    def to_dict(self) -> dict:
        return {
            "design_id": self.id,
            "prep_version": self.prep_version,
            "joints": list(self.joints),
            "options": asdict(self.options),
            "iterations": [it.to_dict() for it in self.iterations],
        }


def circle(
    radius: float,
    order: int,
    name: str = "circle",
    lag: float = 0.0,
    joints: tuple[str, ...] = SWIMMER_JOINTS,
    traces: int = 1,
) -> FourierGait:
    """Joint j at r cos(t - j (pi/2 - lag)) rad, with ``order`` harmonics: for the
    swimmer phi1 = r cos t, phi2 = r sin(t + lag) (the paper's O at r = 1, lag = 0; a lag
    tilts the circle into an ellipse); on m joints the travelling wave it generalises
    (one joint: r cos t). ``traces``: times the loop is traced a cycle (t -> traces t;
    at most ``order``)."""
    if not 1 <= traces <= order:
        raise ConfigError(f"circle: traces {traces}: expected 1 .. order ({order})")
    m = len(joints)
    a = np.zeros((1, m))
    b = np.zeros((1, m))
    behind = np.arange(m) * (np.pi / 2 - lag)
    a[0] = radius * np.cos(behind)
    b[0] = radius * np.sin(behind)
    return FourierGait(np.zeros(m), a, b, name, joints).traced(traces, order)


def traced_starts(gaits, order: int) -> list[FourierGait]:
    """Each Fourier gait of ``gaits`` traced 2 .. ``order`` times a cycle
    (`FourierGait.traced`): starts a local search would not reach from loops traced
    once. A rate-independent body goes about k times as far per cycle on a loop traced k
    times, so the best gait of an order-2 family is often a loop traced twice; the map
    judges each start, nothing here assumes it."""
    return [
        g.traced(k, order) for g in gaits if isinstance(g, FourierGait) for k in range(2, order + 1)
    ]


def optimise_gait(
    objective,
    support: Support,
    bound: float,
    trust: float,
    starts: list[FourierGait],
    max_evals: int = 800,
    name: str = "design",
) -> tuple[FourierGait, float]:
    """Maximise ``objective(gait)`` (mm) over Fourier gaits within ``bound`` (rad) and
    the trust radius ``trust`` (rad) from ``support``; Nelder-Mead from each start.
    Returns (best gait, its objective)."""

    joints = starts[0].joints

    def penalised(x):
        g = within_bound(FourierGait.from_vector(x, name, joints), bound)
        excess = support.gait_distance(g) - trust
        if excess > 0:
            # outside: only the way back counts, so the search cannot trade for it
            return PENALTY_MM_PER_RAD * (1 + excess)
        return -objective(g)

    best_x, best_f = None, np.inf
    for s in starts:
        x0 = s.to_vector()
        res = minimize(
            penalised,
            x0,
            method="Nelder-Mead",
            options={"maxfev": max_evals, "xatol": 1e-3, "fatol": 1e-2, "adaptive": True},
        )
        for x, f in ((res.x, res.fun), (x0, penalised(x0))):
            if f < best_f:
                best_x, best_f = x, f
    best = within_bound(FourierGait.from_vector(best_x, name, joints), bound)
    # the search kept the bound on 256 phases; make it hold on a finer grid too
    while best.max_abs() > bound:
        best = FourierGait(best.a0, best.a * 0.999, best.b * 0.999, name, joints)
    return best, objective(best)


def _circle_starts(opts: DesignOptions, joints: tuple[str, ...]) -> list[FourierGait]:
    """The multi-start circles of ``joints``: radius 1 rad (the paper's O) and
    `AMPLITUDES_OF_BOUND` of the bound (when below ``amplitude_starts``'s cap), each at
    every lag of `LAGS_RAD` (one joint: no lag to tilt)."""
    radii = (1.0, *(f * opts.bound for f in AMPLITUDES_OF_BOUND[: opts.amplitude_starts]))
    lags = LAGS_RAD if len(joints) > 1 else (0.0,)
    return [circle(r, opts.order, lag=d, joints=joints) for r in radii for d in lags]


def data_gait(samples: pd.DataFrame, order: int, joints: tuple[str, ...]) -> FourierGait:
    """The training data's mean path: each joint's angle (rad) fitted by least squares on
    the samples' phase (rad) with ``order`` harmonics, as a gait of ``joints``."""
    theta = samples["phase"].to_numpy(float)
    n = np.arange(1, order + 1)
    basis = np.hstack(
        [np.ones((len(theta), 1)), np.cos(theta[:, None] * n), np.sin(theta[:, None] * n)]
    )
    ra = samples[[f"ra_{j + 1}" for j in range(len(joints))]].to_numpy(float)
    coef = np.linalg.lstsq(basis, ra, rcond=None)[0]  # (1 + 2 order, m)
    return FourierGait(coef[0], coef[1 : 1 + order], coef[1 + order :], "data", joints)


def _fit_inside(gait: FourierGait, support: Support, bound: float, trust: float) -> FourierGait:
    """The start shrunk towards its centre until it is inside bound and trust region."""
    for scale in np.linspace(1.0, 0.3, 15):
        x = gait.to_vector().copy()
        x[2:] *= scale
        g = FourierGait.from_vector(x, gait.name, gait.joints)
        if g.max_abs(128) <= bound and support.gait_distance(g) <= trust:
            return g
    return gait


def design_gait(
    store: Store,
    prep=None,
    options: DesignOptions | None = None,
    out: str | Path = Path("reports") / "gait-design",
    config: SimConfig | None = None,
    progress=None,
) -> Design:
    """`gait design`: the design loop on version ``prep`` (see the module docstring).

    out: folder for the verify trials' files and the designed gaits' TOML; config: the
    simulator of the verify trials (default nominal). ``progress``: called with each
    finished `Iteration`. Returns the `Design`, already stored.
    """
    opts = options or DesignOptions()
    opts.check()
    make_model(opts.learner)  # an unknown learner is refused before anything is stored
    version = get_version(store, prep)
    joints = version_joints(version.params)
    if opts.verify and not is_swimmer(version.params):
        raise ConfigError(
            f"verify: {describe(version.name, version.params)}: verify runs each designed "
            "gait on the swimmer simulator, which moves only the swimmer; design without "
            "verify",
            param="verify",
        )
    samples = version.samples()
    if samples.empty:
        raise ConfigError(
            f"version {version.name} has no samples; preprocess trials first", step="preprocess"
        )
    if opts.verify:
        # refused before anything is stored: where the verify trials would go
        trial_level_axis(stored_design(store))
    design_id = _register(store, version.id, opts)
    design = Design(design_id, version.id, opts, joints=joints)
    out = Path(out)
    trust = opts.trust0
    best = circle(1.0, opts.order, "O", joints=joints)
    best_achieved = -np.inf
    for it in range(1, opts.iterations + 1):
        started = time.perf_counter()
        fitted = fit_map(samples, opts.learner)
        support = Support.of(decimate(samples))
        name = f"design-{design_id}-it{it}.toml"
        starts = [
            _fit_inside(g, support, opts.bound, trust)
            for g in (best, *traced_starts([best], opts.order), *_circle_starts(opts, joints))
        ]
        if all(support.gait_distance(g) > trust for g in starts):
            # no circle fits the trust region (on a body of many joints whose data are not
            # circles): start too from the data's own mean path, inside it by construction
            starts.append(
                _fit_inside(data_gait(samples, opts.order, joints), support, opts.bound, trust)
            )
        gait, _ = optimise_gait(
            lambda g, fitted=fitted: fitted.forward(g, opts.frequency_hz),
            support,
            opts.bound,
            trust,
            starts,
            opts.max_evals,
            name,
        )
        check_bound(gait, opts.bound, name)
        predicted = fitted.motion(gait, opts.frequency_hz)
        flag = support.flag(gait)
        distance = support.gait_distance(gait)
        summary = support.summary(joints) | {"n_trials": int(samples["trial_id"].nunique())}
        summary |= flag
        achieved, trial_id = None, None
        used = trust
        if opts.verify:
            trial_id = _verify_trial(store, version, gait, opts, out, design_id, it, config)
            achieved = simulate_gaits([gait], opts.frequency_hz, config)[0]
            factor, best_achieved = _verified_factor(
                opts, fitted, predicted, achieved, best, best_achieved, config
            )
            trust = min(opts.trust_max, trust * factor)
            if achieved.forward_mm > best_achieved:
                best, best_achieved = gait, achieved.forward_mm
            samples = version.samples()
        else:
            trust = min(opts.trust_max, trust * opts.grow)
            best = gait
        record = Iteration(
            it,
            gait,
            predicted,
            achieved,
            used,
            distance,
            summary,
            trial_id,
            time.perf_counter() - started,
        )
        _store_iteration(store, design_id, record)
        design.iterations.append(record)
        if progress is not None:
            progress(record)
    return design


def _verified_factor(opts, fitted, predicted, achieved, best, best_achieved, config):
    """The trust radius' factor after a verified iteration, and the best forward
    displacement achieved before it (mm; the start gait is simulated once, when the
    ratio rule first needs it)."""
    if opts.radius_rule != "ratio":
        error = abs(predicted.forward_mm - achieved.forward_mm) / max(
            abs(achieved.forward_mm), 1e-9
        )
        return _radius_factor(error, opts), best_achieved
    if not np.isfinite(best_achieved):
        best_achieved = simulate_gaits([best], opts.frequency_hz, config)[0].forward_mm
    factor = _ratio_factor(
        achieved.forward_mm - best_achieved,
        predicted.forward_mm - fitted.forward(best, opts.frequency_hz),
        opts,
    )
    return factor, best_achieved


def _ratio_factor(real_gain: float, predicted_gain: float, opts: DesignOptions) -> float:
    """The textbook trust-region rule on rho = achieved gain / predicted gain over the
    best verified gait (mm / mm): grow when rho > 0.75 (the map was right or too
    cautious), shrink when rho < 0.25 (it promised more than the simulator gave)."""
    if predicted_gain <= 0:
        return opts.grow if real_gain > 0 else opts.shrink
    rho = real_gain / predicted_gain
    if rho > 0.75:
        return opts.grow_fast if rho > 1.5 else opts.grow
    return 1.0 if rho >= 0.25 else opts.shrink


def _radius_factor(error: float, opts: DesignOptions) -> float:
    """The trust radius's factor after a verified step with relative prediction error
    ``error``: the classical rule with a very-successful tier (grow twice when the map
    was right within half the accepted error), shrink when it was wrong."""
    if error <= opts.accept_error / 2:
        return opts.grow_fast
    return opts.grow if error <= opts.accept_error else opts.shrink


def _verify_trial(store, version, gait, opts, out, design_id, it, config) -> int:
    """Simulate the gait as a capture, ingest it and preprocess it into ``version``;
    the new trial's id."""
    folder = out / f"design-{design_id}" / f"it{it}"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / gait.name).write_text(gait.to_toml())
    seed = derive_seed("gait-design", design_id, it) % 2**31
    summary = simulate_gait_file(
        folder, gait, config, (opts.frequency_hz,), 1, (opts.cycles, opts.cycles), seed, store
    )
    trial_id = int(summary["trial_ids"][0])
    # the designed gait becomes a level of the stored design, so that every command
    # treats its trial as one of the experiment's conditions
    add_trial_levels(store, {trial_id: gait.name}, added_by=f"gait design {design_id}")
    run_preprocess(store, version.name, params=version.params, trials=[trial_id], progress=False)
    return trial_id


def _register(store: Store, version_id: int, opts: DesignOptions) -> int:
    with store.write() as conn:
        return int(
            conn.execute(
                sa.text(
                    "INSERT INTO gait_designs (prep_version, learner, bound_rad, frequency_hz, "
                    "definition, created_at) VALUES (:v, :l, :b, :f, :d, :c) RETURNING id"
                ),
                {
                    "v": version_id,
                    "l": opts.learner,
                    "b": opts.bound,
                    "f": opts.frequency_hz,
                    "d": json.dumps(asdict(opts), sort_keys=True),
                    "c": datetime.now(UTC).replace(tzinfo=None),
                },
            ).scalar_one()
        )


def _store_iteration(store: Store, design_id: int, it: Iteration) -> None:
    row = {
        "design_id": design_id,
        "iteration": it.iteration,
        "gait": json.dumps(
            it.gait.to_dict()
            | {"coefficients": it.gait.to_vector().tolist(), "order": it.gait.order}
        ),
        "trust_radius": it.trust_radius,
        "support_distance": it.support_distance,
        "support": json.dumps(it.support),
        "trial_id": it.trial_id,
        "seconds": it.seconds,
    }
    for prefix, m in (("predicted", it.predicted), ("achieved", it.achieved)):
        for key in ("forward_mm", "lateral_mm", "turn_rad", "mean_vx_mm_s"):
            row[f"{prefix}_{key}"] = None if m is None else getattr(m, key)
    with store.write() as conn:
        Store.insert_df(conn, "gait_design_iterations", pd.DataFrame([row]))


def load_design(store: Store, design_id: int) -> pd.DataFrame:
    """The stored iterations of design ``design_id``, in order (one row each)."""
    return store.query_df(
        "SELECT * FROM gait_design_iterations WHERE design_id = ? ORDER BY iteration",
        [int(design_id)],
    )
