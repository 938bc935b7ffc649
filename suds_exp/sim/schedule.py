"""Effects that switch on during a trial: ``--effect NAME=VALUE@Ts`` (a changing world).

A change is an effect assignment (the syntax of `set_effect`) with the trial time at which
it takes hold, e.g. ``flippers=locked@40s`` (the flippers jam at t = 40 s, at the angle
they are locked at), ``medium_compaction=on@20s`` (the bed starts compacting along the path
from t = 20 s), ``hinge_damping.damping=80@30s`` (the tape hinges stiffen). Changes apply
in time order on top of the configuration of the trial's start.

The physics is run piecewise: each stretch between two change times is one call of
`simulate_prescribed` with its configuration, started from the pose and flipper angles
where the previous stretch ended. State the kernel keeps internally restarts at a change:
the body-inertia lag starts from the quasi-static twist and compaction counts distance
from the change (so ``medium_compaction=on@20s`` is a bed that starts compacting then).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from suds_exp.errors import ConfigError
from suds_exp.sim.config import SimConfig
from suds_exp.sim.effects import set_effect
from suds_exp.sim.mechanics import simulate_prescribed

_AT = re.compile(r"^(?P<assignment>[^@]+)@\s*(?P<time>[-+0-9.eE]+)\s*s?\s*$")


@dataclass(frozen=True)
class Change:
    """One scheduled effect: ``assignment`` (``NAME=VALUE``) takes hold at ``time_s``."""

    assignment: str
    time_s: float

    def __str__(self) -> str:
        return f"{self.assignment}@{self.time_s:g}s"


def parse_change(text: str, config: SimConfig | None = None) -> Change:
    """``"flippers=locked@40s"`` -> Change; checks the effect against `config` (nominal).

    Raises ConfigError (one line, naming the option) for a missing or non-positive time
    or an assignment `set_effect` refuses (unknown effect, parameter or value).
    """
    m = _AT.match(text.strip())
    if not m:
        raise ConfigError(
            f"effects {text!r}: expected NAME=VALUE@TIMEs, e.g. flippers=locked@40s",
            param="effects",
        )
    try:
        time_s = float(m["time"])
    except ValueError:
        raise ConfigError(
            f"effects {text!r}: time {m['time']!r} is not a number of seconds", param="effects"
        ) from None
    if not np.isfinite(time_s) or time_s <= 0:
        raise ConfigError(f"effects {text!r}: the change time must be > 0 s", param="effects")
    assignment = m["assignment"].strip()
    try:
        set_effect(config or SimConfig(), assignment)
    except ConfigError as exc:
        raise ConfigError(f"{exc} (in schedule {text!r})", param=exc.param) from None
    return Change(assignment, time_s)


def split_effects(
    effects: Sequence[str], config: SimConfig | None = None
) -> tuple[list[str], list[Change]]:
    """``effects`` (``NAME=VALUE`` or ``NAME=VALUE@Ts``) -> (static assignments, changes
    sorted by time)."""
    static, changes = [], []
    for e in effects:
        if "@" in e:
            changes.append(parse_change(e, config))
        else:
            static.append(e)
    return static, sorted(changes, key=lambda c: c.time_s)


def check_times(changes: Sequence[Change], durations: dict[str, float]) -> None:
    """Raise ConfigError if a change comes at or after the end of a trial.

    durations: trial name -> duration in s.
    """
    for c in changes:
        for name, d in durations.items():
            if c.time_s >= d:
                raise ConfigError(
                    f"effects {str(c)!r}: {c.time_s:g} s is past the end of trial {name} "
                    f"({d:g} s long); give an earlier time or more cycles",
                    param=("effects", "cycles"),
                )


def configs_over_time(config: SimConfig, changes: Sequence[Change]) -> list[SimConfig]:
    """The configuration of each stretch: [start, after change 1, after change 2, ...]."""
    out = [config]
    for c in changes:
        out.append(set_effect(out[-1], c.assignment))
    return out


def simulate_scheduled(
    phi: np.ndarray,
    dt: float,
    config: SimConfig,
    changes: Sequence[Change],
    pose0: np.ndarray,
    n_frames: np.ndarray,
    **options,
) -> dict[str, np.ndarray]:
    """`simulate_prescribed` of a batch with effects changing at the scheduled times.

    phi (n_trials, n_max, 2) rad, dt s, pose0 (n_trials, 3), n_frames (n_trials,); every
    change must come before every trial's last frame (see `check_times`). ``options`` go
    to every stretch's `simulate_prescribed` (``commanded``, ``trial_seeds``); the servo's
    internal state restarts at each change. Returns the arrays of `simulate_prescribed`
    (pose, vel, flippers, phi, residual per frame).
    """
    configs = configs_over_time(config, changes)
    n_trials, n_max = phi.shape[:2]
    cuts = [0] + [int(round(c.time_s / dt)) for c in changes] + [n_max - 1]
    out = {
        "pose": np.full((n_trials, n_max, 3), np.nan),
        "vel": np.full((n_trials, n_max, 3), np.nan),
        "flippers": np.full((n_trials, n_max, 4), np.nan),
        "residual": np.full((n_trials, n_max), np.nan),
        "phi": np.full((n_trials, n_max, 2), np.nan),
    }
    start_pose = np.asarray(pose0, float)
    start_fl = np.zeros((n_trials, 4))
    for j, cfg in enumerate(configs):
        a, b = cuts[j], cuts[j + 1]
        if b <= a and j < len(configs) - 1:
            continue
        lengths = np.clip(np.asarray(n_frames) - a, 1, b - a + 1)
        piece = simulate_prescribed(
            phi[:, a : b + 1],
            dt,
            cfg,
            pose0=start_pose,
            flippers0=start_fl,
            n_frames=lengths,
            **options,
        )
        # frame a was written by the previous stretch; keep it and take a+1.. from this one
        first = 0 if j == 0 else 1
        for key in out:
            out[key][:, a + first : b + 1] = piece[key][:, first:]
        last = np.minimum(lengths - 1, b - a)
        rows = np.arange(n_trials)
        start_pose = piece["pose"][rows, last]
        start_fl = piece["flippers"][rows, last]
    return out
