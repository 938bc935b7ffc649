"""Simulator configuration: geometry, medium, hinges, actuators, measurement, effects.

Every number of the simulator lives in one `SimConfig` (nested dataclasses), loadable
from a JSON or TOML file whose sections and keys mirror the dataclass fields, e.g.

    [geometry]
    middle_length_mm = 100.0
    [effects.hinge_damping]
    damping = 5.0

Units are in the field names or comments: lengths mm, angles rad unless `_deg`, time s.
The named effects (section `effects`, declared in `suds_exp.sim.effect_params`) carry
per-parameter metadata (unit, nominal value, realistic range) that
`suds_exp.sim.effects.effect_library()` publishes as data.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from suds_exp.errors import ConfigError
from suds_exp.sim import effect_params
from suds_exp.sim.effect_params import effect_param


@dataclass
class Geometry:
    """Robot geometry (mm). Segments are thin rods along their axes, flippers thin plates.

    Body frame: origin midway between the two motor axes, +X from tail joint to head
    joint. The head segment runs from the head joint (+middle_length/2, 0) outwards over
    `head_length_mm`; the tail from the tail joint (-middle_length/2, 0) backwards over
    `tail_length_mm`. Flipper hinges sit on both sides (+-segment_width/2) of the head
    and tail segments at the given distances from the joint; a closed flipper lies along
    its segment pointing away from the head (backwards), and opens outwards.
    """

    middle_length_mm: float = 100.0
    head_length_mm: float = 110.0
    tail_length_mm: float = 110.0
    segment_width_mm: float = 40.0
    segment_depth_mm: float = 20.0
    flipper_length_mm: float = 60.0
    flipper_depth_mm: float = 25.0
    head_hinge_mm: float = 100.0
    tail_hinge_mm: float = 10.0
    elements_per_segment: int = 8
    elements_per_flipper: int = 4


@dataclass
class Medium:
    """Granular resistive force theory (Maladen et al. 2009) for glass beads.

    F_par = C_F cos(psi) + C_L (1 - sin(psi)), F_perp = C_S sin(beta0) with
    tan(beta0) = gamma sin(psi), each opposing the element's velocity component; per unit
    length and depth, times `stress_scale_n_per_mm2` (N/mm^2 per coefficient unit).
    Sign functions are smoothed with the velocity scale
    eps = smoothing_rel * middle_length_mm * |d(phi)/dt| (so the model stays exactly
    rate independent); `regularization` adds a linear drag of that relative size
    (dimensionless, numerical only: it keeps the hinge balance solvable when a spring
    overpowers the medium).
    """

    c_s: float = 3.21
    c_f: float = 1.34
    c_l: float = -0.82
    gamma: float = 2.79
    stress_scale_n_per_mm2: float = 0.003
    smoothing_rel: float = 1e-2
    regularization: float = 1e-4


@dataclass
class Hinges:
    """Flipper hinges: torsional spring towards closed, hard stops at 0 and `open_stop_deg`.

    Spring torque = -spring_n_mm_per_rad * (angle + preload_rad) (N mm), so a closed
    flipper is pressed against its stop with spring * preload.

    The paper's live hinges are fibre-reinforced tape (Scotch #8959). As a thin beam the
    tape bridging the gap is a spring k = E w t^3 / (12 L_h): tape 0.17 mm thick (3M's
    datasheet of the same glass-yarn filament tape family, #8981), w = 25 mm of hinge
    (the flipper's immersed depth), a free gap L_h of 1-3 mm. With the glass yarn along
    the hinge line the bend goes through the polypropylene backing (E ~ 1.5 GPa):
    5-15 N mm/rad; with the yarn across the gap (E ~ 15 GPa by the rule of mixtures at
    ~20 % glass), 50-150, twice that with tape on both faces. Hence the range 5-300,
    checked by `validate_config`; the nominal 20 is the soft end. The paper does not say
    how the tape was laid.
    """

    spring_n_mm_per_rad: float = field(
        default=20.0,
        metadata=effect_param("N mm/rad", 5.0, 300.0, "torsional stiffness of a tape live hinge"),
    )
    preload_rad: float = field(
        default=0.1, metadata=effect_param("rad", 0.0, 0.5, "spring pre-bend of a closed flipper")
    )
    open_stop_deg: float = 80.0


@dataclass
class Actuator:
    """Motor tracking: smooth random tracking error (sd noise_rad, correlation time
    noise_corr_s; second-order filtered noise) on the command, then a first-order lag."""

    lag_s: float = 0.04
    noise_rad: float = 0.02
    noise_corr_s: float = 0.3


@dataclass
class Measurement:
    """Motion capture: 100 Hz, sub-mm noise, rare jumps (> 9 mm), short dropouts.

    Marker heights (world Z, mm above the bed surface): top-face markers at
    `top_height_mm`, spoke markers raised at `spoke_height_mm`, `tail_back` lowered at
    `back_height_mm`, flipper markers at `flipper_height_mm`.
    """

    sample_rate_hz: float = 100.0
    noise_mm: float = 0.2
    jump_prob: float = 1.5e-4
    jump_mm_min: float = 12.0
    jump_mm_max: float = 30.0
    dropout_per_s: float = 0.02
    dropout_frames_min: int = 2
    dropout_frames_max: int = 12
    top_height_mm: float = 55.0
    spoke_height_mm: float = 140.0
    back_height_mm: float = 15.0
    flipper_height_mm: float = 30.0
    flipper_marker_mm: float = 30.0


@dataclass
class Solver:
    """Per-step quasi-static solve (units: residual in N and N mm scaled, see rft.py)."""

    substeps: int = 1
    tol: float = 1e-8
    max_iter: int = 40
    shape_rate_floor: float = 1e-4


@dataclass
class SimConfig:
    """Everything the simulator needs; `SimConfig()` is the nominal robot."""

    geometry: Geometry = field(default_factory=Geometry)
    medium: Medium = field(default_factory=Medium)
    hinges: Hinges = field(default_factory=Hinges)
    actuator: Actuator = field(default_factory=Actuator)
    measurement: Measurement = field(default_factory=Measurement)
    solver: Solver = field(default_factory=Solver)
    effects: effect_params.Effects = field(default_factory=lambda: effect_params.Effects())

    def copy(self) -> SimConfig:
        return copy.deepcopy(self)

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


def _fill(obj: Any, values: dict, where: str) -> None:
    if not isinstance(values, dict):
        raise ConfigError(f"{where}: expected a table of settings, got {values!r}")
    fields = {f.name: f for f in dataclasses.fields(obj)}
    for key, value in values.items():
        if key not in fields:
            raise ConfigError(
                f"{where}: unknown setting {key!r}; expected one of {', '.join(fields)}"
            )
        current = getattr(obj, key)
        if dataclasses.is_dataclass(current):
            _fill(current, value, f"{where}.{key}")
            continue
        setattr(obj, key, _coerce(value, current, f"{where}.{key}"))


def _coerce(value: Any, current: Any, where: str) -> Any:
    kind = type(current)
    if kind is bool or kind is str:
        if not isinstance(value, kind):
            raise ConfigError(f"{where}: expected {kind.__name__}, got {value!r}")
        return value
    if kind is int:
        if isinstance(value, bool) or not isinstance(value, int | float) or value != int(value):
            raise ConfigError(f"{where}: expected an integer, got {value!r}")
        return int(value)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{where}: expected a number, got {value!r}")
    return float(value)


def config_from_dict(values: dict, base: SimConfig | None = None) -> SimConfig:
    """A `SimConfig` from nested settings (missing keys keep `base`'s or nominal values)."""
    cfg = SimConfig() if base is None else base.copy()
    _fill(cfg, values, "config")
    validate_config(cfg)
    return cfg


def load_config(path: str | Path) -> SimConfig:
    """Read a JSON (.json) or TOML (.toml) simulator configuration file."""
    path = Path(path)
    try:
        text = path.read_bytes()
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read config file ({exc.strerror})") from None
    try:
        if path.suffix.lower() == ".json":
            values = json.loads(text)
        elif path.suffix.lower() == ".toml":
            values = tomllib.loads(text.decode())
        else:
            raise ConfigError(f"{path}: config file must end in .json or .toml")
    except (json.JSONDecodeError, tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: not a valid {path.suffix[1:]} file ({exc})") from None
    try:
        return config_from_dict(values)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None


def validate_config(cfg: SimConfig) -> None:
    """Raise `ConfigError` naming the first setting outside its physical domain."""
    g = cfg.geometry
    for name in (
        "middle_length_mm",
        "head_length_mm",
        "tail_length_mm",
        "segment_depth_mm",
        "flipper_length_mm",
        "flipper_depth_mm",
    ):
        if not getattr(g, name) > 0:
            raise ConfigError(f"config.geometry.{name}: must be > 0")
    if g.elements_per_segment < 1 or g.elements_per_flipper < 1:
        raise ConfigError("config.geometry.elements_per_*: need at least 1 element")
    if not 0 < cfg.hinges.open_stop_deg < 180:
        raise ConfigError("config.hinges.open_stop_deg: must be in (0, 180)")
    _check_fields(cfg.hinges, "config.hinges")
    if cfg.solver.substeps < 1:
        raise ConfigError("config.solver.substeps: must be >= 1")
    if cfg.measurement.sample_rate_hz <= 0:
        raise ConfigError("config.measurement.sample_rate_hz: must be > 0")
    fl = cfg.effects.flippers
    if fl.mode not in ("free", "locked", "absent"):
        raise ConfigError(
            f"config.effects.flippers.mode: {fl.mode!r}; expected free, locked or absent"
        )
    if not 0 <= fl.locked_angle_deg <= cfg.hinges.open_stop_deg:
        raise ConfigError("config.effects.flippers.locked_angle_deg: must be within the stops")
    for name, value in (
        ("hinge_damping.damping", cfg.effects.hinge_damping.damping),
        ("body_inertia.tau_s", cfg.effects.body_inertia.tau_s),
        ("medium_compaction.rate_per_m", cfg.effects.medium_compaction.rate_per_m),
        ("spoke_oscillation.gain", cfg.effects.spoke_oscillation.gain),
    ):
        if value < 0:
            raise ConfigError(f"config.effects.{name}: must be >= 0, got {value}")
    for name, value in (
        ("asymmetric_drag.ratio", cfg.effects.asymmetric_drag.ratio),
        ("drag_anisotropy.normal_scale", cfg.effects.drag_anisotropy.normal_scale),
        ("spoke_oscillation.freq_hz", cfg.effects.spoke_oscillation.freq_hz),
        ("spoke_oscillation.damping_ratio", cfg.effects.spoke_oscillation.damping_ratio),
    ):
        if not value > 0:
            raise ConfigError(f"config.effects.{name}: must be > 0, got {value}")
    # the first effects check their own domains above; the rest, their declared ranges
    for name, cls in effect_params.EFFECTS.items():
        if getattr(cls, "range_checked", True):
            _check_fields(getattr(cfg.effects, name), f"config.effects.{name}")


def _check_fields(obj: Any, where: str) -> None:
    """Raise `ConfigError` for a field of dataclass ``obj`` outside its declared range
    (fields without a range in their metadata are not checked here)."""
    for f in dataclasses.fields(obj):
        if "range" not in f.metadata:
            continue
        low, high = f.metadata["range"]
        value = getattr(obj, f.name)
        if not low <= value <= high:
            raise ConfigError(
                f"{where}.{f.name}: {value} is outside its range {low}..{high} {f.metadata['unit']}"
            )
