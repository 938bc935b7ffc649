"""Net motion over a cycle: the path-ordered (SE(2)) integral of body velocities.

A body twist xi = (vx, vy, wz) (mm/s, mm/s, rad/s, body frame) held for dt moves the
body by the group exponential exp(xi dt); the pose after a cycle is the ordered product
g(T) = exp(xi_1 dt) exp(xi_2 dt) ... (Hatton & Choset's displacement). Integrating the
body velocities' components instead would ignore that the body turns while it moves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def se2_exp(xi: np.ndarray, dt: float) -> np.ndarray:
    """exp(xi dt) of twists xi (n, 3) (vx, vy mm/s, wz rad/s): displacements (n, 3)
    (dx, dy mm in the frame at the step's start, dtheta rad)."""
    xi = np.asarray(xi, float).reshape(-1, 3)
    vx, vy, w = xi[:, 0] * dt, xi[:, 1] * dt, xi[:, 2] * dt
    small = np.abs(w) < 1e-8
    ws = np.where(small, 1.0, w)
    s = np.where(small, 1 - w**2 / 6, np.sin(ws) / ws)
    c = np.where(small, w / 2, (1 - np.cos(ws)) / ws)
    return np.column_stack([s * vx - c * vy, c * vx + s * vy, w])


def compose(g: np.ndarray, h: np.ndarray) -> np.ndarray:
    """g h for poses (x, y, theta): h expressed in g's frame. Shapes (3,) or (n, 3)."""
    g, h = np.asarray(g, float), np.asarray(h, float)
    c, s = np.cos(g[..., 2]), np.sin(g[..., 2])
    return np.stack(
        [
            g[..., 0] + c * h[..., 0] - s * h[..., 1],
            g[..., 1] + s * h[..., 0] + c * h[..., 1],
            g[..., 2] + h[..., 2],
        ],
        axis=-1,
    )


def relative(g0: np.ndarray, g1: np.ndarray) -> np.ndarray:
    """g0^-1 g1: pose g1 (x, y mm, theta rad; world) in the frame of g0. Shapes (3,) or
    (n, 3)."""
    g0, g1 = np.asarray(g0, float), np.asarray(g1, float)
    dx, dy = g1[..., 0] - g0[..., 0], g1[..., 1] - g0[..., 1]
    c, s = np.cos(g0[..., 2]), np.sin(g0[..., 2])
    return np.stack([c * dx + s * dy, -s * dx + c * dy, g1[..., 2] - g0[..., 2]], axis=-1)


def integrate_twists(xi: np.ndarray, dt: float, pose0=(0.0, 0.0, 0.0)) -> np.ndarray:
    """World poses (n, 3) from body twists xi (n, 3) sampled every dt s: the ordered
    product of exponentials of the mean twist over each interval (pose[0] = pose0)."""
    xi = np.asarray(xi, float)
    steps = se2_exp(0.5 * (xi[1:] + xi[:-1]), dt)
    # g_k+1 = g_k step_k: headings add up, and each step's translation is turned by the
    # heading at its start, so the ordered product is two cumulative sums
    x0, y0, th0 = (float(v) for v in pose0)
    theta = th0 + _from_zero(np.cumsum(steps[:, 2]))
    c, s = np.cos(theta[:-1]), np.sin(theta[:-1])
    dx = c * steps[:, 0] - s * steps[:, 1]
    dy = s * steps[:, 0] + c * steps[:, 1]
    return np.column_stack([x0 + _from_zero(np.cumsum(dx)), y0 + _from_zero(np.cumsum(dy)), theta])


def recorded_cycles(twists: np.ndarray, dt: float, period_s: float) -> np.ndarray:
    """Net motion of each whole period of a recording: body twists (n, 3) (vx, vy mm/s, wz
    rad/s) sampled every dt s, integrated (path-ordered) and cut every ``period_s`` s from
    the first sample. Returns (cycles, 3): forward, lateral (mm, body frame at each
    period's start) and turn (rad); no row when the recording is shorter than a period.
    A period that starts elsewhere than the gait's phase 0 turns the first two by the
    body's heading there, not the distance."""
    per = int(round(period_s / dt))
    n = (len(twists) - 1) // per if per > 0 else 0
    if n < 1:
        return np.zeros((0, 3))
    return cycle_motion(integrate_twists(twists[: n * per + 1], dt), per, range(n)).per_cycle


def _from_zero(cumulative: np.ndarray) -> np.ndarray:
    """0 then ``cumulative`` (n,): shape (n + 1,) (np.r_[0.0, x] at a tenth of its cost;
    the designer integrates thousands of rollouts)."""
    out = np.empty(len(cumulative) + 1)
    out[0] = 0.0
    out[1:] = cumulative
    return out


@dataclass
class CycleMotion:
    """Net motion over one cycle in the body frame at the cycle's start, averaged over
    the cycles measured: forward_mm, lateral_mm, turn_rad, mean_vx_mm_s; ``per_cycle``
    holds each cycle's (forward, lateral, turn)."""

    forward_mm: float
    lateral_mm: float
    turn_rad: float
    mean_vx_mm_s: float
    per_cycle: np.ndarray

    def to_dict(self) -> dict:
        return {
            "forward_mm": round(self.forward_mm, 4),
            "lateral_mm": round(self.lateral_mm, 4),
            "turn_rad": round(self.turn_rad, 6),
            "mean_vx_mm_s": round(self.mean_vx_mm_s, 4),
        }


def cycle_motion(
    poses: np.ndarray, frames_per_cycle: int, cycles, vx: np.ndarray | None = None
) -> CycleMotion:
    """Per-cycle net motion of world poses (n, 3) (x, y mm, theta rad) sampled so that
    cycle c spans frames [c F, (c + 1) F] (F = frames_per_cycle); ``cycles``: which
    cycles (0-based) to average. ``vx`` (n,) mm/s gives mean_vx over them (else the
    forward displacement over the period)."""
    per = []
    for c in cycles:
        a, b = c * frames_per_cycle, (c + 1) * frames_per_cycle
        per.append(relative(poses[a], poses[b]))
    per = np.array(per)
    if vx is not None:
        a, b = min(cycles) * frames_per_cycle, (max(cycles) + 1) * frames_per_cycle
        mean_vx = float(np.mean(vx[a:b]))
    else:
        mean_vx = float("nan")
    return CycleMotion(
        float(per[:, 0].mean()), float(per[:, 1].mean()), float(per[:, 2].mean()), mean_vx, per
    )
