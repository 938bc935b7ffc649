"""The simulator's named effects, each declared once: a dataclass of its parameters
(unit, nominal value, realistic range and meaning in field metadata, one marked main),
registered with `@effect(NAME)`, and, for an effect the compiled solver reads, its
slots in the solver's packed parameter vector: a parameter declared with ``slot=`` (its
value in the solver's units), or a ``kernel(units)`` method that computes them.

`Effects` (the ``effects`` section of a `SimConfig`), `effect_library()`, the discrepancy
candidates and the packed layout (`sim.kernel_params.kernel_layout`, the solver's ``P_*``
indices) all follow the registry `EFFECTS`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

from suds_exp.errors import ConfigError


def effect_param(
    unit: str,
    low: Any,
    high: Any,
    doc: str,
    main: bool = False,
    on: Any = None,
    off: Any = None,
    slot: str | None = None,
    scale: str | None = None,
) -> dict:
    """Field metadata of an effect parameter: unit, realistic range, meaning; for the
    main parameter also its typical "on" value and its "off" value (no effect); for a
    parameter the solver reads as it is, its ``slot`` and the `SLOT_SCALES` entry that
    puts it in the solver's units."""
    if scale not in SLOT_SCALES:
        raise ConfigError(
            f"slot scale {scale!r}: expected one of {', '.join(map(str, SLOT_SCALES))}"
        )
    return {
        "unit": unit,
        "range": (low, high),
        "doc": doc,
        "main": main,
        "on": on,
        "off": off,
        "slot": slot,
        "scale": scale,
    }


def param(
    default: Any,
    unit: str,
    low: Any,
    high: Any,
    doc: str,
    slot: str | None = None,
    scale: str | None = None,
) -> Any:
    """A dataclass field of an effect's parameter: its nominal value, unit, realistic
    range and meaning; ``slot``/``scale`` as `effect_param`'s."""
    return field(
        default=default, metadata=effect_param(unit, low, high, doc, slot=slot, scale=scale)
    )


def main_param(
    default: Any,
    unit: str,
    low: Any,
    high: Any,
    doc: str,
    on: Any,
    off: Any = None,
    slot: str | None = None,
    scale: str | None = None,
) -> Any:
    """The field of an effect's main parameter (the one ``NAME=VALUE`` sets), with its
    typical "on" value and its "off" value (no effect; by default the nominal value);
    ``slot``/``scale`` as `effect_param`'s."""
    off = default if off is None else off
    return field(
        default=default,
        metadata=effect_param(
            unit, low, high, doc, main=True, on=on, off=off, slot=slot, scale=scale
        ),
    )


@dataclass(frozen=True)
class KernelUnits:
    """The scales of the compiled solver's parameters: lengths in units of `l_ref_mm`
    (the middle segment's length), torques in `torque_unit_n_mm` (N mm), forces in
    `force_unit_n` (N)."""

    l_ref_mm: float
    force_unit_n: float
    torque_unit_n_mm: float


#: How a parameter declared with ``slot=`` reaches the solver: ``scale`` -> (value, units)
#: -> the slot's value. None: as it is; "torque": N mm (or N mm s/rad) in the solver's
#: torque unit; "per_length": a rate per metre in one per `l_ref_mm`.
SLOT_SCALES = {
    None: lambda value, units: value,
    "torque": lambda value, units: value / units.torque_unit_n_mm,
    "per_length": lambda value, units: value * units.l_ref_mm / 1000.0,
}


def effect_slots(eff, units: KernelUnits) -> dict:
    """The solver's slots of effect ``eff`` (an instance), ``SLOT`` -> value(s) in the
    solver's units: its ``kernel(units)``, else its parameters declared with ``slot=``."""
    if hasattr(eff, "kernel"):
        return eff.kernel(units)
    return {
        f.metadata["slot"]: SLOT_SCALES[f.metadata["scale"]](getattr(eff, f.name), units)
        for f in dataclasses.fields(eff)
        if f.metadata.get("slot")
    }


#: Every named effect, in the order of `Effects`' fields: name -> its dataclass.
EFFECTS: dict[str, type] = {}


def effect(name: str):
    """Class decorator registering an effect (a dataclass of its parameters) as `name`.

    The effect becomes a field of `Effects` (section ``effects.NAME`` of a config file),
    an entry of `effect_library()` and a discrepancy candidate. Class attributes:
    ``replay`` ("exact", "mean" for an effect drawn anew per trial, "none" for one acting
    between the command and the joints), ``range_checked`` (whether `validate_config`
    holds each parameter to its declared range). An effect the compiled solver reads
    gives its slots, named ``NAME.SLOT``, either by declaring parameters with ``slot=``
    (and ``scale=``, see `SLOT_SCALES`) or, for slots computed from several parameters,
    with a method ``kernel(units) -> {slot: value or tuple of values}``; they take their
    place in the packed parameter vector (`kernel_layout`) from the nominal parameters.
    """

    def register(cls: type) -> type:
        if name in EFFECTS:
            raise ConfigError(f"effect {name!r} is already registered")
        declared = any(f.metadata.get("slot") for f in dataclasses.fields(cls))
        if declared and hasattr(cls, "kernel"):
            raise ConfigError(
                f"effect {name!r}: declare its slots with slot= or kernel(), not both"
            )
        EFFECTS[name] = cls
        _build_effects()
        return cls

    return register


def unregister_effect(name: str) -> None:
    """Forget the effect `name` (for an effect registered by a test or a session)."""
    del EFFECTS[name]
    _build_effects()


Effects: type


def _build_effects() -> None:
    """(Re)make `Effects`, the dataclass of every registered effect (defaults nominal)."""
    global Effects
    Effects = dataclasses.make_dataclass(
        "Effects",
        [(n, cls, field(default_factory=cls)) for n, cls in EFFECTS.items()],
    )
    Effects.__module__ = __name__
    Effects.__doc__ = "The named candidate effects (`EFFECTS`); defaults are the nominal ones."


@effect("flippers")
@dataclass
class FlippersEffect:
    """Passive flippers: free on their spring hinges, locked at a fixed opening, or
    removed. Locking removes the passive shape and the flippers' ratchet-like thrust."""

    mode: str = main_param("free", "-", "free", "absent", "free | locked | absent", on="locked")
    locked_angle_deg: float = param(0.0, "deg", 0.0, 80.0, "opening of locked flippers")

    range_checked: ClassVar[bool] = False
    #: kernel codes of the modes (`sim.rft.FL_FREE`, ...)
    MODES: ClassVar[dict[str, int]] = {"free": 0, "locked": 1, "absent": 2}

    def kernel(self, units: KernelUnits) -> dict:
        try:
            mode = self.MODES[self.mode]
        except KeyError:
            raise ConfigError(
                f"effects.flippers.mode: {self.mode!r}; expected {', '.join(self.MODES)}"
            ) from None
        return {"mode": mode, "locked": math.radians(self.locked_angle_deg)}


@effect("hinge_damping")
@dataclass
class HingeDampingEffect:
    """Viscous friction in the tape hinges: flippers lag behind, more at high frequency."""

    damping: float = main_param(
        0.0, "N mm s/rad", 0.0, 200.0, "viscous torque per hinge rate", on=50.0,
        slot="c", scale="torque",
    )  # fmt: skip

    range_checked: ClassVar[bool] = False


@effect("body_inertia")
@dataclass
class BodyInertiaEffect:
    """Momentum: the body twist relaxes towards the quasi-static one with time constant
    tau, so motion lags the shape and shrinks at high frequency (speed dependence)."""

    tau_s: float = main_param(
        0.0, "s", 0.0, 0.5, "body velocity relaxes to the quasi-static one", on=0.15, slot="tau"
    )

    range_checked: ClassVar[bool] = False


@effect("asymmetric_drag")
@dataclass
class AsymmetricDragEffect:
    """Tangential drag on the segments differs sliding forward (towards the head) vs
    backward (grain texture, surface finish): slows or speeds the forward glide."""

    ratio: float = main_param(
        1.0, "-", 0.5, 2.5, "tangential drag on the segments sliding forward / backward", on=1.8,
        slot="ratio",
    )  # fmt: skip

    range_checked: ClassVar[bool] = False


@effect("drag_anisotropy")
@dataclass
class DragAnisotropyEffect:
    """Normal vs tangential drag ratio differs from glass beads (beans are not beads):
    scales all propulsion and the lateral slip."""

    normal_scale: float = main_param(
        1.0, "-", 0.5, 2.0, "multiplies the normal drag C_S", on=1.5, slot="normal"
    )

    range_checked: ClassVar[bool] = False


@effect("medium_compaction")
@dataclass
class MediumCompactionEffect:
    """The bed compacts as the robot ploughs through it: normal drag grows with distance
    travelled, so speed drifts along a trial."""

    rate_per_m: float = main_param(
        0.0, "1/m", 0.0, 3.0, "normal drag grows by this fraction per metre travelled", on=1.5,
        slot="rate", scale="per_length",
    )  # fmt: skip

    range_checked: ClassVar[bool] = False


@effect("spoke_oscillation")
@dataclass
class SpokeOscillationEffect:
    """Raised spoke markers ring on their skewers (damped oscillation driven by the
    spoke base's acceleration); affects the measured markers, not the body."""

    gain: float = main_param(
        1.0,
        "-",
        0.0,
        3.0,
        "spoke marker response to base acceleration (1 = rigid mass on spring)",
        on=1.0,
        off=0.0,
    )
    freq_hz: float = param(5.0, "Hz", 2.0, 10.0, "natural frequency of the spoke")
    damping_ratio: float = param(0.15, "-", 0.02, 0.4, "damping ratio of the spoke")

    range_checked: ClassVar[bool] = False


@effect("servo")
@dataclass
class ServoEffect:
    """Compliant position servos (hobby / Dynamixel class): the joint is driven by a
    proportional controller saturating at the stall torque, minus back-EMF damping
    (torque = clip(error / compliance, +-stall) - stall / no_load_speed * rate), against
    the medium's torque on the segment and its flippers. Under load r_a lags and falls
    short of the command, more in stiffer ground and at higher speed, so r_a carries
    the force the beans exert. Only the commanded drive feels it: replaying measured
    joint angles already contains it."""

    compliance_rad_per_n_m: float = main_param(
        0.0,
        "rad/(N m)",
        0.0,
        0.5,
        "joint deflection per unit load torque below stall (1 / proportional gain); "
        "Dynamixel AX-12A: compliance slope 2-128 steps of 0.29 deg to its 1.5 N m "
        "stall = 0.007-0.43, default 32 steps = 0.11 (ROBOTIS e-manual)",
        on=0.1,
    )
    stall_torque_n_m: float = param(
        4.0,
        "N m",
        0.5,
        6.0,
        "torque at zero speed (ROBOTIS e-manual: AX-12A 1.5, MX-28 2.5, "
        "MX-64 6.0 N m; hobby MG996R ~1 N m)",
    )
    no_load_speed_rad_s: float = param(
        6.2,
        "rad/s",
        4.0,
        12.0,
        "joint speed at zero torque (AX-12A 59 rpm = 6.2 rad/s, MG996R 0.17 s/60 deg = 6.2 rad/s)",
    )

    replay: ClassVar[str] = "none"

    def kernel(self, units: KernelUnits) -> dict:
        """Proportional gain (scaled torque per rad, 0 = joints follow the given angles),
        stall torque (scaled) and back-EMF damping (scaled torque s/rad)."""
        if not self.compliance_rad_per_n_m > 0:
            return {"gain": 0.0, "stall": 0.0, "damp": 0.0}
        stall = self.stall_torque_n_m * 1000.0 / units.torque_unit_n_mm
        return {
            "gain": 1000.0 / self.compliance_rad_per_n_m / units.torque_unit_n_mm,
            "stall": stall,
            "damp": stall / self.no_load_speed_rad_s,
        }


@effect("bed_heterogeneity")
@dataclass
class BedHeterogeneityEffect:
    """The bed of beans is remixed and levelled by hand between trials, so resistance
    (packing fraction, immersion depth) varies across the tub: a log-normal random field
    of mean 1 with Gaussian correlation over `correlation_mm`, multiplying every
    element's drag where it is. Drawn anew for every trial from the trial's seed (a
    replay of measured joint angles, which cannot know the field, sees the mean bed)."""

    spatial_cv: float = main_param(
        0.0, "-", 0.0, 0.5, "coefficient of variation of the resistance over the tub", on=0.2
    )
    correlation_mm: float = param(
        300.0, "mm", 100.0, 1000.0, "correlation length of the field (robot: 320 mm)"
    )

    replay: ClassVar[str] = "mean"


@effect("bed_packing")
@dataclass
class BedPackingEffect:
    """Each remix leaves the whole bed a little looser or denser and the robot a little
    deeper or shallower: one log-normal resistance factor of mean 1 per trial (drawn from
    the trial's seed) on every element. Kinematics of a rigid robot are blind to a uniform
    factor (rate- and scale-independent RFT); compliant servos and flipper hinges are not."""

    trial_cv: float = main_param(
        0.0,
        "-",
        0.0,
        0.4,
        "coefficient of variation of the bed's resistance from trial to trial",
        on=0.2,
    )

    replay: ClassVar[str] = "mean"


@effect("hinge_friction")
@dataclass
class HingeFrictionEffect:
    """Dry (Coulomb) friction in the flippers' tape hinges, different for every flipper:
    flipper i gets torque x (1 + spread x (+1, -1/3, +1/3, -1)[i]); a flipper resting on a
    stop leaves it only once the net torque beats its friction (stiction)."""

    torque_n_mm: float = main_param(
        0.0, "N mm", 0.0, 60.0, "mean friction torque of a hinge", on=15.0
    )
    spread: float = param(0.5, "-", 0.0, 1.0, "relative flipper-to-flipper variation")

    #: relative deviation of flipper_1..flipper_4's friction from the mean, x spread
    PATTERN: ClassVar[tuple[float, ...]] = (1.0, -1 / 3, 1 / 3, -1.0)

    def kernel(self, units: KernelUnits) -> dict:
        return {
            "torque": tuple(
                self.torque_n_mm * (1.0 + self.spread * p) / units.torque_unit_n_mm
                for p in self.PATTERN
            )
        }


@effect("grain_contacts")
@dataclass
class GrainContactsEffect:
    """Grain-scale fluctuations of the granular drag: the force chains in front of each
    part of the robot jam and collapse as it slips through the beans (stick-slip), so
    the drag on every RFT element is its mean times a log-normal factor of mean 1 that
    changes over a slip distance of the order of a grain diameter (an Ornstein-Uhlenbeck
    process in the element's own slip distance: rate independent), partly shared by the
    elements of one segment or flipper. Drawn from the trial's seed."""

    cv: float = main_param(
        0.0,
        "-",
        0.0,
        1.0,
        "coefficient of variation of an element's drag (Albert et al. 2001 PRE "
        "64 031307: stick-slip drag fluctuations of the order of the mean force; "
        "Hossain & Rognon 2020: drops of up to 60 %)",
        on=0.4,
    )
    correlation_mm: float = param(
        15.0,
        "mm",
        5.0,
        40.0,
        "slip distance over which the contacts renew: 0.5-4 grain diameters (red beans 8-15 mm)",
    )
    coherence: float = param(0.5, "-", 0.0, 1.0, "share of the log-variance common to a whole part")

    replay: ClassVar[str] = "mean"

    def kernel(self, units: KernelUnits) -> dict:
        """Log-sd of each element's drag multiplier and the share of its log-variance
        common to its whole part (the slip correlation length is in the modes)."""
        if not self.cv > 0:
            return {"sigma": 0.0, "coherence": 0.0}
        return {"sigma": math.sqrt(math.log1p(self.cv**2)), "coherence": self.coherence}


@effect("bed_depth")
@dataclass
class BedDepthEffect:
    """The robot rests on the bed at a depth set by the beans' bearing under its whole
    footprint, and a hand-levelled bed is denser in some places than others, so the
    immersion depth changes as the robot travels. RFT stress grows with depth, so every
    element's drag changes by one common factor (log-normal, mean 1) taken from a random
    field over the tub at the body's position. A uniform factor leaves a rigid robot's
    kinematics unchanged (RFT is scale free); it loads the servos and the flipper hinges.
    Drawn anew for every trial from its seed."""

    cv: float = main_param(
        0.0,
        "-",
        0.0,
        0.5,
        "coefficient of variation of the drag from the immersion depth along the tub "
        "(drag grows about as depth^2 for plates reaching from the surface, Maladen et "
        "al. 2009; +-2-4 mm of a 20 mm immersion gives 0.2-0.4)",
        on=0.25,
    )
    correlation_mm: float = param(
        200.0, "mm", 50.0, 1000.0, "correlation length of the depth field over the tub"
    )

    replay: ClassVar[str] = "mean"
