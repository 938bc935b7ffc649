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

``directions="visited"`` fits A at each shape only from the directions of shape velocity
the training data took within ``radius`` of it (at most `MAX_VISITED` of them, drawn
with a fixed seed; each visiting sample counts once, so the fit is weighted by the data's
density): the connection inside the support in (shape, direction), not the learner's
extrapolation to directions it never saw. Where the visited directions are nearly
collinear one column of A is barely determined; ``spread`` (the smaller eigenvalue of
the visited unit directions' second moment, 0 for one line, 1/2 for all directions
alike) says how well they span the plane.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.spatial import cKDTree

from suds_exp.errors import ConfigError
from suds_exp.gait.support import SHAPE_RADIUS, Support, actuated_columns

COMPONENTS = ("vx", "vy", "wz")
#: Most visited directions a shape's fit uses (``directions="visited"``).
MAX_VISITED = 32


@dataclass
class LearnedConnection:
    """A connection on a grid: A[i, j, c, k] (component c of v_b per unit rate of joint
    k at (phi1[i], phi2[j]); mm/rad for vx, vy, rad/rad for wz), NaN outside ``inside``;
    ``nonlinearity`` (n1, n2); ``curl`` (n1, n2, 3) per rad^2; ``spread`` (n1, n2) of
    the directions fitted (NaN outside)."""

    phi1: np.ndarray
    phi2: np.ndarray
    A: np.ndarray
    inside: np.ndarray
    nonlinearity: np.ndarray
    curl: np.ndarray
    spread: np.ndarray | None = None

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


def _query_frame(ra: np.ndarray, dra: np.ndarray, k: int, rp0) -> pd.DataFrame:
    """One sample per (shape, shape velocity), each its own series so no learner links
    them; r_p (k columns) held at rp0 (mm)."""
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
    return frame


def _spread(dirs: np.ndarray) -> float:
    return float(np.linalg.eigvalsh(dirs.T @ dirs / len(dirs))[0])


def learned_connection(
    model,
    samples: pd.DataFrame,
    grid: int = 21,
    half_range: float = 2.5,
    n_directions: int = 16,
    radius: float = SHAPE_RADIUS,
    k: int = 0,
    rp0: np.ndarray | None = None,
    directions: str = "uniform",
    seed: int = 0,
) -> LearnedConnection:
    """The local connection of a fitted learner (`fit_map(...).model`) on a grid x grid
    square of shapes in [-half_range, half_range] rad, inside the shape support of its
    training ``samples`` (within ``radius`` rad of a training shape).

    directions: "uniform" (``n_directions`` evenly spaced unit shape velocities at every
    shape) or "visited" (the training samples' own directions near each shape, see the
    module docstring; seed draws them when more than `MAX_VISITED`).
    k, rp0: a SUDS learner's passive columns and the r_p (mm) held while asking it.
    """
    if directions not in ("uniform", "visited"):
        raise ConfigError(
            f"directions {directions!r}: expected 'uniform' or 'visited'", param="directions"
        )
    axis = np.linspace(-half_range, half_range, grid)
    p1, p2 = np.meshgrid(axis, axis, indexing="ij")
    pts = np.column_stack([p1.ravel(), p2.ravel()])
    support = Support.of(samples)
    inside = support.inside(pts, radius).reshape(grid, grid)
    rate = samples[actuated_columns(samples)[1]].to_numpy(float)
    norm = np.linalg.norm(rate, axis=1)
    speed = float(np.median(norm))
    if directions == "uniform":
        b = 2 * np.pi * np.arange(n_directions) / n_directions
        uniform = np.column_stack([np.cos(b), np.sin(b)])
        dirs = [uniform] * len(pts)
    else:
        if not inside.any():
            # no shape to fit from: say so rather than ask the learner about nothing
            raise ConfigError(
                f"grid {grid}, half_range {half_range:g}: no shape of the grid lies within "
                f"{radius:g} rad of the data; make it finer or narrower",
                param=("grid", "half_range"),
            )
        dirs = _visited_directions(samples, rate, norm, pts, inside.ravel(), radius, seed)
    counts = np.array([len(d) for d in dirs])
    ra = np.repeat(pts, counts, axis=0)
    every = np.concatenate(dirs)
    xi = model.predict(_query_frame(ra, every * speed, k, rp0))[list(COMPONENTS)]
    xi = xi.to_numpy(float) / speed
    if directions == "uniform":
        # every shape asks the same directions: one pseudo-inverse for all (as before)
        xi = xi.reshape(len(pts), len(uniform), 3)
        At = np.einsum("dk,pkc->pdc", np.linalg.pinv(uniform), xi)  # (n_pts, 2, 3)
        fit = np.einsum("kd,pdc->pkc", uniform, At)
        resid = np.sqrt(np.mean((xi - fit) ** 2, axis=(1, 2)))
        scale = np.sqrt(np.mean(xi**2, axis=(1, 2)))
        spread = np.full(len(pts), _spread(uniform))
    else:
        At, resid, scale, spread = (
            np.full(s, np.nan) for s in ((len(pts), 2, 3),) + 3 * (len(pts),)
        )
        ends = np.cumsum(counts)
        for i, (a, b) in enumerate(zip(ends - counts, ends, strict=True)):
            if b - a < 2:
                continue
            d, x = every[a:b], xi[a:b]
            At[i] = np.linalg.lstsq(d, x, rcond=None)[0]
            resid[i] = np.sqrt(np.mean((x - d @ At[i]) ** 2))
            scale[i] = np.sqrt(np.mean(x**2))
            spread[i] = _spread(d)
    A = np.transpose(At, (0, 2, 1)).reshape(grid, grid, 3, 2)
    nonlin = (resid / np.where(scale > 0, scale, 1.0)).reshape(grid, grid)
    spread = spread.reshape(grid, grid)
    # the curl's finite differences may lean on a neighbour just outside: take them on
    # the whole grid, then keep only the support
    curl = curl_of(A, axis, axis)
    inside &= np.isfinite(A).all(axis=(2, 3))
    A[~inside] = np.nan
    nonlin[~inside] = np.nan
    curl[~inside] = np.nan
    spread[~inside] = np.nan
    return LearnedConnection(axis, axis, A, inside, nonlin, curl, spread)


def _visited_directions(samples, rate, norm, pts, inside, radius, seed) -> list[np.ndarray]:
    """For each grid shape in ``pts`` (n, 2) inside the support, the unit shape velocities
    (m, 2) of the training samples within ``radius`` rad of it (at most `MAX_VISITED`,
    drawn with ``seed``); an empty (0, 2) array outside."""
    moving = norm > 1e-6
    shapes = samples[actuated_columns(samples)[0]].to_numpy(float)[moving]
    unit = rate[moving] / norm[moving, None]
    tree = cKDTree(shapes)
    rng = np.random.default_rng(seed)
    dirs = []
    for p, ok in zip(pts, inside, strict=True):
        idx = np.asarray(tree.query_ball_point(p, radius), dtype=int) if ok else []
        if len(idx) > MAX_VISITED:
            idx = rng.choice(idx, MAX_VISITED, replace=False)
        dirs.append(unit[idx] if len(idx) else np.empty((0, 2)))
    return dirs


def compare_connections(
    learned: LearnedConnection, reference: np.ndarray, min_spread: float = 0.0
) -> dict[str, float]:
    """Normalised RMS difference RMS(learned - reference) / RMS(reference) inside the
    support, per component (vx, vy, wz; both columns of A) and their mean.

    reference: A of the same grid (n1, n2, 3, 2), e.g. `suds_exp.sim.local_connection`'s.
    min_spread: only shapes whose fitted directions have at least this ``spread``.
    """
    out = {}
    m = learned.inside
    if min_spread > 0 and learned.spread is not None:
        m = m & (np.nan_to_num(learned.spread, nan=-1.0) >= min_spread)
    if not m.any():  # nothing to compare
        return dict.fromkeys((*COMPONENTS, "mean"), float("nan")) | {"n_inside": 0}
    for c, comp in enumerate(COMPONENTS):
        diff = learned.A[m, c, :] - reference[m, c, :]
        ref = reference[m, c, :]
        out[comp] = float(np.sqrt(np.mean(diff**2)) / np.sqrt(np.mean(ref**2)))
    out["mean"] = float(np.mean([out[c] for c in COMPONENTS]))
    out["n_inside"] = int(m.sum())
    return out
