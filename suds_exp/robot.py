"""The robot and the experiment, named once: gaits, frequencies, marker roles, samples
columns, and the parsers of the few strings that name them.

Every other module takes these from here. This module imports nothing of the package but its errors,
so any box of the data flow may import it.

Gaits, with theta = 2 pi f t + phase0 (rad) and the signed k of `GAIT_K`:

    phi1 = cos(theta) + cos(3 theta) / k,   phi2 = sin(theta) - sin(3 theta) / k

k = +9 (D-), +4 (D+), -9 (S-), -4 (S+); O has no third harmonic (k infinite).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from suds_exp.errors import ConfigError

#: The gait axis of the paper, in order (gait similarity = steps along it).
GAITS = ("S+", "S-", "O", "D-", "D+")
#: Signed k of each gait's third harmonic (see the module docstring); inf = none.
GAIT_K = {"S+": -4.0, "S-": -9.0, "O": np.inf, "D-": 9.0, "D+": 4.0}
#: The paper's gait frequencies, Hz.
FREQUENCIES_HZ = (1 / 3, 1 / 2, 1.0)

#: The robot's 11 marker roles and the segment each sits on: top-face, raised (spoke)
#: and lowered markers of the head and tail segments, and one marker on each flipper
#: (1, 2 head; 3, 4 tail; odd = left, +Y side).
ROLE_SEGMENTS = {
    "head_top_1": "head",
    "head_top_2": "head",
    "head_spoke": "head",
    "tail_top_1": "tail",
    "tail_top_2": "tail",
    "tail_spoke": "tail",
    "tail_back": "tail",
    "flipper_1": "head",
    "flipper_2": "head",
    "flipper_3": "tail",
    "flipper_4": "tail",
}
ROLES = tuple(ROLE_SEGMENTS)
#: The raised markers on spokes (they ring: `suds_exp.sim` effect spoke_oscillation).
SPOKE_ROLES = ("head_spoke", "tail_spoke")
#: Passive markers in the order of the 12-number passive state, with their segment.
PASSIVE_ROLES = tuple(
    (role, ROLE_SEGMENTS[role])
    for role in ("head_spoke", "tail_spoke", "flipper_1", "flipper_2", "flipper_3", "flipper_4")
)

#: Most passive principal components a preprocessing version may keep (12 numbers).
MAX_K = 2 * len(PASSIVE_ROLES)
RA_COLUMNS = ("ra_1", "ra_2")
DRA_COLUMNS = ("dra_1", "dra_2")
RP_COLUMNS = tuple(f"rp_{i}" for i in range(1, MAX_K + 1))
DRP_COLUMNS = tuple(f"drp_{i}" for i in range(1, MAX_K + 1))
VB_COLUMNS = ("vx", "vy", "wz")
#: Leading columns of every samples frame: trial, frame, time (s), phase (rad,
#: unwrapped), cycle, r_a (rad) and its rate (rad/s).
SAMPLE_KEYS = ("trial_id", "frame", "t", "phase", "cycle", *RA_COLUMNS, *DRA_COLUMNS)


def sample_columns(k: int, m: int = 2) -> list[str]:
    """The standard samples columns for k passive components and m actuated values
    (2 joint angles, or 4 Cartesian values with ``ra_repr="cartesian"``), in order."""
    ra = [f"ra_{i}" for i in range(1, m + 1)]
    dra = [f"dra_{i}" for i in range(1, m + 1)]
    return [*SAMPLE_KEYS[:5], *ra, *dra, *RP_COLUMNS[:k], *DRP_COLUMNS[:k], *VB_COLUMNS]


def _gait_k(gait: str) -> float:
    try:
        return GAIT_K[gait]
    except KeyError:
        raise ConfigError(f"gait {gait!r}: expected one of {', '.join(GAITS)}") from None


def gait_shape(gait: str, theta) -> np.ndarray:
    """Commanded r_a = (phi1, phi2) of ``gait`` at phases ``theta`` (rad, any shape):
    array (*theta.shape, 2), rad."""
    k = _gait_k(gait)
    theta = np.asarray(theta, dtype=float)
    phi1 = np.cos(theta) + np.cos(3 * theta) / k
    phi2 = np.sin(theta) - np.sin(3 * theta) / k
    return np.stack([phi1, phi2], axis=-1)


def gait_shape_rate(gait: str, theta) -> np.ndarray:
    """d r_a / d theta of ``gait`` at phases ``theta`` (rad): array (*theta.shape, 2),
    rad per rad of phase."""
    k = _gait_k(gait)
    theta = np.asarray(theta, dtype=float)
    d1 = -np.sin(theta) - 3 * np.sin(3 * theta) / k
    d2 = np.cos(theta) - 3 * np.cos(3 * theta) / k
    return np.stack([d1, d2], axis=-1)


def parse_frequency(text: str) -> float:
    """``"0.5"`` or ``"1/3"`` -> Hz as a float; ValueError on anything else or <= 0."""
    try:
        value = float(Fraction(str(text).strip()))
    except ZeroDivisionError:
        raise ValueError(f"{text!r} divides by zero") from None
    if value <= 0:
        raise ValueError(f"{text!r} is not positive")
    return value


def parse_ids(text: str | None, option: str = "trials") -> list[int] | None:
    """``"1,2,5-8"`` -> [1, 2, 5, 6, 7, 8] (sorted, unique, each >= 1); None or blank ->
    None (all). ``option`` names the parameter in the error (ConfigError)."""
    if text is None or not str(text).strip():
        return None
    ids: set[int] = set()
    for part in str(text).split(","):
        part = part.strip()
        if not part:
            continue
        lo, sep, hi = part.partition("-")
        try:
            first, last = int(lo), int(hi) if sep else int(lo)
        except ValueError:
            raise ConfigError(
                f"{option} {text!r}: expected ids and ranges such as 1,2,5-8", param=option
            ) from None
        if first < 1 or last < first:
            raise ConfigError(
                f"{option} {text!r}: {part!r} is not a valid id or range", param=option
            )
        ids.update(range(first, last + 1))
    if not ids:
        raise ConfigError(
            f"{option} {text!r}: expected ids and ranges such as 1,2,5-8", param=option
        )
    return sorted(ids)
