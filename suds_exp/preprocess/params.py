"""Preprocessing parameters: defaults, `KEY=VALUE` parsing, validation and the version hash.

A preprocessing version is its parameter set: the full set (defaults filled in) is stored
as canonical JSON and its SHA-256 names the version, so the same parameters always give
the same version and any changed value gives a new one.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from typing import Any

from suds_exp.errors import ConfigError
from suds_exp.robot import MAX_K

#: Every parameter, its default and meaning (units in the name or the text).
DEFAULTS: dict[str, Any] = {
    # cleaning
    "jump_mm": 9.0,  # a frame-to-frame marker step longer than this is a jump, mm
    "max_gap_s": 0.25,  # refuse a trial whose longest gap to fill exceeds this, s
    # body frame
    "joint_fit": "version",  # segment origins fitted over all trials of the version | per trial
    # the distance between the two motor axes when it is known (the robot's drawing), mm;
    # 0 = fit it. A single gait whose shape loop is a circle leaves it poorly determined
    "joint_distance_mm": 0.0,
    # tail frame: rigid = per-frame least-squares fit of tail_top_1, tail_top_2, tail_back
    # (less noise in the body pose and velocity); rigid+flippers = that, plus the tail
    # flipper markers staying on their circles about the hinges | top = its two top markers
    "tail_fit": "rigid+flippers",
    # body pose: chain = one fit of all rigid markers and the tail flipper circles per
    # frame, with the segments' angles relative to the body smoothed (suds_exp.preprocess.
    # chain) | segments = the midpoint and direction of the motor axes of the segment frames
    "body_fit": "chain",
    # smoothing of those relative angles (body_fit=chain): chain_window_cycles gait cycles
    # when the trial's frequency is known, else chain_window_s seconds; local polynomial
    # of order chain_polyorder. 0.3 cycles and order 7 minimised the body-velocity error
    # against the simulator's truth (0.25-0.4 cycles and orders 6-8 are within 0.05 %)
    "chain_window_cycles": 0.3,
    "chain_window_s": 0.6,
    "chain_polyorder": 7,
    # shape
    # r_a as the joint angles (phi1, phi2), rad | cartesian: each outer segment's
    # top-marker centroid in the body frame (head x, y, tail x, y), mm, as in the paper
    "ra_repr": "angles",
    "shape_window_s": 0.21,  # Savitzky-Golay smoothing of r_a and the passive state, s (0 = off)
    "shape_polyorder": 5,  # its polynomial order
    "k": 4,  # number of passive principal components kept as r_p (1..12)
    # how the 12 passive coordinates become the k of r_p: pca | kernel-pca | autoencoder
    # (suds_exp.preprocess.reduction)
    "reduction": "pca",
    # phase (Phaser, Revzen & Guckenheimer 2008)
    "phaser_order": 10,  # order of the Fourier-series corrections
    "phaser_group": "condition",  # trials that share one trained Phaser: condition|gait|trial|all
    "phaser_channels": "ra",  # signals the phase is estimated from: ra | ra+rp
    "phaser_pad_cycles": 2.0,  # periodic padding at each end against Hilbert edge effects, cycles
    # rates (Savitzky-Golay differentiator)
    # window when the trial's frequency is known: sg_window_cycles * T**sg_window_exponent
    # seconds, T the gait period in s (cycles at a 1 s period; 0 = always use seconds);
    # 0.13 and 0.67 minimised the body-velocity error against the simulator's truth
    # (windows of 27, 21, 13 frames at 1/3, 1/2, 1 Hz)
    "sg_window_cycles": 0.13,
    "sg_window_exponent": 0.67,  # 1 = a fixed number of cycles, 0 = fixed seconds
    "sg_window_s": 0.21,  # window in seconds for trials without a frequency (odd frames)
    "sg_polyorder": 3,  # polynomial order
    # weights over the window: triweight (1 - (j/(h+1))^2)^3 | box (plain Savitzky-Golay)
    "sg_kernel": "triweight",
}

JOINT_FITS = ("version", "trial")
TAIL_FITS = ("rigid+flippers", "rigid", "top")
BODY_FITS = ("chain", "segments")
SG_KERNELS = ("triweight", "box")
PHASER_GROUPS = ("condition", "gait", "trial", "all")
PHASER_CHANNELS = ("ra", "ra+rp")
RA_REPRS = ("angles", "cartesian")
REDUCTIONS = ("pca", "kernel-pca", "autoencoder")  # as suds_exp.preprocess.reduction

#: Named parameter sets over `DEFAULTS` (``suds-exp preprocess --preset NAME``).
#: ``paper``: the paper's own processing ("Data Processing"): jumps over 9 mm removed and
#: filled linearly, segment frames from the two top markers only, the body frame from the
#: segment origins (no chain fit), r_a as Cartesian values, no smoothing of the shape.
#: Rates still need a differentiator; the paper names none, so the default one is kept.
PRESETS: dict[str, dict[str, Any]] = {
    "default": {},
    "paper": {
        "ra_repr": "cartesian",
        "tail_fit": "top",
        "body_fit": "segments",
        "shape_window_s": 0.0,
    },
}


def _coerce(key: str, value: Any) -> Any:
    default = DEFAULTS[key]
    if isinstance(default, str):
        if not isinstance(value, str):
            raise ConfigError(f"params {key}: expected text, got {value!r}", param="params")
        return value
    if isinstance(value, bool):
        raise ConfigError(f"params {key}: expected a number, got {value!r}", param="params")
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            raise ConfigError(f"params {key}={value}: expected a number", param="params") from None
    if not isinstance(value, int | float):
        raise ConfigError(f"params {key}: expected a number, got {value!r}", param="params")
    if isinstance(default, int):
        if value != int(value):
            raise ConfigError(f"params {key}={value}: expected a whole number", param="params")
        return int(value)
    return float(value)


def _check(params: dict[str, Any]) -> None:
    positive = ("jump_mm", "max_gap_s", "sg_window_s", "chain_window_s", "phaser_order")
    for key in positive:
        if not params[key] > 0:
            raise ConfigError(f"params {key}={params[key]}: must be > 0", param="params")
    for key in (
        "phaser_pad_cycles",
        "shape_window_s",
        "sg_window_cycles",
        "chain_window_cycles",
        "joint_distance_mm",
    ):
        if params[key] < 0:
            raise ConfigError(f"params {key}={params[key]}: must be >= 0", param="params")
    if not 0 <= params["sg_window_exponent"] <= 2:
        raise ConfigError(
            f"params sg_window_exponent={params['sg_window_exponent']}: must be 0..2",
            param="params",
        )
    if not 1 <= params["k"] <= MAX_K:
        raise ConfigError(f"params k={params['k']}: must be between 1 and {MAX_K}", param="params")
    for key, top in (("sg_polyorder", 6), ("shape_polyorder", 6), ("chain_polyorder", 9)):
        if not 1 <= params[key] <= top:
            raise ConfigError(f"params {key}={params[key]}: must be 1..{top}", param="params")
    for key, choices in (
        ("joint_fit", JOINT_FITS),
        ("tail_fit", TAIL_FITS),
        ("body_fit", BODY_FITS),
        ("sg_kernel", SG_KERNELS),
        ("phaser_group", PHASER_GROUPS),
        ("phaser_channels", PHASER_CHANNELS),
        ("ra_repr", RA_REPRS),
        ("reduction", REDUCTIONS),
    ):
        if params[key] not in choices:
            raise ConfigError(
                f"params {key}={params[key]}: expected one of {', '.join(choices)}", param="params"
            )


def preset_params(preset: str) -> dict[str, Any]:
    """The parameters a named preset sets over `DEFAULTS` (see `PRESETS`).

    Raises `ConfigError` for an unknown preset name.
    """
    if preset not in PRESETS:
        choices = ", ".join(PRESETS)
        raise ConfigError(
            f"preset {preset}: unknown preset; expected one of {choices}", param="preset"
        )
    return dict(PRESETS[preset])


def resolve_params(
    given: Mapping[str, Any] | None = None, preset: str | None = None
) -> dict[str, Any]:
    """The full parameter set: ``given`` over the ``preset`` (if any) over `DEFAULTS`,
    typed and validated.

    Raises `ConfigError` for an unknown key or preset, or a value of the wrong type or range.
    """
    params = dict(DEFAULTS)
    merged = {**(preset_params(preset) if preset is not None else {}), **(given or {})}
    for key, value in merged.items():
        if key not in DEFAULTS:
            raise ConfigError(
                f"params {key}: unknown parameter; expected one of {', '.join(DEFAULTS)}",
                param="params",
            )
        params[key] = _coerce(key, value)
    _check(params)
    return params


def params_json(params: Mapping[str, Any]) -> str:
    """Canonical JSON of a resolved parameter set (sorted keys, no spaces)."""
    return json.dumps(dict(params), sort_keys=True, separators=(",", ":"))


def params_hash(params: Mapping[str, Any]) -> str:
    """SHA-256 (hex) of the canonical JSON: the identity of a preprocessing version."""
    return hashlib.sha256(params_json(params).encode()).hexdigest()


def params_seed(params: Mapping[str, Any]) -> int:
    """A seed (0 <= seed < 2**32) derived from a version's parameters, for what its fits
    draw at random: the same version always draws the same."""
    return int(params_hash(params)[:8], 16)


def actuated_dimension(params: Mapping[str, Any]) -> int:
    """m, the number of r_a columns of a version with these parameters (a segment body's
    description, under ``body``, has one per actuated joint)."""
    body = params.get("body")
    if isinstance(body, dict) and body.get("joints"):
        return sum(j["kind"] == "actuated" for j in body["joints"])
    return 4 if params.get("ra_repr", "angles") == "cartesian" else 2
