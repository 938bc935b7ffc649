"""Synthetic captures of a rigid 3-segment robot with known truth (tests, benchmarks).

Kinematics only (no physics): the gait drives phi1, phi2 exactly as commanded, the body
follows a prescribed smooth body velocity, and the flippers open and close with the
phase. Markers sit on rigid segments at fixed places (different from the simulator's, so
nothing downstream can rely on one particular placement), the motion plane is tilted
and offset in the capture volume, and the tracks get noise, jumps and dropouts. The truth
frame has the simulator truth file's columns. `qtm_text` and `random_track` make a
QTM TSV export of plain random tracks (for the readers' tests and the ingest benchmark).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.integrate import cumulative_trapezoid
from scipy.spatial.transform import Rotation

from suds_exp.robot import FREQUENCIES_HZ, GAITS, ROLES, gait_shape

MIDDLE_MM = 100.0
#: Marker positions in their segment frame (origin at the segment's joint, X along the
#: segment pointing tail-to-head, Y left, Z up from the bed), mm.
RIGID = {
    "head_top_1": ("head", (35.0, 10.0, 55.0)),
    "head_top_2": ("head", (75.0, -10.0, 55.0)),
    "head_spoke": ("head", (55.0, 8.0, 140.0)),
    "tail_top_1": ("tail", (-35.0, 10.0, 55.0)),
    "tail_top_2": ("tail", (-75.0, -10.0, 55.0)),
    "tail_spoke": ("tail", (-55.0, -8.0, 140.0)),
    "tail_back": ("tail", (-110.0, 0.0, 15.0)),
}
#: Flipper hinges (segment, hinge x, side) and marker distance from the hinge, mm.
FLIPPERS = {
    "flipper_1": ("head", 80.0, 1.0),
    "flipper_2": ("head", 80.0, -1.0),
    "flipper_3": ("tail", -30.0, 1.0),
    "flipper_4": ("tail", -30.0, -1.0),
}
HALF_WIDTH_MM = 20.0
FLIPPER_MARKER_MM = 30.0
FLIPPER_HEIGHT_MM = 30.0


@dataclass
class SyntheticTrial:
    """One synthetic capture: ``xyz`` (n_frames, 11, 3) mm in `ROLES` order (NaN = not
    seen), ``truth`` DataFrame (simulator truth-file columns), masks (n_frames, 11) of
    points displaced by injected jumps and of dropped points."""

    gait: str
    frequency_hz: float
    rate_hz: float
    xyz: np.ndarray
    truth: pd.DataFrame
    jumped: np.ndarray
    dropped: np.ndarray


def _body_motion(rng, gait: str, frequency_hz: float, n_cycles: float, rate_hz: float):
    """Commanded shape, flippers and the body's prescribed motion (s, rad, mm, mm/s)."""
    n = int(round(n_cycles * rate_hz / frequency_hz))
    t = np.arange(n) / rate_hz
    phase0 = rng.uniform(0, 2 * np.pi)
    omega = 2 * np.pi * frequency_hz
    theta = omega * t + phase0
    phi = gait_shape(gait, theta)
    flips = np.column_stack([0.6 * (1 + np.sin(theta + 0.8 * i)) for i in range(4)])

    # body motion: prescribed body velocity, heading integrated analytically
    # displacement per cycle is fixed, as for a rate-independent swimmer: speed ~ frequency
    speed = 80.0 * frequency_hz  # mm/s
    vx = speed * (1.0 + 0.5 * np.cos(2 * theta))
    vy = 0.2 * speed * np.sin(theta)
    w0 = rng.uniform(-0.1, 0.1) * frequency_hz
    heading = rng.uniform(-np.pi, np.pi) + 0.15 * np.sin(theta) + w0 * t
    wz = 0.15 * omega * np.cos(theta) + w0
    # world position: integrate on a 20x finer grid for accuracy
    fine = 20
    tf = np.arange((n - 1) * fine + 1) / (rate_hz * fine)
    thf = omega * tf + phase0
    hf = heading[0] - 0.15 * np.sin(phase0) + 0.15 * np.sin(thf) + w0 * tf
    vxf, vyf = speed * (1.0 + 0.5 * np.cos(2 * thf)), 0.2 * speed * np.sin(thf)
    dx = np.cos(hf) * vxf - np.sin(hf) * vyf
    dy = np.sin(hf) * vxf + np.cos(hf) * vyf
    x = cumulative_trapezoid(dx, tf, initial=0.0)[::fine] + rng.uniform(-200, 200)
    y = cumulative_trapezoid(dy, tf, initial=0.0)[::fine] + rng.uniform(-200, 200)

    return t, theta, phi, flips, vx, vy, wz, heading, x, y


def _markers(x, y, heading, phi, flips) -> np.ndarray:
    """Marker positions (n, 11, 3) mm in `ROLES` order on the rigid segments."""
    n = len(x)
    seg_heading = {"head": heading + phi[:, 0], "tail": heading - phi[:, 1]}
    ch, sh = np.cos(heading), np.sin(heading)
    joint = {
        "head": np.column_stack([x + ch * MIDDLE_MM / 2, y + sh * MIDDLE_MM / 2]),
        "tail": np.column_stack([x - ch * MIDDLE_MM / 2, y - sh * MIDDLE_MM / 2]),
    }

    def place(segment: str, local_xy: np.ndarray, z: float) -> np.ndarray:
        a = seg_heading[segment]
        c, s = np.cos(a), np.sin(a)
        px = joint[segment][:, 0] + c * local_xy[..., 0] - s * local_xy[..., 1]
        py = joint[segment][:, 1] + s * local_xy[..., 0] + c * local_xy[..., 1]
        return np.column_stack([px, py, np.full(n, z)])

    xyz = np.empty((n, len(ROLES), 3))
    for m, role in enumerate(ROLES):
        if role in RIGID:
            segment, (lx, ly, lz) = RIGID[role]
            xyz[:, m] = place(segment, np.array([lx, ly]), lz)
        else:
            segment, hx, side = FLIPPERS[role]
            a = flips[:, int(role[-1]) - 1]
            local = np.column_stack(
                [
                    hx - FLIPPER_MARKER_MM * np.cos(a),
                    side * (HALF_WIDTH_MM + FLIPPER_MARKER_MM * np.sin(a)),
                ]
            )
            xyz[:, m] = place(segment, local, FLIPPER_HEIGHT_MM)

    return xyz


def _capture_errors(xyz, rng, noise_mm, tilt_rad, n_jumps, n_dropouts):
    """The scene tilted and offset in the capture volume, with noise, jumps and dropouts;
    masks (n, 11) of jumped and dropped points."""
    n = len(xyz)
    # tilt and offset the whole scene in the capture volume
    rot = Rotation.from_rotvec(tilt_rad * np.array([0.6, 0.8, 0.0]))
    xyz = rot.apply(xyz.reshape(-1, 3)).reshape(xyz.shape) + np.array([150.0, -80.0, 30.0])
    xyz += rng.normal(0.0, noise_mm, xyz.shape)

    jumped = np.zeros((n, len(ROLES)), dtype=bool)
    for _ in range(n_jumps):
        m = int(rng.integers(len(ROLES)))
        start = int(rng.integers(5, n - 10))
        length = int(rng.integers(1, 4))
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        xyz[start : start + length, m] += rng.uniform(12.0, 30.0) * direction
        jumped[start : start + length, m] = True
    dropped = np.zeros_like(jumped)
    for _ in range(n_dropouts):
        m = int(rng.integers(len(ROLES)))
        start = int(rng.integers(5, n - 20))
        dropped[start : start + int(rng.integers(2, 13)), m] = True
    xyz[dropped] = np.nan
    jumped &= ~dropped

    return xyz, jumped, dropped


#: Each gait once, at a frequency of its own (Hz): a mix of gaits and rates.
ONE_PER_GAIT = (("O", 0.5), ("D+", 1.0), ("S+", 1 / 3), ("D-", 0.5), ("S-", 1.0))


def synthetic_trial(
    gait: str = "O",
    frequency_hz: float = 0.5,
    n_cycles: float = 10.0,
    rate_hz: float = 100.0,
    noise_mm: float = 0.2,
    n_jumps: int = 0,
    n_dropouts: int = 0,
    tilt_rad: float = 0.03,
    seed: int = 0,
) -> SyntheticTrial:
    """Build a synthetic trial (see the module docstring); all randomness from ``seed``."""
    rng = np.random.default_rng(seed)
    t, theta, phi, flips, vx, vy, wz, heading, x, y = _body_motion(
        rng, gait, frequency_hz, n_cycles, rate_hz
    )
    xyz = _markers(x, y, heading, phi, flips)
    xyz, jumped, dropped = _capture_errors(xyz, rng, noise_mm, tilt_rad, n_jumps, n_dropouts)
    truth = pd.DataFrame(
        {
            "t": t,
            "x": x,
            "y": y,
            "theta": heading,
            "vx": vx,
            "vy": vy,
            "wz": wz,
            "phi1": phi[:, 0],
            "phi2": phi[:, 1],
            **{f"flipper_{i + 1}": flips[:, i] for i in range(4)},
            "phase_cmd": theta,
        }
    )
    return SyntheticTrial(gait, frequency_hz, rate_hz, xyz, truth, jumped, dropped)


def synthetic_trials(conditions=ONE_PER_GAIT, seed: int = 0, **settings) -> list[SyntheticTrial]:
    """`synthetic_trial` of each (gait, frequency Hz) of ``conditions``, seeded ``seed``,
    ``seed + 1``, ...; ``settings``: its others (``n_cycles``, ``noise_mm``, ...)."""
    return [synthetic_trial(g, f, seed=seed + i, **settings) for i, (g, f) in enumerate(conditions)]


def write_marker_csv(trial: SyntheticTrial, path: Path) -> Path:
    """Write the trial as a marker CSV (`frame,t,<role>_x,...`, empty = not seen) and its
    truth as ``<stem>.truth.parquet`` beside it."""
    path = Path(path)
    n = len(trial.xyz)
    cols = {"frame": np.arange(1, n + 1), "t": trial.truth["t"].to_numpy()}
    for m, role in enumerate(ROLES):
        for c, axis in enumerate("xyz"):
            cols[f"{role}_{axis}"] = np.round(trial.xyz[:, m, c], 3)
    pd.DataFrame(cols).to_csv(path, index=False, float_format="%.3f")
    trial.truth.to_parquet(path.with_suffix(".truth.parquet"))
    return path


def write_dataset(
    folder: Path,
    gaits=GAITS,
    frequencies=FREQUENCIES_HZ,
    repeats: int = 1,
    n_cycles: float = 10.0,
    seed: int = 0,
    **kw,
) -> Path:
    """Write one synthetic trial per (gait, frequency, repeat) and a manifest; return the
    manifest's path. Extra keywords go to `synthetic_trial`."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    i = 0
    for gait in gaits:
        for f in frequencies:
            for r in range(1, repeats + 1):
                trial = synthetic_trial(gait, f, n_cycles, seed=seed + i, **kw)
                name = f"trial_{i:03d}.csv"
                write_marker_csv(trial, folder / name)
                rows.append(
                    {
                        "file": name,
                        "gait": gait,
                        "frequency_hz": f"{f:.10g}",
                        "repeat": r,
                        "notes": "synthetic",
                    }
                )
                i += 1
    manifest = folder / "manifest.csv"
    pd.DataFrame(rows).to_csv(manifest, index=False)
    return manifest


def qtm_text(names: list[str], xyz: np.ndarray, rate: float = 100.0, crlf: bool = True) -> str:
    """A QTM 3D TSV export of ``xyz`` (n_frames, n_markers, 3) mm; NaN -> 0 0 0."""
    n_frames = xyz.shape[0]
    head = [
        f"NO_OF_FRAMES\t{n_frames}",
        "NO_OF_CAMERAS\t4",
        f"NO_OF_MARKERS\t{len(names)}",
        f"FREQUENCY\t{rate:g}",
        "NO_OF_ANALOG\t0",
        "ANALOG_FREQUENCY\t0",
        "DESCRIPTION\t--",
        "TIME_STAMP\t2026-01-01, 10:00:00.000\t0.0",
        "DATA_INCLUDED\t3D",
        "MARKER_NAMES\t" + "\t".join(names),
        "TRAJECTORY_TYPES\t" + "\t".join(["Mixed"] * len(names)),
        "Frame\tTime\t" + "\t".join(f"{n} {a}" for n in names for a in "XYZ") + "\t",
    ]
    values = np.nan_to_num(xyz, nan=0.0).reshape(n_frames, -1)
    rows = [
        f"{i + 1}\t{i / rate:.5f}\t" + "\t".join(f"{v:.3f}" for v in row) + "\t"
        for i, row in enumerate(values)
    ]
    return ("\r\n" if crlf else "\n").join(head + rows) + ("\r\n" if crlf else "\n")


def random_track(n_frames: int, n_markers: int, seed: int = 0) -> np.ndarray:
    """Smooth random marker tracks, shape (n_frames, n_markers, 3), mm."""
    rng = np.random.default_rng(seed)
    base = rng.uniform(-300, 300, size=(1, n_markers, 3))
    drift = np.cumsum(rng.normal(0, 0.5, size=(n_frames, n_markers, 3)), axis=0)
    return np.round(base + drift, 3)
