"""Simulator configuration: geometry, medium, hinges, actuators, measurement, effects.

Every number of the simulator lives in one `SimConfig` (nested dataclasses), loadable
from a JSON or TOML file whose sections and keys mirror the dataclass fields, e.g.

    [geometry]
    middle_length_mm = 100.0
    [effects.hinge_damping]
    damping = 5.0

Units are in the field names or comments: lengths mm, angles rad unless `_deg`, time s.
The named effects (section `effects`) carry per-parameter metadata (unit, nominal value,
realistic range) that `suds_exp.sim.effects.effect_library()` publishes as data.
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


def _p(
    unit: str, low: Any, high: Any, doc: str, main: bool = False, on: Any = None, off: Any = None
) -> dict:
    """Field metadata of an effect parameter: unit, realistic range, meaning; for the
    main parameter also its typical "on" value and its "off" value (no effect)."""
    return {"unit": unit, "range": (low, high), "doc": doc, "main": main, "on": on, "off": off}


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
        metadata=_p("N mm/rad", 5.0, 300.0, "torsional stiffness of a tape live hinge"),
    )
    preload_rad: float = field(
        default=0.1, metadata=_p("rad", 0.0, 0.5, "spring pre-bend of a closed flipper")
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
class FlippersEffect:
    """Passive flippers: free on their spring hinges, locked at a fixed opening, or
    removed. Locking removes the passive shape and the flippers' ratchet-like thrust."""

    mode: str = field(
        default="free",
        metadata=_p(
            "-", "free", "absent", "free | locked | absent", main=True, on="locked", off="free"
        ),
    )
    locked_angle_deg: float = field(
        default=0.0, metadata=_p("deg", 0.0, 80.0, "opening of locked flippers")
    )


@dataclass
class HingeDampingEffect:
    """Viscous friction in the tape hinges: flippers lag behind, more at high frequency."""

    damping: float = field(
        default=0.0,
        metadata=_p(
            "N mm s/rad", 0.0, 200.0, "viscous torque per hinge rate", main=True, on=50.0, off=0.0
        ),
    )


@dataclass
class BodyInertiaEffect:
    """Momentum: the body twist relaxes towards the quasi-static one with time constant
    tau, so motion lags the shape and shrinks at high frequency (speed dependence)."""

    tau_s: float = field(
        default=0.0,
        metadata=_p(
            "s",
            0.0,
            0.5,
            "body velocity relaxes to the quasi-static one",
            main=True,
            on=0.15,
            off=0.0,
        ),
    )


@dataclass
class AsymmetricDragEffect:
    """Tangential drag on the segments differs sliding forward (towards the head) vs
    backward (grain texture, surface finish): slows or speeds the forward glide."""

    ratio: float = field(
        default=1.0,
        metadata=_p(
            "-",
            0.5,
            2.5,
            "tangential drag on the segments sliding forward / backward",
            main=True,
            on=1.8,
            off=1.0,
        ),
    )


@dataclass
class DragAnisotropyEffect:
    """Normal vs tangential drag ratio differs from glass beads (beans are not beads):
    scales all propulsion and the lateral slip."""

    normal_scale: float = field(
        default=1.0,
        metadata=_p("-", 0.5, 2.0, "multiplies the normal drag C_S", main=True, on=1.5, off=1.0),
    )


@dataclass
class MediumCompactionEffect:
    """The bed compacts as the robot ploughs through it: normal drag grows with distance
    travelled, so speed drifts along a trial."""

    rate_per_m: float = field(
        default=0.0,
        metadata=_p(
            "1/m",
            0.0,
            3.0,
            "normal drag grows by this fraction per metre travelled",
            main=True,
            on=1.5,
            off=0.0,
        ),
    )


@dataclass
class SpokeOscillationEffect:
    """Raised spoke markers ring on their skewers (damped oscillation driven by the
    spoke base's acceleration); affects the measured markers, not the body."""

    gain: float = field(
        default=1.0,
        metadata=_p(
            "-",
            0.0,
            3.0,
            "spoke marker response to base acceleration (1 = rigid mass on spring)",
            main=True,
            on=1.0,
            off=0.0,
        ),
    )
    freq_hz: float = field(
        default=5.0, metadata=_p("Hz", 2.0, 10.0, "natural frequency of the spoke")
    )
    damping_ratio: float = field(
        default=0.15, metadata=_p("-", 0.02, 0.4, "damping ratio of the spoke")
    )


@dataclass
class ServoEffect:
    """Compliant position servos (hobby / Dynamixel class): the joint is driven by a
    proportional controller saturating at the stall torque, minus back-EMF damping
    (torque = clip(error / compliance, +-stall) - stall / no_load_speed * rate), against
    the medium's torque on the segment and its flippers. Under load r_a lags and falls
    short of the command, more in stiffer ground and at higher speed, so r_a carries
    the force the beans exert. Only the commanded drive feels it: replaying measured
    joint angles already contains it."""

    compliance_rad_per_n_m: float = field(
        default=0.0,
        metadata=_p(
            "rad/(N m)",
            0.0,
            0.5,
            "joint deflection per unit load torque below stall (1 / proportional gain); "
            "Dynamixel AX-12A: compliance slope 2-128 steps of 0.29 deg to its 1.5 N m "
            "stall = 0.007-0.43, default 32 steps = 0.11 (ROBOTIS e-manual)",
            main=True,
            on=0.1,
            off=0.0,
        ),
    )
    stall_torque_n_m: float = field(
        default=4.0,
        metadata=_p(
            "N m",
            0.5,
            6.0,
            "torque at zero speed (ROBOTIS e-manual: AX-12A 1.5, MX-28 2.5, "
            "MX-64 6.0 N m; hobby MG996R ~1 N m)",
        ),
    )
    no_load_speed_rad_s: float = field(
        default=6.2,
        metadata=_p(
            "rad/s",
            4.0,
            12.0,
            "joint speed at zero torque (AX-12A 59 rpm = 6.2 rad/s, "
            "MG996R 0.17 s/60 deg = 6.2 rad/s)",
        ),
    )


@dataclass
class BedHeterogeneityEffect:
    """The bed of beans is remixed and levelled by hand between trials, so resistance
    (packing fraction, immersion depth) varies across the tub: a log-normal random field
    of mean 1 with Gaussian correlation over `correlation_mm`, multiplying every
    element's drag where it is. Drawn anew for every trial from the trial's seed (a
    replay of measured joint angles, which cannot know the field, sees the mean bed)."""

    spatial_cv: float = field(
        default=0.0,
        metadata=_p(
            "-",
            0.0,
            0.5,
            "coefficient of variation of the resistance over the tub",
            main=True,
            on=0.2,
            off=0.0,
        ),
    )
    correlation_mm: float = field(
        default=300.0,
        metadata=_p("mm", 100.0, 1000.0, "correlation length of the field (robot: 320 mm)"),
    )


@dataclass
class BedPackingEffect:
    """Each remix leaves the whole bed a little looser or denser and the robot a little
    deeper or shallower: one log-normal resistance factor of mean 1 per trial (drawn from
    the trial's seed) on every element. Kinematics of a rigid robot are blind to a uniform
    factor (rate- and scale-independent RFT); compliant servos and flipper hinges are not."""

    trial_cv: float = field(
        default=0.0,
        metadata=_p(
            "-",
            0.0,
            0.4,
            "coefficient of variation of the bed's resistance from trial to trial",
            main=True,
            on=0.2,
            off=0.0,
        ),
    )


@dataclass
class HingeFrictionEffect:
    """Dry (Coulomb) friction in the flippers' tape hinges, different for every flipper:
    flipper i gets torque x (1 + spread x (+1, -1/3, +1/3, -1)[i]); a flipper resting on a
    stop leaves it only once the net torque beats its friction (stiction)."""

    torque_n_mm: float = field(
        default=0.0,
        metadata=_p(
            "N mm", 0.0, 60.0, "mean friction torque of a hinge", main=True, on=15.0, off=0.0
        ),
    )
    spread: float = field(
        default=0.5, metadata=_p("-", 0.0, 1.0, "relative flipper-to-flipper variation")
    )


@dataclass
class BedDepthEffect:
    """The robot rests on the bed at a depth set by the beans' bearing under its whole
    footprint, and a hand-levelled bed is denser in some places than others, so the
    immersion depth changes as the robot travels. RFT stress grows with depth, so every
    element's drag changes by one common factor (log-normal, mean 1) taken from a random
    field over the tub at the body's position. A uniform factor leaves a rigid robot's
    kinematics unchanged (RFT is scale free); it loads the servos and the flipper hinges.
    Drawn anew for every trial from its seed."""

    cv: float = field(
        default=0.0,
        metadata=_p(
            "-",
            0.0,
            0.5,
            "coefficient of variation of the drag from the immersion depth along the tub "
            "(drag grows about as depth^2 for plates reaching from the surface, Maladen et "
            "al. 2009; +-2-4 mm of a 20 mm immersion gives 0.2-0.4)",
            main=True,
            on=0.25,
            off=0.0,
        ),
    )
    correlation_mm: float = field(
        default=200.0,
        metadata=_p("mm", 50.0, 1000.0, "correlation length of the depth field over the tub"),
    )


@dataclass
class GrainContactsEffect:
    """Grain-scale fluctuations of the granular drag: the force chains in front of each
    part of the robot jam and collapse as it slips through the beans (stick-slip), so
    the drag on every RFT element is its mean times a log-normal factor of mean 1 that
    changes over a slip distance of the order of a grain diameter (an Ornstein-Uhlenbeck
    process in the element's own slip distance: rate independent), partly shared by the
    elements of one segment or flipper. Drawn from the trial's seed."""

    cv: float = field(
        default=0.0,
        metadata=_p(
            "-",
            0.0,
            1.0,
            "coefficient of variation of an element's drag (Albert et al. 2001 PRE "
            "64 031307: stick-slip drag fluctuations of the order of the mean force; "
            "Hossain & Rognon 2020: drops of up to 60 %)",
            main=True,
            on=0.4,
            off=0.0,
        ),
    )
    correlation_mm: float = field(
        default=15.0,
        metadata=_p(
            "mm",
            5.0,
            40.0,
            "slip distance over which the contacts renew: 0.5-4 grain diameters "
            "(red beans 8-15 mm)",
        ),
    )
    coherence: float = field(
        default=0.5,
        metadata=_p("-", 0.0, 1.0, "share of the log-variance common to a whole part"),
    )


@dataclass
class Effects:
    """The named candidate effects; defaults are the nominal configuration."""

    flippers: FlippersEffect = field(default_factory=FlippersEffect)
    hinge_damping: HingeDampingEffect = field(default_factory=HingeDampingEffect)
    body_inertia: BodyInertiaEffect = field(default_factory=BodyInertiaEffect)
    asymmetric_drag: AsymmetricDragEffect = field(default_factory=AsymmetricDragEffect)
    drag_anisotropy: DragAnisotropyEffect = field(default_factory=DragAnisotropyEffect)
    medium_compaction: MediumCompactionEffect = field(default_factory=MediumCompactionEffect)
    spoke_oscillation: SpokeOscillationEffect = field(default_factory=SpokeOscillationEffect)
    servo: ServoEffect = field(default_factory=ServoEffect)
    bed_heterogeneity: BedHeterogeneityEffect = field(default_factory=BedHeterogeneityEffect)
    bed_packing: BedPackingEffect = field(default_factory=BedPackingEffect)
    hinge_friction: HingeFrictionEffect = field(default_factory=HingeFrictionEffect)
    grain_contacts: GrainContactsEffect = field(default_factory=GrainContactsEffect)
    bed_depth: BedDepthEffect = field(default_factory=BedDepthEffect)


#: Effects drawn anew for every trial from its seed: a replay of measured joint angles
#: cannot reproduce them sample by sample and simulates their mean (a uniform bed).
PER_TRIAL_RANDOM_EFFECTS = (
    "bed_heterogeneity",
    "bed_packing",
    "grain_contacts",
    "bed_depth",
)
#: Effects acting between the command and the joint angles: invisible when measured
#: joint angles are replayed.
COMMAND_ONLY_EFFECTS = ("servo",)


@dataclass
class SimConfig:
    """Everything the simulator needs; `SimConfig()` is the nominal robot."""

    geometry: Geometry = field(default_factory=Geometry)
    medium: Medium = field(default_factory=Medium)
    hinges: Hinges = field(default_factory=Hinges)
    actuator: Actuator = field(default_factory=Actuator)
    measurement: Measurement = field(default_factory=Measurement)
    solver: Solver = field(default_factory=Solver)
    effects: Effects = field(default_factory=Effects)

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
    _check_ranges(
        cfg,
        (
            "servo",
            "bed_heterogeneity",
            "bed_packing",
            "hinge_friction",
            "grain_contacts",
            "bed_depth",
        ),
    )


def _check_ranges(cfg: SimConfig, effects: tuple[str, ...]) -> None:
    """Raise `ConfigError` for a parameter of ``effects`` outside its declared range."""
    for name in effects:
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
