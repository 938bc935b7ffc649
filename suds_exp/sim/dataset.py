"""Simulated capture sessions: gait command -> actuator -> physics -> markers -> files.

Every trial's random numbers come from its own seed derived from
(seed, gait, frequency, repeat), so a trial's files do not depend on which other trials
are simulated with it or in which order; same seed, same files, byte for byte.
"""

from __future__ import annotations

import datetime as _dt
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from suds_exp.errors import ConfigError
from suds_exp.progress import progress_bar
from suds_exp.robot import FREQUENCIES_HZ, GAITS, gait_shape
from suds_exp.sim.config import SimConfig
from suds_exp.sim.files import write_manifest, write_qtm_tsv, write_truth
from suds_exp.sim.gaits import actuate
from suds_exp.sim.markers import MARKER_NAMES, measure, true_marker_positions
from suds_exp.sim.mechanics import simulate_prescribed

_GAIT_FILE_CODE = {"S+": "Sp", "S-": "Sm", "O": "O", "D-": "Dm", "D+": "Dp"}
_EPOCH = _dt.datetime(2026, 1, 1, 9, 0, 0)


@dataclass(frozen=True)
class TrialSpec:
    """One simulated trial: condition, its seed-derived randomness, and its drive."""

    gait: str
    frequency_hz: float
    repeat: int
    n_cycles: int
    phase0: float
    pose0: tuple[float, float, float]
    seed: tuple[int, ...]
    #: A gait from a file (phase rad (n,) -> r_a (n, 2) rad) in place of the named one;
    #: ``gait`` then holds the file's name.
    path: Callable | None = field(default=None, compare=False, repr=False)

    @property
    def name(self) -> str:
        mhz = int(round(self.frequency_hz * 1000))
        code = _GAIT_FILE_CODE.get(self.gait) or re.sub(r"[^A-Za-z0-9_-]+", "-", self.gait)
        return f"sim_{code}_{mhz:04d}mHz_r{self.repeat:02d}"


@dataclass(frozen=True)
class SimulatedDataset:
    """Paths written by `simulate_dataset` (TSV files in trial order)."""

    tsv_paths: list[Path]
    truth_paths: list[Path]
    manifest: Path
    simulated_seconds: float


def check_cycles(cycles: tuple[int, int], text: str | None = None) -> tuple[int, int]:
    """``cycles`` (MIN, MAX) if 1 <= MIN <= MAX, else a `ConfigError` (quoting ``text``,
    the string it was read from, when there is one)."""
    lo, hi = cycles
    if not 1 <= lo <= hi:
        shown = repr(text) if text is not None else f"({lo}, {hi})"
        raise ConfigError(f"cycles {shown}: expected 1 <= MIN <= MAX", param="cycles")
    return int(lo), int(hi)


@dataclass(frozen=True)
class SimDesign:
    """A simulated gait x frequency x repeat design, built once and passed through.

    ``gaits``: names of `GAITS`; ``frequencies_hz``: gait frequencies (Hz); ``repeats``:
    trials per condition; ``cycles``: (MIN, MAX) gait cycles per trial; ``seed``: the
    seed every trial's randomness derives from; ``changes``: `schedule.Change` items,
    effects switched on during every trial. Default: the paper's design. Gaits outside
    `GAITS` and cycles other than 1 <= MIN <= MAX are a `ConfigError`.
    """

    gaits: tuple[str, ...] = GAITS
    frequencies_hz: tuple[float, ...] = FREQUENCIES_HZ
    repeats: int = 4
    cycles: tuple[int, int] = (10, 30)
    seed: int = 0
    changes: tuple = ()

    def __post_init__(self):
        bad = [g for g in self.gaits if g not in GAITS]
        if bad or not self.gaits:
            raise ConfigError(
                f"gaits {list(self.gaits)!r}: expected some of {', '.join(GAITS)}",
                param="gaits",
            )
        # frozen: the normalised values are set through object's own __setattr__
        object.__setattr__(self, "gaits", tuple(self.gaits))
        object.__setattr__(self, "frequencies_hz", tuple(float(f) for f in self.frequencies_hz))
        object.__setattr__(self, "cycles", check_cycles(tuple(self.cycles)))
        object.__setattr__(self, "changes", tuple(self.changes))

    def keywords(self) -> dict:
        """The design as `simulate_dataset`'s keywords."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


def trial_seed(seed: int, gait: str, frequency_hz: float, repeat: int) -> tuple[int, ...]:
    """Entropy of one trial: independent of loop order and of the other trials."""
    return (int(seed), GAITS.index(gait), int(round(frequency_hz * 1e6)), int(repeat))


def plan_trials(
    gaits: Sequence[str] = GAITS,
    frequencies_hz: Sequence[float] = FREQUENCIES_HZ,
    repeats: int = 4,
    cycles: tuple[int, int] = (10, 30),
    seed: int = 0,
) -> list[TrialSpec]:
    """Trial specs of a gait x frequency x repeat design (repeats numbered from 1).

    A condition's repeats take their cycle counts from equal strata of `cycles` (one
    each, in an order drawn from the condition's seed): with 4 repeats of 10-30 cycles,
    the three longer ones hold at least 15 + 20 + 26 cycles.
    """
    for g in gaits:
        if g not in GAITS:
            raise ConfigError(f"gait {g!r}: expected one of {', '.join(GAITS)}")
    for f in frequencies_hz:
        if not f > 0:
            raise ConfigError(f"frequency {f!r}: must be > 0 Hz")
    if repeats < 1:
        raise ConfigError(f"repeats {repeats}: must be >= 1")
    lo, hi = cycles
    if not 1 <= lo <= hi:
        raise ConfigError(f"cycles {lo}:{hi}: expected 1 <= MIN <= MAX")
    specs = []
    span = hi - lo + 1
    for g in gaits:
        for f in frequencies_hz:
            # the repeats of a condition spread over the cycle range, one per stratum in
            # a random order, so the longest ones always leave enough cycles outside the
            # shortest (the paper's 48-cycle sweep point, whatever the seed)
            cond = trial_seed(seed, g, f, 0)
            strata = np.random.default_rng(np.random.SeedSequence(cond + (4,))).permutation(repeats)
            for r in range(1, repeats + 1):
                j = int(strata[r - 1])
                c_lo = lo + (j * span) // repeats
                c_hi = max(c_lo, lo + ((j + 1) * span) // repeats - 1)
                specs.append(draw_trial(g, f, r, trial_seed(seed, g, f, r), (c_lo, c_hi)))
    return specs


def draw_trial(
    gait: str,
    frequency_hz: float,
    repeat: int,
    seed: tuple[int, ...],
    cycles: tuple[int, int],
    path: Callable | None = None,
) -> TrialSpec:
    """The trial of (gait, frequency_hz Hz, repeat) with its randomness drawn from `seed`.

    Its cycle count is drawn from ``cycles`` (MIN, MAX), its start phase (rad) and start
    pose (x, y mm in [-300, 300], heading rad) from the stream ``seed + (0,)``.
    """
    rng = np.random.default_rng(np.random.SeedSequence(seed + (0,)))
    return TrialSpec(
        gait=gait,
        frequency_hz=float(frequency_hz),
        repeat=repeat,
        n_cycles=int(rng.integers(cycles[0], cycles[1] + 1)),
        phase0=float(rng.uniform(0, 2 * math.pi)),
        pose0=(
            float(rng.uniform(-300, 300)),
            float(rng.uniform(-300, 300)),
            float(rng.uniform(-math.pi, math.pi)),
        ),
        seed=seed,
        path=path,
    )


def drive(spec: TrialSpec, cfg: SimConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t (n,) s, commanded phase (n,) rad, phi (n, 2) rad) of one trial: the joint
    angles after the actuator's lag and tracking noise, which the `servo` effect (when
    on) then follows under load."""
    rate = cfg.measurement.sample_rate_hz
    n = int(round(spec.n_cycles / spec.frequency_hz * rate)) + 1
    t = np.arange(n) / rate
    phase = 2 * math.pi * spec.frequency_hz * t + spec.phase0
    rng = np.random.default_rng(np.random.SeedSequence(spec.seed + (1,)))
    shape = spec.path(phase) if spec.path is not None else gait_shape(spec.gait, phase)
    phi = actuate(shape, 1 / rate, cfg.actuator, rng)
    return t, phase, phi


def simulate_trials(
    specs: list[TrialSpec], cfg: SimConfig, changes: Sequence = ()
) -> list[dict[str, np.ndarray]]:
    """Simulate trials in one batched physics call; one truth-column dict per trial.

    `changes`: `schedule.Change` items, effects that take hold during the trials.
    """
    drives = [drive(s, cfg) for s in specs]
    if not specs:
        return []
    n_max = max(len(d[0]) for d in drives)
    phi = np.zeros((len(specs), n_max, 2))
    lengths = np.array([len(d[0]) for d in drives])
    for k, (_, _, p) in enumerate(drives):
        phi[k, : len(p)] = p
    dt = 1 / cfg.measurement.sample_rate_hz
    start = dict(
        pose0=np.array([s.pose0 for s in specs]),
        n_frames=lengths,
        commanded=True,
        trial_seeds=[s.seed for s in specs],
    )
    if changes:
        from suds_exp.sim.schedule import check_times, simulate_scheduled

        ends = {s.name: (len(d[0]) - 1) * dt for s, d in zip(specs, drives, strict=True)}
        check_times(changes, ends)
        out = simulate_scheduled(phi, dt, cfg, changes, **start)
    else:
        out = simulate_prescribed(phi, dt, cfg, **start)
    truths = []
    for k, (t, phase, _) in enumerate(drives):
        n = len(t)
        p = out["phi"][k, :n]
        cols = {"t": t, "phase_cmd": phase, "phi1": p[:, 0], "phi2": p[:, 1]}
        for j, c in enumerate(("x", "y", "theta")):
            cols[c] = out["pose"][k, :n, j]
        for j, c in enumerate(("vx", "vy", "wz")):
            cols[c] = out["vel"][k, :n, j]
        for i in range(4):
            cols[f"flipper_{i + 1}"] = out["flippers"][k, :n, i]
        cols["residual"] = out["residual"][k, :n]
        truths.append(cols)
    return truths


def truth_markers(truth: dict | object, cfg: SimConfig) -> np.ndarray:
    """Noise-free marker positions (n, 11, 3), mm, of a truth table (dict or DataFrame)."""
    pose = np.column_stack([np.asarray(truth[c]) for c in ("x", "y", "theta")])
    phi = np.column_stack([np.asarray(truth["phi1"]), np.asarray(truth["phi2"])])
    fl = np.column_stack([np.asarray(truth[f"flipper_{i}"]) for i in range(1, 5)])
    return true_marker_positions(cfg, pose, phi, fl, 1 / cfg.measurement.sample_rate_hz)


def simulate_dataset(
    out_dir: str | Path,
    config: SimConfig | None = None,
    gaits: Sequence[str] = GAITS,
    frequencies_hz: Sequence[float] = FREQUENCIES_HZ,
    repeats: int = 4,
    cycles: tuple[int, int] = (10, 30),
    seed: int = 0,
    progress: bool = False,
    batch_size: int = 20,
    changes: Sequence = (),
    specs: Sequence[TrialSpec] | None = None,
) -> SimulatedDataset:
    """Simulate a gait x frequency x repeat design and write its files into out_dir.

    Writes `<trial>.tsv` (QTM export of the 11 markers), `<trial>.truth.parquet` and
    `manifest.csv`. Default: the paper's design, 5 gaits x 3 frequencies x 4 repeats,
    10-30 cycles each. ``progress``: a bar over the written trials.
    `changes` (`schedule.Change` items) switch effects on during every trial; they are
    noted in the manifest as ``schedule=NAME=VALUE@Ts``. ``specs`` (e.g. trials of a
    gait file, `suds_exp.gait.trials.simulate_gait_file`) replace the planned design.
    """
    cfg = SimConfig() if config is None else config
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"{out}: cannot create output folder ({exc.strerror})") from None
    if specs is None:
        specs = plan_trials(gaits, frequencies_hz, repeats, cycles, seed)
    specs = list(specs)
    if changes:
        from suds_exp.sim.schedule import check_times

        # refuse a schedule past any trial's end before writing anything
        check_times(changes, {sp.name: sp.n_cycles / sp.frequency_hz for sp in specs})
    rows, tsvs, truths_written = [], [], []
    seconds = 0.0
    with progress_bar("Simulating", len(specs), enabled=progress, unit="trials") as advance:
        for start in range(0, len(specs), batch_size):
            batch = specs[start : start + batch_size]
            for spec, truth in zip(batch, simulate_trials(batch, cfg, changes), strict=True):
                row, tsv, truth_path = _write_trial(out, spec, truth, cfg, changes)
                rows.append(row)
                tsvs.append(tsv)
                truths_written.append(truth_path)
                seconds += truth["t"][-1]
                advance()
    manifest = out / "manifest.csv"
    write_manifest(manifest, rows)
    return SimulatedDataset(tsvs, truths_written, manifest, seconds)


def _write_trial(
    out: Path, spec: TrialSpec, truth: dict, cfg: SimConfig, changes: Sequence
) -> tuple[dict, Path, Path]:
    """Measure one simulated trial's markers, write its QTM TSV and truth Parquet files;
    (manifest row, TSV path, truth path)."""
    rng = np.random.default_rng(np.random.SeedSequence(spec.seed + (2,)))
    measured = measure(cfg, truth_markers(truth, cfg), rng)
    tsv = out / f"{spec.name}.tsv"
    # a plausible session clock: one hour per gait, a minute per repeat
    g, mhz, r = spec.seed[1] % 24, spec.seed[2] // 1000, spec.seed[3]
    stamp = _EPOCH + _dt.timedelta(seconds=3600 * g + 60 * r + mhz)
    write_qtm_tsv(tsv, measured, MARKER_NAMES, cfg.measurement.sample_rate_hz, stamp)
    truth_path = out / f"{spec.name}.truth.parquet"
    write_truth(truth_path, truth)
    row = {
        "file": tsv.name,
        "gait": spec.gait,
        "frequency_hz": f"{spec.frequency_hz:.6f}",
        "repeat": spec.repeat,
        "notes": f"simulated seed={spec.seed[0]} cycles={spec.n_cycles}"
        + "".join(f" schedule={c}" for c in changes),
    }
    return row, tsv, truth_path
