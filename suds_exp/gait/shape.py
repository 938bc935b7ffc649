"""A gait: a closed path of the actuated joints r_a over one cycle, one column per
actuated joint, named as the body's joints (``joints``; the swimmer's are phi1, phi2).

Two kinds, one face (`Gait.shape(theta)`, `Gait.rate(theta)`, theta = phase in rad):

- `FourierGait`: r_j(theta) = a0_j + sum_n (a_nj cos(n theta) + b_nj sin(n theta)),
  read from TOML (one table a joint: ``[phi1] a0 = 0.0, cos = [1.2], sin = [0.0]``) and
  what the designer optimises.
- `SampledGait`: rows ``phase_rad,<joint>_rad,...`` over one cycle (CSV; the swimmer's
  ``phase_rad,phi1_rad,phi2_rad``), phase in [0, 2 pi) in increasing order, interpolated
  by a periodic cubic spline.

A file is refused in one line (`ConfigError` naming the file and row) when the phase has
a gap, the ends do not meet (the path is not closed), or an angle exceeds the bound.
Which body a gait fits is decided by its joints' names (`suds_exp.gait.joints`).
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from suds_exp.errors import ConfigError
from suds_exp.robot import GAITS, gait_shape, gait_shape_rate

TWO_PI = 2 * math.pi
#: Default joint bound (rad) a gait file must stay within: beyond it the segments fold
#: onto each other; `--bound` narrows it.
JOINT_LIMIT_RAD = 2.0
#: A CSV spacing larger than this many times the median spacing is a gap in phase.
GAP_FACTOR = 3.0
#: Ends meet when the step from the last row to the first (across 2 pi), per rad of
#: phase, is at most this many times the steepest step between rows.
END_FACTOR = 3.0
#: The swimmer's actuated joints: a gait's columns when none are named.
SWIMMER_JOINTS = ("phi1", "phi2")
#: A CSV column of a joint: its name and this suffix (``phi1_rad``).
ANGLE_SUFFIX = "_rad"


def default_joints(m: int) -> tuple[str, ...]:
    """Names of m joints when none are given: phi1 .. phim (the swimmer's at m = 2)."""
    return tuple(f"phi{j + 1}" for j in range(m))


class Gait:
    """A periodic joint path. Subclasses give `shape` and `rate`; `name` labels it and
    ``joints`` (m names) say which joint each column moves."""

    name: str
    joints: tuple[str, ...] = SWIMMER_JOINTS

    def shape(self, theta) -> np.ndarray:
        """r_a at phases theta (rad, any shape): array (*theta.shape, m), rad."""
        raise NotImplementedError

    def rate(self, theta) -> np.ndarray:
        """d r_a / d theta at phases theta: array (*theta.shape, m), rad per rad."""
        raise NotImplementedError

    def cycle(self, n: int = 200) -> tuple[np.ndarray, np.ndarray]:
        """(phase (n,) rad in [0, 2 pi), r_a (n, m) rad) over one cycle."""
        theta = TWO_PI * np.arange(n) / n
        return theta, self.shape(theta)

    def max_abs(self, n: int = 720) -> float:
        """Largest |angle| of any joint over the cycle (rad)."""
        return float(np.abs(self.cycle(n)[1]).max())

    def to_dict(self, n: int = 100) -> dict:
        """JSON-ready: name, joints and the path sampled at n phases (``phase_rad`` and
        one ``<joint>_rad`` list a joint, e.g. ``phi1_rad``, ``phi2_rad``)."""
        theta, r = self.cycle(n)
        out = {"name": self.name, "joints": list(self.joints)}
        out["phase_rad"] = [round(float(x), 6) for x in theta]
        for j, joint in enumerate(self.joints):
            out[joint + ANGLE_SUFFIX] = [round(float(x), 6) for x in r[:, j]]
        return out


@dataclass
class FourierGait(Gait):
    """r_j = a0[j] + sum_n a[n-1, j] cos(n theta) + b[n-1, j] sin(n theta), rad.

    a0 (m,), a (N, m), b (N, m): N harmonics of each of the m joints; ``joints`` their
    names (default phi1 .. phim).
    """

    a0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    name: str = "fourier"
    joints: tuple[str, ...] | None = None

    def __post_init__(self):
        self.a0 = np.atleast_1d(np.asarray(self.a0, float))
        m = len(self.a0)
        self.a = np.asarray(self.a, float).reshape(-1, m)
        self.b = np.asarray(self.b, float).reshape(-1, m)
        self.joints = default_joints(m) if self.joints is None else tuple(self.joints)
        if len(self.joints) != m:
            raise ConfigError(f"Fourier gait: {m} joint(s) of coefficients, joints {self.joints}")
        if self.a.shape != self.b.shape:
            raise ConfigError("Fourier gait: cos and sin need the same number of harmonics")

    @property
    def order(self) -> int:
        return len(self.a)

    def _basis(self, theta):
        theta = np.asarray(theta, float)
        n = np.arange(1, self.order + 1)
        arg = theta[..., None] * n
        return n, np.cos(arg), np.sin(arg)

    def shape(self, theta) -> np.ndarray:
        _, c, s = self._basis(theta)
        return self.a0 + c @ self.a + s @ self.b

    def rate(self, theta) -> np.ndarray:
        n, c, s = self._basis(theta)
        return (-s * n) @ self.a + (c * n) @ self.b

    def to_vector(self) -> np.ndarray:
        """(a0, a, b) flattened: m + 2 m N numbers (the designer's variables)."""
        return np.concatenate([self.a0, self.a.ravel(), self.b.ravel()])

    @classmethod
    def from_vector(
        cls, x, name: str = "fourier", joints: tuple[str, ...] = SWIMMER_JOINTS
    ) -> FourierGait:
        """The gait of `to_vector`'s numbers ``x`` for ``joints`` (m names)."""
        x = np.asarray(x, float)
        m = len(joints)
        n = (len(x) - m) // (2 * m)
        a, b = x[m : m + m * n].reshape(n, m), x[m + m * n :].reshape(n, m)
        return cls(x[:m], a, b, name, tuple(joints))

    def traced(self, times: int, order: int) -> FourierGait:
        """The loop of the gait's first ``order // times`` harmonics traced ``times`` times
        a cycle, as a gait of ``order`` harmonics: r(theta) -> r(times theta), so harmonic n
        becomes harmonic n x times and the rates scale by ``times``. A body whose motion
        depends on the shape path alone (rate-independent, principally kinematic) moves
        g^times per cycle where the loop moves g. Harmonics above ``order // times`` do
        not fit and are left out (a start for a search, not a copy)."""
        if times < 1 or order < times:
            raise ConfigError(f"traced: times {times}, order {order}: expected 1 <= times <= order")
        m = len(self.a0)
        a, b = np.zeros((order, m)), np.zeros((order, m))
        keep = min(self.order, order // times)
        a[times - 1 : keep * times : times] = self.a[:keep]
        b[times - 1 : keep * times : times] = self.b[:keep]
        return FourierGait(self.a0, a, b, self.name, self.joints)

    def to_toml(self) -> str:
        """The TOML text `read_gait_file` reads back."""
        lines = [f'name = "{self.name}"']
        for j, joint in enumerate(self.joints):
            lines += [
                "",
                f"[{_toml_key(joint)}]",
                f"a0 = {self.a0[j]:.9g}",
                "cos = [" + ", ".join(f"{v:.9g}" for v in self.a[:, j]) + "]",
                "sin = [" + ", ".join(f"{v:.9g}" for v in self.b[:, j]) + "]",
            ]
        return "\n".join(lines) + "\n"


def _toml_key(name: str) -> str:
    """A joint's name as a TOML table key: bare when TOML allows, else quoted."""
    return name if re.fullmatch(r"[A-Za-z0-9_-]+", name) else json.dumps(name)


@dataclass
class SampledGait(Gait):
    """A path given at phases ``phase`` (n,) rad in [0, 2 pi) with r_a ``phi`` (n, m)
    rad, interpolated by a periodic cubic spline; ``joints`` the m joints' names."""

    phase: np.ndarray
    phi: np.ndarray
    name: str = "sampled"
    joints: tuple[str, ...] | None = None
    _spline: CubicSpline = field(init=False, repr=False)

    def __post_init__(self):
        self.phi = np.asarray(self.phi, float).reshape(len(self.phase), -1)
        m = self.phi.shape[1]
        self.joints = default_joints(m) if self.joints is None else tuple(self.joints)
        x = np.append(self.phase, self.phase[0] + TWO_PI)
        y = np.vstack([self.phi, self.phi[:1]])
        self._spline = CubicSpline(x, y, axis=0, bc_type="periodic")

    def _wrap(self, theta):
        theta = np.asarray(theta, float)
        return self.phase[0] + np.mod(theta - self.phase[0], TWO_PI)

    def shape(self, theta) -> np.ndarray:
        return self._spline(self._wrap(theta))

    def rate(self, theta) -> np.ndarray:
        return self._spline(self._wrap(theta), 1)


@dataclass
class NamedGait(Gait):
    """One of the paper's gaits (S+, S-, O, D-, D+), exactly as the simulator runs it."""

    name: str

    def shape(self, theta) -> np.ndarray:
        return gait_shape(self.name, theta)

    def rate(self, theta) -> np.ndarray:
        return gait_shape_rate(self.name, theta)


def paper_gaits() -> list[Gait]:
    """The paper's five gaits, in the order of the gait axis."""
    return [NamedGait(g) for g in GAITS]


def ellipse(a1: float, a2: float, shift: float = 0.0, c1=0.0, c2=0.0, name=None) -> FourierGait:
    """phi1 = c1 + a1 cos(theta), phi2 = c2 + a2 sin(theta + shift) (rad): circles,
    ellipses, phase-shifted and offset ones."""
    a = np.array([[a1, a2 * math.sin(shift)]])
    b = np.array([[0.0, a2 * math.cos(shift)]])
    label = name or f"ellipse({a1:g},{a2:g},{shift:g},{c1:g},{c2:g})"
    return FourierGait([c1, c2], a, b, label)


def within_bound(gait: FourierGait, bound: float, n: int = 256) -> FourierGait:
    """The gait with its oscillation (not its centre) scaled down just enough that
    every joint's |angle| <= bound (rad) on n phases; unchanged when already inside. A search
    over coefficients through this map never leaves the bound, and the bound's edge is
    continuous for it (no penalty wall)."""
    theta = TWO_PI * np.arange(n) / n
    r = gait.shape(theta)
    if np.abs(r).max() <= bound:
        return gait
    osc = r - gait.a0
    # largest s with |a0 + s osc| <= bound everywhere (the centre itself clipped inside)
    a0 = np.clip(gait.a0, -0.95 * bound, 0.95 * bound)
    with np.errstate(divide="ignore", invalid="ignore"):
        room = np.where(osc > 0, (bound - a0) / osc, np.where(osc < 0, (-bound - a0) / osc, np.inf))
    scale = min(1.0, float(np.min(room)) * (1 - 1e-9))
    return FourierGait(a0, gait.a * scale, gait.b * scale, gait.name, gait.joints)


def check_bound(gait: Gait, bound: float, where: str) -> None:
    """Refuse a gait that leaves |angle| <= bound (rad) at any joint."""
    worst = gait.max_abs()
    if worst > bound + 1e-9:
        raise ConfigError(
            f"{where}: an angle reaches {worst:.3f} rad, beyond the bound {bound:g} rad; "
            "scale the gait down or raise the bound",
        )


def read_gait_file(path: str | Path, bound: float = JOINT_LIMIT_RAD) -> Gait:
    """A gait from a CSV (``phase_rad,<joint>_rad,...``, the swimmer's
    ``phase_rad,phi1_rad,phi2_rad``) or TOML (Fourier, one table a joint) file.

    The gait's name is the file's name, its joints the columns' (tables') names in file
    order. Raises ConfigError (one line, naming the file and
    row) for a missing file, wrong columns, phase outside [0, 2 pi) or out of order, a gap
    in phase, ends that do not meet, or an angle beyond ``bound`` (rad).
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: gait file not found", param="gait_file")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        gait = _read_csv(path)
    elif suffix == ".toml":
        gait = _read_toml(path)
    else:
        raise ConfigError(
            f"{path}: expected a .csv (phase_rad,<joint>_rad,...) or .toml (Fourier) gait",
            param="gait_file",
        )
    check_bound(gait, bound, str(path))
    return gait


def _read_csv(path: Path) -> SampledGait:
    try:
        table = pd.read_csv(path, comment="#")
    except (ValueError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: not a readable CSV ({exc})", param="gait_file") from None
    cols = [c.strip() for c in table.columns]
    joints = _csv_joints(path, cols)
    values = table.apply(pd.to_numeric, errors="coerce").to_numpy(float)
    bad = np.flatnonzero(~np.isfinite(values).all(axis=1))
    if len(bad):
        raise ConfigError(
            f"{path}: row {bad[0] + 2}: expected {len(cols)} numbers", param="gait_file"
        )
    if len(values) < 8:
        raise ConfigError(f"{path}: {len(values)} rows; expected at least 8 over one cycle")
    phase, phi = values[:, 0], values[:, 1:]
    if np.isclose(phase[-1], TWO_PI) and np.allclose(phi[-1], phi[0], atol=1e-6):
        phase, phi = phase[:-1], phi[:-1]  # a closing row repeating the first is allowed
    outside = np.flatnonzero((phase < 0) | (phase >= TWO_PI))
    if len(outside):
        raise ConfigError(
            f"{path}: row {outside[0] + 2}: phase {phase[outside[0]]:g} rad outside [0, 2 pi)",
            param="gait_file",
        )
    step = np.diff(np.append(phase, phase[0] + TWO_PI))
    back = np.flatnonzero(step[:-1] <= 0)
    if len(back):
        raise ConfigError(
            f"{path}: row {back[0] + 3}: phase does not increase; rows must be in phase order",
            param="gait_file",
        )
    typical = float(np.median(step))
    gap = int(np.argmax(step))
    if step[gap] > GAP_FACTOR * typical:
        where = f"rows {gap + 2}-{gap + 3}" if gap < len(step) - 1 else "last row to first"
        raise ConfigError(
            f"{path}: {where}: gap of {step[gap]:.3f} rad in phase (spacing {typical:.3f}); "
            "give the path over the whole cycle",
            param="gait_file",
        )
    slopes = np.linalg.norm(np.diff(phi, axis=0), axis=1) / step[:-1]
    wrap = np.linalg.norm(phi[0] - phi[-1]) / step[-1]
    if wrap > END_FACTOR * max(float(slopes.max()), 1e-3):
        raise ConfigError(
            f"{path}: the ends do not meet (last row {np.round(phi[-1], 3).tolist()}, first "
            f"{np.round(phi[0], 3).tolist()} rad); a gait is a closed path over one cycle",
            param="gait_file",
        )
    return SampledGait(phase, phi, path.name, joints)


def _csv_joints(path: Path, cols: list[str]) -> tuple[str, ...]:
    """The joints of a gait CSV's header ``phase_rad,<joint>_rad,...`` (one or more)."""
    expected = "phase_rad,JOINT_rad,... (one column per actuated joint, e.g. phi1_rad,phi2_rad)"
    if len(cols) < 2 or cols[0] != "phase_rad":
        raise ConfigError(
            f"{path}: columns {','.join(cols)}; expected {expected}", param="gait_file"
        )
    joints = []
    for c in cols[1:]:
        if not c.endswith(ANGLE_SUFFIX) or c == ANGLE_SUFFIX:
            raise ConfigError(f"{path}: column {c!r}: expected {expected}", param="gait_file")
        joints.append(c[: -len(ANGLE_SUFFIX)])
    twice = sorted({j for j in joints if joints.count(j) > 1})
    if twice:
        raise ConfigError(f"{path}: joint {twice[0]!r} has two columns", param="gait_file")
    return tuple(joints)


def _read_toml(path: Path) -> FourierGait:
    try:
        doc = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})", param="gait_file") from None
    joints = [k for k in doc if k != "name"]
    loose = [k for k in joints if not isinstance(doc[k], dict)]
    if loose or not joints:
        what = f"entry {loose[0]!r} is not a table; expected" if loose else "no joint; expected"
        raise ConfigError(
            f"{path}: {what} one table a joint, named as the body's joints ([phi1], "
            "[phi2] for the swimmer; keys a0, cos, sin), and an optional name",
            param="gait_file",
        )
    a0, cos, sin = [], [], []
    for j in joints:
        t = doc[j]
        extra = set(t) - {"a0", "cos", "sin"}
        if extra:
            raise ConfigError(f"{path}: [{j}] unknown keys {sorted(extra)}; expected a0, cos, sin")
        try:
            a0.append(float(t.get("a0", 0.0)))
            cos.append([float(v) for v in t.get("cos", [])])
            sin.append([float(v) for v in t.get("sin", [])])
        except (TypeError, ValueError):
            raise ConfigError(f"{path}: [{j}]: a0 a number, cos and sin lists of numbers") from None
    n = max(len(c) for c in cos + sin)
    if n == 0:
        raise ConfigError(f"{path}: no harmonics; give cos or sin coefficients", param="gait_file")
    m = len(joints)
    a = np.zeros((n, m))
    b = np.zeros((n, m))
    for j in range(m):
        a[: len(cos[j]), j] = cos[j]
        b[: len(sin[j]), j] = sin[j]
    if not (np.isfinite(a).all() and np.isfinite(b).all() and np.isfinite(a0).all()):
        raise ConfigError(f"{path}: coefficients must be finite numbers", param="gait_file")
    return FourierGait(a0, a, b, path.name, tuple(joints))
