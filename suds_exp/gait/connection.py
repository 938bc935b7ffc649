"""The learned local connection of a two-joint robot, its curl, and its support.

A learned map gives v_b = f(r_a, dr_a/dt). Its local connection at a shape is read off
as the simulator's is (`suds_exp.sim.connection`): f is evaluated at `n_directions` unit
shape velocities u_b = (cos b, sin b), b evenly spaced on [0, 2 pi) (a learned map need
not be odd in dr_a/dt, so both senses are asked), scaled to the training data's median
shape speed and divided by it, and A (3 x 2) is the least-squares fit of xi_b = A u_b.
``nonlinearity`` is the RMS residual of that fit over the RMS of xi: how far the map is
from a connection at that shape (granular media are not linear in the shape rate).

The curl of each row of A, d A_c2 / d phi1 - d A_c1 / d phi2 (finite differences on the
grid), is the height function of the constraint curvature: the net motion of a small
gait is about its integral over the enclosed area (Hatton & Choset; the Lie-bracket
term is left out, as sysplotter's "curl" panel does).

Only grid points inside the training data's shape support are reported (NaN elsewhere).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from suds_exp.gait.support import SHAPE_RADIUS, Support

COMPONENTS = ("vx", "vy", "wz")


@dataclass
class LearnedConnection:
    """A connection on a grid: A[i, j, c, k] (component c of v_b per unit rate of joint
    k at (phi1[i], phi2[j]); mm/rad for vx, vy, rad/rad for wz), NaN outside ``inside``;
    ``nonlinearity`` (n1, n2); ``curl`` (n1, n2, 3) per rad^2."""

    phi1: np.ndarray
    phi2: np.ndarray
    A: np.ndarray
    inside: np.ndarray
    nonlinearity: np.ndarray
    curl: np.ndarray

    def to_frame(self) -> pd.DataFrame:
        """The connection CSV layout (`suds_exp.sim.CONNECTION_COLUMNS`) plus
        ``inside``, ``nonlinearity`` and ``curl_vx``/``curl_vy``/``curl_wz``."""
        p1, p2 = np.meshgrid(self.phi1, self.phi2, indexing="ij")
        cols = {"phi1": p1.ravel(), "phi2": p2.ravel()}
        for c, comp in enumerate(COMPONENTS):
            for k in range(2):
                cols[f"{comp}_phi{k + 1}"] = self.A[:, :, c, k].ravel()
        cols["inside"] = self.inside.ravel()
        cols["nonlinearity"] = self.nonlinearity.ravel()
        for c, comp in enumerate(COMPONENTS):
            cols[f"curl_{comp}"] = self.curl[:, :, c].ravel()
        return pd.DataFrame(cols)


def curl_of(A: np.ndarray, phi1: np.ndarray, phi2: np.ndarray) -> np.ndarray:
    """d A[..., c, 1] / d phi1 - d A[..., c, 0] / d phi2 on the grid: (n1, n2, 3)."""
    d2_d1 = np.gradient(A[:, :, :, 1], phi1, axis=0)
    d1_d2 = np.gradient(A[:, :, :, 0], phi2, axis=1)
    return d2_d1 - d1_d2


def learned_connection(
    model,
    samples: pd.DataFrame,
    grid: int = 21,
    half_range: float = 2.5,
    n_directions: int = 16,
    radius: float = SHAPE_RADIUS,
    k: int = 0,
    rp0: np.ndarray | None = None,
) -> LearnedConnection:
    """The local connection of a fitted learner (`fit_map(...).model`) on a grid x grid
    square of shapes in [-half_range, half_range] rad, inside the shape support of its
    training ``samples`` (within ``radius`` rad of a training shape).

    k, rp0: a SUDS learner's passive columns and the r_p (mm) held while asking it.
    """
    axis = np.linspace(-half_range, half_range, grid)
    p1, p2 = np.meshgrid(axis, axis, indexing="ij")
    pts = np.column_stack([p1.ravel(), p2.ravel()])
    support = Support.of(samples)
    inside = support.inside(pts, radius).reshape(grid, grid)
    speed = float(np.median(np.linalg.norm(samples[["dra_1", "dra_2"]].to_numpy(float), axis=1)))
    b = 2 * np.pi * np.arange(n_directions) / n_directions
    dirs = np.column_stack([np.cos(b), np.sin(b)])
    ra = np.repeat(pts, len(dirs), axis=0)
    dra = np.tile(dirs, (len(pts), 1)) * speed
    # one sample per (shape, direction); each its own series so no learner links them
    frame = pd.DataFrame(
        {
            "trial_id": np.arange(len(ra)) + 1,
            "frame": 0,
            "t": 0.0,
            "phase": np.arctan2(ra[:, 1], ra[:, 0]),
            "cycle": 0,
            "ra_1": ra[:, 0],
            "ra_2": ra[:, 1],
            "dra_1": dra[:, 0],
            "dra_2": dra[:, 1],
        }
    )
    for j in range(k):
        frame[f"rp_{j + 1}"] = 0.0 if rp0 is None else rp0[j]
        frame[f"drp_{j + 1}"] = 0.0
    xi = model.predict(frame)[list(COMPONENTS)].to_numpy(float) / speed
    xi = xi.reshape(len(pts), len(dirs), 3)
    At = np.einsum("dk,pkc->pdc", np.linalg.pinv(dirs), xi)  # (n_pts, 2, 3)
    fit = np.einsum("kd,pdc->pkc", dirs, At)
    resid = np.sqrt(np.mean((xi - fit) ** 2, axis=(1, 2)))
    scale = np.sqrt(np.mean(xi**2, axis=(1, 2)))
    A = np.transpose(At, (0, 2, 1)).reshape(grid, grid, 3, 2)
    nonlin = (resid / np.where(scale > 0, scale, 1.0)).reshape(grid, grid)
    # the curl's finite differences may lean on a neighbour just outside: take them on
    # the whole grid, then keep only the support
    curl = curl_of(A, axis, axis)
    A[~inside] = np.nan
    nonlin[~inside] = np.nan
    curl[~inside] = np.nan
    return LearnedConnection(axis, axis, A, inside, nonlin, curl)


def compare_connections(learned: LearnedConnection, reference: np.ndarray) -> dict[str, float]:
    """Normalised RMS difference RMS(learned - reference) / RMS(reference) inside the
    support, per component (vx, vy, wz; both columns of A) and their mean.

    reference: A of the same grid (n1, n2, 3, 2), e.g. `suds_exp.sim.local_connection`'s.
    """
    out = {}
    m = learned.inside
    for c, comp in enumerate(COMPONENTS):
        diff = learned.A[m, c, :] - reference[m, c, :]
        ref = reference[m, c, :]
        out[comp] = float(np.sqrt(np.mean(diff**2)) / np.sqrt(np.mean(ref**2)))
    out["mean"] = float(np.mean([out[c] for c in COMPONENTS]))
    out["n_inside"] = int(m.sum())
    return out
