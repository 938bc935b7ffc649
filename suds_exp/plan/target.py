"""What a plan is for: a target set of gaits and frequencies, or the best gait within a
bound; and the map's error on a target set, measured on the simulator.

The default target of the map goal is a fixed set of gaits no declared level runs but
inside the paper grid's support (the grid's gaits are unit circles with a third
harmonic of amplitude 1/4 to 1/9; these are ellipses and third harmonics in between),
so a map's error on it is a held-out error of the whole grid's kind of data.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from suds_exp.errors import ConfigError
from suds_exp.gait.motion import CycleMotion
from suds_exp.gait.shape import JOINT_LIMIT_RAD, FourierGait, Gait, ellipse, read_gait_file
from suds_exp.gait.truth import simulate_gaits

GOALS = ("gait", "map")
#: Frequency (Hz) of the default targets and of the gait goal's trials: the paper's middle.
DEFAULT_FREQUENCY_HZ = 0.5


def third_harmonic(k: float, name: str) -> FourierGait:
    """phi1 = cos t + cos 3t / k, phi2 = sin t - sin 3t / k (rad): the paper's family
    (S+ is k = -4, D+ is k = 4) at another k."""
    a = np.array([[1.0, 0.0], [0.0, 0.0], [1 / k, 0.0]])
    b = np.array([[0.0, 1.0], [0.0, 0.0], [0.0, -1 / k]])
    return FourierGait([0.0, 0.0], a, b, name)


def unseen_gaits() -> list[Gait]:
    """The map goal's fixed held-out gaits inside the paper grid's support (rad)."""
    return [
        ellipse(1.1, 0.9, name="unseen-ellipse-wide"),
        ellipse(0.9, 1.1, name="unseen-ellipse-tall"),
        ellipse(1.0, 1.0, 0.15, name="unseen-tilted"),
        third_harmonic(6.0, "unseen-k6"),
        third_harmonic(-6.0, "unseen-k-6"),
    ]


def check_bound(bound: float) -> float:
    """Refuse a bound (rad) beyond the robot's joint limits or not positive."""
    if not 0 < bound <= JOINT_LIMIT_RAD:
        raise ConfigError(
            f"bound {bound:g}: expected 0 < bound <= {JOINT_LIMIT_RAD:g} rad (the robot's "
            "joint limits)",
            param="bound",
        )
    return float(bound)


@dataclass
class Target:
    """Gaits (and frequencies, Hz) a map should predict well, and the bound (rad) a
    designed gait must keep. ``files``: the gait files the gaits came from, if any."""

    gaits: list[Gait] = field(default_factory=unseen_gaits)
    frequencies_hz: tuple[float, ...] = (DEFAULT_FREQUENCY_HZ,)
    bound: float = 1.3
    files: tuple[str, ...] = ()

    @classmethod
    def of(
        cls,
        gait_files: Sequence[str | Path] = (),
        frequencies_hz: Sequence[float] = (),
        bound: float = 1.3,
    ) -> Target:
        """The target of the user's gait files (default: `unseen_gaits`) at
        ``frequencies_hz`` (default 1/2 Hz); files and bound are checked here, before
        anything is fitted or stored."""
        bound = check_bound(bound)
        for f in frequencies_hz:
            if not f > 0:
                raise ConfigError(f"frequencies_hz {f!r}: must be > 0 Hz", param="frequencies_hz")
        gaits = [read_gait_file(p) for p in gait_files] or unseen_gaits()
        freqs = tuple(float(f) for f in frequencies_hz) or (DEFAULT_FREQUENCY_HZ,)
        return cls(gaits, freqs, bound, tuple(str(p) for p in gait_files))

    def pairs(self) -> list[tuple[Gait, float]]:
        """Every (gait, frequency) of the target."""
        return [(g, f) for f in self.frequencies_hz for g in self.gaits]


class TargetTruth:
    """The simulator's net motion per cycle of each target (gait, frequency), computed
    once (nominal robot, the measurement of `suds_exp.gait.truth`)."""

    def __init__(self, target: Target, config=None):
        self.target = target
        self.motions: list[CycleMotion] = []
        for f in target.frequencies_hz:
            self.motions += simulate_gaits(target.gaits, f, config)

    def map_error(self, fitted) -> float:
        """RMS over the target pairs of the distance (mm) between the net displacement
        per cycle (forward, lateral) ``fitted`` (a `FittedMap`) predicts and the
        simulator's."""
        sq = []
        for (g, f), truth in zip(self.target.pairs(), self.motions, strict=True):
            m = fitted.motion(g, f)
            sq.append(
                (m.forward_mm - truth.forward_mm) ** 2 + (m.lateral_mm - truth.lateral_mm) ** 2
            )
        return float(np.sqrt(np.mean(sq)))
