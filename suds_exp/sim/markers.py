"""The 11 motion-capture markers: rigid positions on segments and flippers, the spokes'
parasitic oscillation, and the measurement errors of the capture system.

Segment frames (mm): origin on the segment's motor axis (head: head joint, tail: tail
joint), +X along the segment's tail-to-head axis, +Y to the robot's left. Marker
heights are world Z above the bed surface (`Measurement.*_height_mm`).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.signal import cont2discrete, lfilter, ss2tf

from suds_exp.robot import ROLES, SPOKE_ROLES
from suds_exp.sim.config import SimConfig

#: The simulated robot carries one marker per role, named after the role, so its files
#: need no marker layout (the ingest default).
MARKER_NAMES = ROLES

SPOKE_MARKERS = SPOKE_ROLES


def marker_layout(cfg: SimConfig) -> dict[str, tuple[str, float, float, float]]:
    """name -> (segment 'head' | 'tail' | 'flipper_i', x, y, z): x, y in the segment
    frame (for flippers: distance from the hinge along the flipper, 0), z world height (mm).

    Top-face markers sit off the axis on both sides so a segment's heading follows from
    the two; the spoke markers sit near the segment middle on a raised skewer; tail_back
    is on the tail's back edge.
    """
    g, m = cfg.geometry, cfg.measurement
    hl, tl, w = g.head_length_mm, g.tail_length_mm, g.segment_width_mm
    top, spoke, back, fz = m.top_height_mm, m.spoke_height_mm, m.back_height_mm, m.flipper_height_mm
    return {
        "head_top_1": ("head", 0.25 * hl, 0.3 * w, top),
        "head_top_2": ("head", 0.8 * hl, -0.3 * w, top),
        "head_spoke": ("head", 0.55 * hl, 0.0, spoke),
        "tail_top_1": ("tail", -0.2 * tl, 0.3 * w, top),
        "tail_top_2": ("tail", -0.75 * tl, -0.3 * w, top),
        "tail_spoke": ("tail", -0.5 * tl, 0.0, spoke),
        "tail_back": ("tail", -tl, 0.0, back),
        "flipper_1": ("flipper_1", m.flipper_marker_mm, 0.0, fz),
        "flipper_2": ("flipper_2", m.flipper_marker_mm, 0.0, fz),
        "flipper_3": ("flipper_3", m.flipper_marker_mm, 0.0, fz),
        "flipper_4": ("flipper_4", m.flipper_marker_mm, 0.0, fz),
    }


def _segment_poses(cfg: SimConfig, pose: np.ndarray, phi: np.ndarray) -> dict:
    """World (origin x, y, heading) of the head and tail segment frames, arrays (n,)."""
    half = cfg.geometry.middle_length_mm / 2
    x, y, th = pose[:, 0], pose[:, 1], pose[:, 2]
    c, s = np.cos(th), np.sin(th)
    return {
        "head": (x + c * half, y + s * half, th + phi[:, 0]),
        "tail": (x - c * half, y - s * half, th - phi[:, 1]),
    }


def rigid_marker_positions(
    cfg: SimConfig, pose: np.ndarray, phi: np.ndarray, flippers: np.ndarray
) -> np.ndarray:
    """Marker positions without oscillation or noise.

    pose (n, 3) world x, y (mm), theta (rad); phi (n, 2) rad; flippers (n, 4) rad.
    Returns array (n, 11, 3), mm, markers in `MARKER_NAMES` order.
    """
    g = cfg.geometry
    segs = _segment_poses(cfg, pose, phi)
    layout = marker_layout(cfg)
    n = pose.shape[0]
    out = np.empty((n, len(MARKER_NAMES), 3))
    hinge_x = {0: g.head_hinge_mm, 1: g.head_hinge_mm, 2: -g.tail_hinge_mm, 3: -g.tail_hinge_mm}
    for j, name in enumerate(MARKER_NAMES):
        seg, lx, ly, z = layout[name]
        if seg.startswith("flipper"):
            i = int(seg[-1]) - 1
            side = 1.0 if i in (0, 2) else -1.0
            a = flippers[:, i]
            px = hinge_x[i] - lx * np.cos(a)
            py = side * (g.segment_width_mm / 2 + lx * np.sin(a))
            ox, oy, th = segs["head" if i < 2 else "tail"]
        else:
            px, py = lx, ly
            ox, oy, th = segs[seg]
        c, s = np.cos(th), np.sin(th)
        out[:, j, 0] = ox + c * px - s * py
        out[:, j, 1] = oy + s * px + c * py
        out[:, j, 2] = z
    return out


@functools.lru_cache(maxsize=64)
def _spoke_filter(freq_hz: float, zeta: float, gain: float, dt: float):
    """(num, den) of the zero-order-hold discretised spoke oscillator."""
    w = 2 * math.pi * freq_hz
    A = np.array([[0.0, 1.0], [-w * w, -2 * zeta * w]])
    B = np.array([[0.0], [-gain]])
    C = np.array([[1.0, 0.0]])
    D = np.array([[0.0]])
    Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, D), dt, method="zoh")
    num, den = ss2tf(Ad, Bd, Cd, Dd)
    return np.ravel(num), np.ravel(den)


def spoke_deflection(cfg: SimConfig, base_xy: np.ndarray, dt: float) -> np.ndarray:
    """Parasitic oscillation of a raised spoke marker, mm, array (n, 2).

    The marker is a mass on a flexible skewer: d'' + 2 zeta w d' + w^2 d = -gain * a,
    with a the acceleration of the rigid marker point (world XY, from second differences
    of base_xy (n, 2), mm, sampled every dt s). Discretised exactly (zero-order hold).
    """
    eff = cfg.effects.spoke_oscillation
    n = base_xy.shape[0]
    if eff.gain == 0 or n < 3:
        return np.zeros((n, 2))
    acc = np.gradient(np.gradient(base_xy, dt, axis=0), dt, axis=0)
    num, den = _spoke_filter(eff.freq_hz, eff.damping_ratio, eff.gain, dt)
    return lfilter(num, den, acc, axis=0)


def true_marker_positions(
    cfg: SimConfig, pose: np.ndarray, phi: np.ndarray, flippers: np.ndarray, dt: float
) -> np.ndarray:
    """Noise-free marker positions including the spokes' oscillation: (n, 11, 3), mm."""
    pos = rigid_marker_positions(cfg, pose, phi, flippers)
    for name in SPOKE_MARKERS:
        j = MARKER_NAMES.index(name)
        pos[:, j, :2] += spoke_deflection(cfg, pos[:, j, :2], dt)
    return pos


def measure(cfg: SimConfig, true_pos: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Measured positions: Gaussian noise, rare single-frame jumps, dropouts (NaN).

    true_pos (n, 11, 3), mm. Jumps are displacements of jump_mm_min..jump_mm_max in a
    random direction on a fraction jump_prob of marker-frames; dropouts last
    dropout_frames_min..max frames and occur dropout_per_s times per marker-second.
    """
    m = cfg.measurement
    n, k, _ = true_pos.shape
    out = true_pos + rng.normal(scale=m.noise_mm, size=true_pos.shape)
    jumps = rng.random((n, k)) < m.jump_prob
    nj = int(jumps.sum())
    if nj:
        d = rng.normal(size=(nj, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        out[jumps] += d * rng.uniform(m.jump_mm_min, m.jump_mm_max, size=(nj, 1))
    duration = n / m.sample_rate_hz
    for j in range(k):
        for _ in range(rng.poisson(m.dropout_per_s * duration)):
            length = int(rng.integers(m.dropout_frames_min, m.dropout_frames_max + 1))
            start = int(rng.integers(0, max(n - length, 1)))
            out[start : start + length, j] = np.nan
    return out
