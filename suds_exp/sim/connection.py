"""Local connection of the swimmer with flippers locked: xi = A(phi) d(phi)/dt.

Granular RFT is not linear in the shape rate, so "the" connection depends on how it is
estimated. We fit it by least squares over `n_directions` unit shape rates
d(phi)/dt = (cos b, sin b), b evenly spaced on [0, pi) (xi is odd in d(phi)/dt, so the
opposite directions add nothing): A(phi) = argmin sum_b |xi(phi, b) - A (cos b, sin b)|^2.
`method="columns"` instead takes column j = xi(d(phi)/dt = e_j), the textbook reading.

Geometries: "robot" (the configured robot, flippers locked at their locked angle) and
"classic" (three equal links of total length 1, no flippers, body frame on the middle
link: the textbook three-link swimmer, for comparison with published fields).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.errors import ConfigError
from suds_exp.sim import rft
from suds_exp.sim.config import SimConfig
from suds_exp.sim.mechanics import element_table, pack_params

CONNECTION_COLUMNS = (
    "phi1",
    "phi2",
    "vx_phi1",
    "vx_phi2",
    "vy_phi1",
    "vy_phi2",
    "wz_phi1",
    "wz_phi2",
)
# GeometricSystemPlotter's grid (-10:10) * pi / 11 is labelled -2.5:0.25:2.5 in the
# published granular table; true angle = label * this (likely, see the notes).
HATTON_RELABEL = (10 * np.pi / 11) / 2.5
# Medium coefficients calibrated to the published granular table (C_S kept at 3.21; only
# ratios matter): Nelder-Mead on the mean normalised RMS difference of the six
# components, least-squares connection, relabelled grid (benchmarks in the README).
# A fit to the table, not a measured medium: use it to compare fields, not as beans.
HATTON_CALIBRATED_MEDIUM = {"c_f": 1.569, "c_l": -0.93, "gamma": 1.739}


def classic_config(elements_per_link: int = 20, medium: dict | None = None) -> SimConfig:
    """The textbook three-link swimmer: equal links of total length 1 (unit: total length).

    medium: optional overrides of `Medium` fields, e.g. HATTON_CALIBRATED_MEDIUM."""
    cfg = SimConfig()
    for key, value in (medium or {}).items():
        setattr(cfg.medium, key, value)
    g = cfg.geometry
    g.middle_length_mm = g.head_length_mm = g.tail_length_mm = 1 / 3
    g.elements_per_segment = elements_per_link
    cfg.effects.flippers.mode = "absent"
    return cfg


def robot_config(config: SimConfig | None = None) -> SimConfig:
    cfg = (config or SimConfig()).copy()
    if cfg.effects.flippers.mode == "free":
        cfg.effects.flippers.mode = "locked"
    return cfg


GEOMETRIES = {"robot": robot_config, "classic": lambda config=None: classic_config()}


@dataclass
class Connection:
    """A local connection on a grid: A[i, j, c, k] = body velocity component c (vx, vy
    in length units/s, wz rad/s) per unit rate of joint k at (phi1[i], phi2[j])."""

    phi1: np.ndarray
    phi2: np.ndarray
    A: np.ndarray
    max_residual: float

    def to_frame(self) -> pd.DataFrame:
        """The CSV layout of `suds-exp connection`, one row per grid point (phi2 fastest)."""
        p1, p2 = np.meshgrid(self.phi1, self.phi2, indexing="ij")
        cols = {"phi1": p1.ravel(), "phi2": p2.ravel()}
        for c, comp in enumerate(("vx", "vy", "wz")):
            for k in range(2):
                cols[f"{comp}_phi{k + 1}"] = self.A[:, :, c, k].ravel()
        return pd.DataFrame(cols, columns=list(CONNECTION_COLUMNS))


def body_twists(cfg: SimConfig, phis: np.ndarray, dphis: np.ndarray) -> np.ndarray:
    """Quasi-static body twists with flippers held: (n, 3) vx, vy (length/s), wz (rad/s).

    phis, dphis: arrays (n, 2), rad and rad/s.
    """
    table = element_table(cfg)
    prm = pack_params(cfg)
    out = np.empty((len(phis), 3))
    res = np.empty(len(phis))
    rft.solve_twists(
        np.ascontiguousarray(phis, dtype=float),
        np.ascontiguousarray(dphis, dtype=float),
        prm,
        *table.kernel_args(),
        out,
        res,
    )
    return out, res


def local_connection(
    grid: int = 21,
    half_range: float = 2.5,
    geometry: str = "robot",
    config: SimConfig | None = None,
    n_directions: int = 8,
    method: str = "lstsq",
    phi_values: np.ndarray | None = None,
    medium: dict | None = None,
) -> Connection:
    """Local connection on a grid x grid square of (phi1, phi2) in [-half_range, half_range].

    geometry: "robot" (config, flippers locked) or "classic"; method: "lstsq" (fit over
    n_directions shape-rate directions) or "columns"; phi_values overrides the grid axis
    (rad), e.g. to evaluate at relabelled angles; medium overrides `Medium` fields.
    """
    try:
        cfg = GEOMETRIES[geometry](config)
    except KeyError:
        raise ConfigError(
            f"geometry {geometry!r}: expected robot or classic", param="geometry"
        ) from None
    for key, value in (medium or {}).items():
        setattr(cfg.medium, key, value)
    if grid < 2:
        raise ConfigError(f"grid {grid}: need at least 2 points per axis", param="grid")
    axis = np.linspace(-half_range, half_range, grid) if phi_values is None else phi_values
    axis = np.asarray(axis, dtype=float)
    if method == "lstsq":
        b = np.pi * np.arange(n_directions) / n_directions
        dirs = np.column_stack([np.cos(b), np.sin(b)])
    elif method == "columns":
        dirs = np.eye(2)
    else:
        raise ConfigError(f"method {method!r}: expected lstsq or columns")
    p1, p2 = np.meshgrid(axis, axis, indexing="ij")
    pts = np.column_stack([p1.ravel(), p2.ravel()])
    phis = np.repeat(pts, len(dirs), axis=0)
    dphis = np.tile(dirs, (len(pts), 1))
    xi, res = body_twists(cfg, phis, dphis)
    xi = xi.reshape(len(pts), len(dirs), 3)
    # least squares per point: xi (K, 3) = dirs (K, 2) @ A^T (2, 3)
    pinv = np.linalg.pinv(dirs)  # (2, K)
    At = np.einsum("dk,pkc->pdc", pinv, xi)  # (n_pts, 2, 3)
    A = np.transpose(At, (0, 2, 1)).reshape(len(axis), len(axis), 3, 2)
    return Connection(axis, axis, A, float(res.max()))


def save_connection(conn: Connection, out: str | Path, figures: bool = True) -> list[Path]:
    """Write the connection CSV and (figures=True) one vector-field PNG per component
    (`<stem>_vx.png`, `_vy.png`, `_wz.png`). Returns the written paths."""
    out = Path(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        conn.to_frame().to_csv(out, index=False, float_format="%.8g")
    except OSError as exc:
        raise ConfigError(f"{out}: cannot write connection CSV ({exc.strerror})") from None
    written = [out]
    if figures:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        p1, p2 = np.meshgrid(conn.phi1, conn.phi2, indexing="ij")
        for c, (comp, unit) in enumerate(
            (("vx", "length/rad"), ("vy", "length/rad"), ("wz", "rad/rad"))
        ):
            fig, ax = plt.subplots(figsize=(5, 5))
            u, v = conn.A[:, :, c, 0], conn.A[:, :, c, 1]
            mag = np.hypot(u, v)
            ax.quiver(p1, p2, u, v, mag, cmap="viridis")
            ax.set_xlabel("phi1 (rad)")
            ax.set_ylabel("phi2 (rad)")
            ax.set_title(f"{comp}: rows of A ({unit}), xi = A dphi/dt")
            ax.set_aspect("equal")
            path = out.with_name(f"{out.stem}_{comp}.png")
            fig.savefig(path, dpi=110, bbox_inches="tight")
            plt.close(fig)
            written.append(path)
    return written


def compare_with_hatton(
    mat_path: str | Path,
    relabel: bool = False,
    method: str = "lstsq",
    n_directions: int = 8,
    medium: dict | None = None,
) -> dict[str, float]:
    """RMS(ours - published) / RMS(published) per component of the classic swimmer.

    The published table (Hatton et al. 2013, granular) is read raw as xi = +T alpha_dot,
    alpha1 = our phi2 (tail joint, link 1 at -x), alpha2 = our phi1; its translational
    rows are per unit link length, so ours (total length 1) are multiplied by 3.
    relabel=True evaluates ours at the probable true angles (labels x HATTON_RELABEL);
    medium overrides the medium coefficients (e.g. HATTON_CALIBRATED_MEDIUM).
    Returns {"Ax1": ..., ..., "Atheta2": ..., "mean": ...}.
    """
    from scipy.io import loadmat

    mat = loadmat(mat_path)
    labels = np.asarray(mat["alpha1"])[:, 0]
    axis = labels * (HATTON_RELABEL if relabel else 1.0)
    conn = local_connection(
        geometry="classic",
        phi_values=axis,
        method=method,
        n_directions=n_directions,
        medium=medium,
    )
    A = conn.A  # [i (phi1), j (phi2), comp, k]
    # table index [a, b] is at (alpha1 = labels[a], alpha2 = labels[b]) = (phi2, phi1)
    ours = {}
    for comp_t, c, scale in (("Ax", 0, 3.0), ("Ay", 1, 3.0), ("Atheta", 2, 1.0)):
        for k_t, k in (("1", 1), ("2", 0)):
            ours[comp_t + k_t] = scale * A[:, :, c, k].T
    out = {}
    for key, val in ours.items():
        pub = np.asarray(mat[key], dtype=float)
        out[key] = float(np.sqrt(np.mean((val - pub) ** 2)) / np.sqrt(np.mean(pub**2)))
    out["mean"] = float(np.mean(list(out.values())))
    return out
