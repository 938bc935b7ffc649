"""Predict what a gait does from a learned motility map.

The learner is fitted on a preprocessing version's trials (decimated to the same samples
per cycle at every frequency by the campaign's rule: the fewest of any trial), rolled over
the gait and the body's path reconstructed by the path-ordered SE(2) integral
(`suds_exp.gait.motion`):

- phase-free learners (GMR) see only (r_a, dr_a/dt) of the gait;
- phase-based learners (phase-only, TLS) get the gait's own phase as ``phase``;
- SUDS learners run in ``mode="rollout"``: r_p starts at the training mean and follows
  their own passive dynamics along the gait.

The gait is rolled for `N_CYCLES` cycles and cycles `MEASURED` are averaged (the rollout
of r_p settles first); a learner without memory (no r_p, no branching) needs one cycle.
A bootstrap over training trials (resampled with replacement,
seeds derived from the request) gives each number's interval: the 2.5 and 97.5
percentiles of at least `MIN_BOOT` refits (`percentile_interval`); an estimate outside
its interval is reported with a note saying why. Every prediction says whether the gait
lies inside the training data's support (`suds_exp.gait.support`): outside, the map
extrapolates.

A gait is matched to the version's actuated joints by name (`suds_exp.gait.joints`).
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from suds_exp.errors import ConfigError
from suds_exp.gait.joints import body_label, match_joints, version_joints
from suds_exp.gait.motion import CycleMotion, cycle_motion, integrate_twists
from suds_exp.gait.shape import TWO_PI, Gait
from suds_exp.gait.support import Support, actuated_columns
from suds_exp.models import make_model
from suds_exp.models.base import Columns, TimeSeries
from suds_exp.models.registry import GMR
from suds_exp.preprocess import get_version
from suds_exp.robot import DRP_COLUMNS, RP_COLUMNS

#: Cycles rolled and the cycles (0-based) averaged.
N_CYCLES = 4
MEASURED = (2, 3)
#: Samples per cycle of the rolled gait (and of training data whose rate is unknown).
SAMPLES_PER_CYCLE = 100
MOTION_KEYS = ("forward_mm", "lateral_mm", "turn_rad", "mean_vx_mm_s")
#: Decimals each motion number is reported with (`CycleMotion.to_dict`'s), its interval too.
DIGITS = {"forward_mm": 4, "lateral_mm": 4, "turn_rad": 6, "mean_vx_mm_s": 4}


def derive_seed(*key) -> int:
    """A 32-bit seed from a JSON-able key (stable across runs and machines)."""
    text = json.dumps([str(k) for k in key])
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:4], "little")


def _raw_samples_per_cycle(trial: pd.DataFrame) -> float:
    dt = float(np.median(np.diff(trial["t"].to_numpy()))) if len(trial) > 1 else np.nan
    f = float(trial["frequency_hz"].iloc[0]) if "frequency_hz" in trial else np.nan
    return 1 / (f * dt) if np.isfinite(f) and f > 0 and dt > 0 else np.nan


def decimate(samples: pd.DataFrame, samples_per_cycle: int | None = None) -> pd.DataFrame:
    """Every trial's samples thinned to about ``samples_per_cycle`` per cycle (plain
    decimation by a whole factor from its frequency and sample spacing). None: the
    campaign's rule (`suds_exp.campaign.bank`), the fewest samples per cycle of any
    trial, so every frequency ends with the same."""
    trials = [t for _, t in samples.groupby("trial_id", sort=True)]
    raw = [_raw_samples_per_cycle(t) for t in trials]
    if samples_per_cycle is None:
        finite = [r for r in raw if np.isfinite(r)]
        samples_per_cycle = int(round(min(finite))) if finite else SAMPLES_PER_CYCLE
    parts = [
        t.iloc[:: max(1, int(round(r / samples_per_cycle))) if np.isfinite(r) else 1]
        for t, r in zip(trials, raw, strict=True)
    ]
    return pd.concat(parts) if parts else samples


def gait_samples(
    gait: Gait,
    frequency_hz: float,
    k: int = 0,
    rp0: np.ndarray | None = None,
    n_cycles: int = N_CYCLES,
    samples_per_cycle: int = SAMPLES_PER_CYCLE,
) -> pd.DataFrame:
    """A samples frame of the gait run at frequency_hz (Hz) from phase 0: the standard
    columns (t s, phase rad, ra_1 .. ra_m rad, dra_1 .. dra_m rad/s; m the gait's joints),
    r_p (k columns) held at rp0 (mm) for a rollout's start, dr_p/dt and v_b as NaN."""
    return GaitTable.of(frequency_hz, k, rp0, n_cycles, samples_per_cycle).columns(gait).frame()


@dataclass(frozen=True, eq=False)
class GaitTable:
    """What `gait_samples` holds that does not depend on the gait, built once for many
    gaits at one frequency_hz (Hz): the phases ``theta`` (n,) rad (n = n_cycles x
    samples_per_cycle + 1) and every column but r_a and dr_a/dt, in `gait_samples`'s
    column order (``head`` before them, ``tail`` after), and the rows' `TimeSeries`."""

    frequency_hz: float
    samples_per_cycle: int
    theta: np.ndarray
    head: dict
    tail: dict
    series: TimeSeries

    @classmethod
    def of(
        cls,
        frequency_hz: float,
        k: int = 0,
        rp0: np.ndarray | None = None,
        n_cycles: int = N_CYCLES,
        samples_per_cycle: int = SAMPLES_PER_CYCLE,
    ) -> GaitTable:
        n = n_cycles * samples_per_cycle + 1
        theta = TWO_PI * np.arange(n) / samples_per_cycle
        head = {
            "trial_id": np.zeros(n, dtype=np.int64),
            "frame": np.arange(n),
            "t": theta / (TWO_PI * frequency_hz),
            "phase": theta,
            "cycle": np.arange(n) // samples_per_cycle,
        }
        tail = {}
        rp0 = np.zeros(k) if rp0 is None else np.asarray(rp0, float)
        for j in range(k):
            tail[RP_COLUMNS[j]] = np.full(n, rp0[j])
            tail[DRP_COLUMNS[j]] = np.zeros(n)
        for c in ("vx", "vy", "wz"):
            tail[c] = np.full(n, np.nan)
        tail["frequency_hz"] = np.full(n, float(frequency_hz))
        series = TimeSeries.of(Columns(head))
        for a in (*head.values(), *tail.values(), series.order, series.starts, series.dt):
            a.flags.writeable = False  # shared by every gait's table
        return cls(frequency_hz, samples_per_cycle, theta, head, tail, series)

    def columns(self, gait: Gait) -> Columns:
        """The samples table of ``gait`` (the columns of `gait_samples`)."""
        ra = gait.shape(self.theta)
        dra = gait.rate(self.theta) * TWO_PI * self.frequency_hz
        m = ra.shape[1]
        actuated = {f"ra_{j + 1}": ra[:, j] for j in range(m)}
        actuated |= {f"dra_{j + 1}": dra[:, j] for j in range(m)}
        return Columns(self.head | actuated | self.tail, self.series)


def build_learner(name: str, params: dict | None = None):
    """`make_model(name, **params)`; SUDS learners switched to their rollout mode (a new
    gait has no measured r_p)."""
    model = make_model(name, **(params or {}))
    if "mode" in model.get_params():
        model.set_params(mode="rollout")
    return model


def rollout_motion(
    model,
    gait: Gait,
    frequency_hz: float,
    k: int = 0,
    rp0: np.ndarray | None = None,
    samples_per_cycle: int = SAMPLES_PER_CYCLE,
) -> CycleMotion:
    """Net motion per cycle of ``gait`` at frequency_hz predicted by a fitted ``model``
    (SE(2) integral of its predicted v_b; mean of cycles `MEASURED`)."""
    return Rollout.of(model, frequency_hz, k, rp0, samples_per_cycle).motion(gait)


@dataclass(frozen=True, eq=False)
class Rollout:
    """`rollout_motion` of one fitted ``model`` at one frequency, for many gaits: the
    gait's table (`GaitTable`) is built once, the model predicts from arrays
    (`Learner.predict_array`, the numbers of its `predict`); ``measured`` the cycles
    averaged."""

    model: object
    table: GaitTable
    measured: tuple

    @classmethod
    def of(
        cls,
        model,
        frequency_hz: float,
        k: int = 0,
        rp0: np.ndarray | None = None,
        samples_per_cycle: int = SAMPLES_PER_CYCLE,
    ) -> Rollout:
        # a learner without memory (no r_p to roll, no branch history) repeats every cycle
        memoryless = k == 0 and getattr(model, "branching", "none") == "none"
        cycles, measured = (1, (0,)) if memoryless else (N_CYCLES, MEASURED)
        return cls(model, GaitTable.of(frequency_hz, k, rp0, cycles, samples_per_cycle), measured)

    def motion(self, gait: Gait) -> CycleMotion:
        """Net motion per cycle of ``gait`` (see `rollout_motion`)."""
        spc = self.table.samples_per_cycle
        values = self.model.predict_array(self.table.columns(gait))
        # the layout a predicted frame's [vx, vy, wz].to_numpy() has: same arithmetic after
        vb = np.asfortranarray(values[:, :3])
        dt = 1 / (self.table.frequency_hz * spc)
        poses = integrate_twists(vb, dt)
        return cycle_motion(poses, spc, self.measured, vb[:, 0])


@dataclass
class FittedMap:
    """A learner fitted on training samples, with what a rollout needs: k (r_p columns)
    and rp0 (k,) mm, the training mean of r_p."""

    model: object
    k: int
    rp0: np.ndarray
    _rollouts: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def motion(self, gait: Gait, frequency_hz: float) -> CycleMotion:
        # one Rollout a frequency: the designer evaluates thousands of gaits at one
        roll = self._rollouts.get(frequency_hz)
        if roll is None:
            roll = self._rollouts[frequency_hz] = Rollout.of(
                self.model, frequency_hz, self.k, self.rp0
            )
        return roll.motion(gait)

    def forward(self, gait: Gait, frequency_hz: float) -> float:
        return self.motion(gait, frequency_hz).forward_mm


def fit_map(
    samples: pd.DataFrame,
    learner: str = GMR,
    params: dict | None = None,
    samples_per_cycle: int | None = None,
) -> FittedMap:
    """Fit ``learner`` on ``samples`` (the version's frame; decimated here as a campaign
    does, see `decimate`)."""
    train = decimate(samples, samples_per_cycle)
    k = sum(1 for c in RP_COLUMNS if c in train.columns)
    rp0 = train[list(RP_COLUMNS[:k])].mean().to_numpy(float) if k else np.zeros(0)
    model = build_learner(learner, params).fit(train)
    return FittedMap(model, k, rp0)


@dataclass
class GaitPrediction:
    """Predicted motion of one gait (point fit on all training trials), bootstrap
    intervals (2.5 and 97.5 percentiles over ``n_boot`` refits on resampled trials,
    `percentile_interval`) with a note for each estimate outside its interval, and the
    gait's place in the training data's support (`Support.flag`)."""

    gait: Gait
    frequency_hz: float
    learner: str
    motion: CycleMotion
    interval: dict = field(default_factory=dict)
    n_boot: int = 0
    support: dict = field(default_factory=dict)
    notes: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        out = {"gait": self.gait.name, "joints": list(self.gait.joints)}
        out |= {"frequency_hz": self.frequency_hz, "learner": self.learner}
        out |= self.motion.to_dict()
        out["n_boot"] = self.n_boot
        out["interval"] = self.interval
        out["interval_notes"] = self.notes
        out["support"] = self.support
        return out


#: Fewest refits a 95 % percentile interval is given from: the 2.5 and 97.5 percentiles
#: of B refits need at least one refit beyond each (B x 2.5 % >= 1). With 3 refits the
#: "interval" is the range of 3 numbers, and the full fit can fall outside it.
MIN_BOOT = 40


@dataclass(frozen=True)
class Interval:
    """A percentile bootstrap interval: ``low``, ``high`` (the estimate's unit) and
    ``note``, empty unless the estimate lies outside the interval (then why)."""

    low: float
    high: float
    note: str = ""


def percentile_interval(estimate: float, boots: np.ndarray, level: float = 0.95) -> Interval:
    """The percentile interval of ``boots`` (B,) refits at ``level`` around ``estimate``
    (the fit on all trials), with B >= `MIN_BOOT` at 95 % and one refit beyond each tail
    at any level (ConfigError otherwise).

    The interval is the refits' spread, not centred on the estimate by construction: when
    resampling trials shifts the refits (bootstrap bias: a resample holds about 63 % of
    the distinct trials, so its map is smoother or rougher than the full fit's), the
    estimate can lie outside. The interval is then reported as it is, with a note giving
    the bias (mean of refits - estimate) rather than moved or widened to include it.
    """
    boots = np.asarray(boots, float)
    tail = 50 * (1 - level)
    needed = max(MIN_BOOT, math.ceil(100 / tail - 1e-9))  # one refit beyond each tail
    if len(boots) < needed:
        raise ConfigError(
            f"n_boot {len(boots)}: a {100 * level:g} % percentile interval needs at least "
            f"{needed} refits (one beyond each {tail:g} % tail); give 0 for no interval or "
            f"{needed} or more",
            param="n_boot",
        )
    low, high = (float(v) for v in np.percentile(boots, [tail, 100 - tail]))
    if low <= estimate <= high:
        return Interval(low, high)
    bias = float(np.mean(boots)) - estimate
    side = "below" if estimate < low else "above"
    note = (
        f"estimate {estimate:.4g} outside its interval [{low:.4g}, {high:.4g}] ({side}): the "
        f"refits on resampled trials are shifted from the fit on all trials (bootstrap bias "
        f"{bias:+.4g}); the interval shows their spread, the estimate is the full fit"
    )
    return Interval(low, high, note)


def bootstrap_draws(samples: pd.DataFrame, n_boot: int, seed: int):
    """``n_boot`` samples frames, each the training trials resampled with replacement
    (draw b seeded by (seed, b)); a trial drawn twice is two series, renumbered 1..n."""
    ids = np.array(sorted(samples["trial_id"].unique()))
    groups = dict(tuple(samples.groupby("trial_id", sort=False)))
    for b in range(n_boot):
        rng = np.random.default_rng([seed, b])
        draw = rng.choice(ids, size=len(ids), replace=True)
        yield pd.concat(
            [groups[t].assign(trial_id=i + 1) for i, t in enumerate(draw)], ignore_index=True
        )


def predict_gaits(
    samples: pd.DataFrame,
    gaits: Sequence[Gait],
    frequency_hz: float,
    learner: str = GMR,
    params: dict | None = None,
    n_boot: int = 0,
    seed: int = 0,
    joints: Sequence[str] | None = None,
) -> list[GaitPrediction]:
    """Predict each gait's net motion per cycle at frequency_hz (Hz) from a learner fitted
    on ``samples``; with n_boot > 0 (at least `MIN_BOOT`), also a bootstrap interval over
    training trials. Each prediction carries the gait's support flag.

    joints: the names of the samples' r_a columns ra_1 .. ra_m (a version's,
    `suds_exp.gait.joints.version_joints`); each gait is matched to them by name. None:
    the gaits' columns must be as many as the samples' and are taken in order.
    """
    if not frequency_hz > 0:
        raise ConfigError(f"frequency {frequency_hz!r}: must be > 0 Hz", param="freq")
    if n_boot < 0:
        raise ConfigError(f"n_boot {n_boot}: must be >= 0", param="n_boot")
    if 0 < n_boot < MIN_BOOT:
        percentile_interval(0.0, np.zeros(n_boot))  # refused before any fit
    gaits = _matched(samples, gaits, joints)
    fitted = fit_map(samples, learner, params)
    support = Support.of(decimate(samples))
    points = [fitted.motion(g, frequency_hz) for g in gaits]
    boots = np.empty((n_boot, len(gaits), len(MOTION_KEYS)))
    for b, frame in enumerate(bootstrap_draws(samples, n_boot, seed)):
        fb = fit_map(frame, learner, params)
        for j, g in enumerate(gaits):
            m = fb.motion(g, frequency_hz)
            boots[b, j] = [getattr(m, key) for key in MOTION_KEYS]
    out = []
    for j, (g, m) in enumerate(zip(gaits, points, strict=True)):
        interval, notes = {}, {}
        for i, key in enumerate(MOTION_KEYS if n_boot else ()):
            iv = percentile_interval(getattr(m, key), boots[:, j, i])
            interval[key] = _outward(iv, DIGITS[key])
            if iv.note:
                notes[key] = iv.note
        flag = support.flag(g)
        out.append(GaitPrediction(g, frequency_hz, learner, m, interval, n_boot, flag, notes))
    return out


def _outward(iv: Interval, digits: int) -> list[float]:
    """[low, high] rounded outwards to ``digits`` decimals: rounding to nearest could put
    an estimate (rounded to the same digits) just outside its reported interval."""
    scale = 10.0**digits
    return [math.floor(iv.low * scale) / scale, math.ceil(iv.high * scale) / scale]


def _matched(samples: pd.DataFrame, gaits: Sequence[Gait], joints) -> list[Gait]:
    """The gaits with their columns in the order of the samples' r_a (see
    `predict_gaits`); refused in one line when they do not fit."""
    m = len(actuated_columns(samples)[0])
    if joints is not None:
        return [match_joints(g, joints, f"gait {g.name}") for g in gaits]
    for g in gaits:
        if len(g.joints) != m:
            raise ConfigError(
                f"gait {g.name}: {len(g.joints)} joint(s) ({', '.join(g.joints)}); the "
                f"samples hold {m} actuated joint(s) (ra_1 .. ra_{m})",
                param="gait_file",
            )
    return list(gaits)


def predict_gait(
    store,
    prep,
    learner: str,
    gait: Gait,
    frequency_hz: float,
    trials: Sequence[int] | None = None,
    n_boot: int = 10,
    params: dict | None = None,
) -> GaitPrediction:
    """`gait predict`: fit ``learner`` on version ``prep``'s trials (all by default) and
    predict ``gait`` at frequency_hz; the bootstrap's seeds derive from the request."""
    version = get_version(store, prep)
    joints = version_joints(version.params)
    where = f"{gait.name}: version {version.name} ({body_label(version.params)})"
    gait = match_joints(gait, joints, where)
    if 0 < n_boot < MIN_BOOT:
        percentile_interval(0.0, np.zeros(n_boot))  # refused before the samples are read
    samples = version.samples(trials)
    if samples.empty:
        raise ConfigError(f"trials {trials}: no samples in version {version.name}", param="trials")
    seed = derive_seed("gait-predict", version.id, learner, gait.name, frequency_hz, trials)
    return predict_gaits(samples, [gait], frequency_hz, learner, params, n_boot, seed, joints)[0]
