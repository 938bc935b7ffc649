"""Drawings as sysplotter draws them: the connection's rows as vector fields over shape
space, the height function (curl) as a colour map, the support's edge, gaits overlaid;
and a design run's page (gaits on the height function, displacement per iteration,
predicted against achieved)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from suds_exp.gait.connection import COMPONENTS, LearnedConnection, curl_of
from suds_exp.gait.shape import Gait


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(plt, fig, path: str | Path) -> Path:
    """Lay out, write ``fig`` as a PNG at ``path`` (its folder made), close it."""
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _panel(ax, phi1, phi2, A, curl, inside, gaits, title, unit, labels=None):
    p1, p2 = np.meshgrid(phi1, phi2, indexing="ij")
    lim = np.nanmax(np.abs(curl)) if np.isfinite(curl).any() else 1.0
    mesh = ax.pcolormesh(
        p1, p2, np.ma.masked_invalid(curl), cmap="RdBu_r", vmin=-lim, vmax=lim, shading="nearest"
    )
    u, v = np.ma.masked_invalid(A[..., 0]), np.ma.masked_invalid(A[..., 1])
    ax.quiver(p1, p2, u, v, color="k", alpha=0.8)
    if inside is not None and inside.any() and not inside.all():
        ax.contour(p1, p2, inside.astype(float), levels=[0.5], colors="0.3", linestyles="--")
    for i, g in enumerate(gaits):
        _, r = g.cycle(200)
        label = g.name if labels is None else labels[i]
        ax.plot(np.r_[r[:, 0], r[0, 0]], np.r_[r[:, 1], r[0, 1]], lw=1.5, label=label)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("phi1 (rad)")
    ax.set_ylabel("phi2 (rad)")
    ax.set_aspect("equal")
    return mesh, unit


def draw_connection(
    learned: LearnedConnection,
    path: str | Path,
    reference: np.ndarray | None = None,
    gaits: Sequence[Gait] = (),
) -> Path:
    """One PNG: a row of the learned connection's three rows (vx, vy, wz; arrows = the
    row of A, colours = its curl, dashed = the support's edge, gaits overlaid) and, given
    ``reference`` (n1, n2, 3, 2; the simulator's connection on the same grid), a second
    row of it drawn the same way. Returns the path."""
    plt = _pyplot()
    rows = 1 if reference is None else 2
    fig, axes = plt.subplots(rows, 3, figsize=(13, 4.4 * rows), squeeze=False)
    sources = [("learned", learned.A, learned.curl, learned.inside)]
    if reference is not None:
        ref_curl = curl_of(reference, learned.phi1, learned.phi2)
        sources.append(("simulator", reference, ref_curl, learned.inside))
    for r, (label, A, curl, inside) in enumerate(sources):
        for c, comp in enumerate(COMPONENTS):
            unit = "mm/rad" if comp != "wz" else "rad/rad"
            mesh, _ = _panel(
                axes[r, c],
                learned.phi1,
                learned.phi2,
                A[:, :, c, :],
                curl[:, :, c],
                inside,
                gaits,
                f"{label} {comp}: A ({unit}), colour = curl",
                unit,
            )
            fig.colorbar(mesh, ax=axes[r, c], shrink=0.8)
    if gaits:
        axes[0, 0].legend(fontsize=7, loc="lower left")
    return _save(plt, fig, path)


def draw_design(design, learned: LearnedConnection | None, path: str | Path) -> Path:
    """One PNG of a design run: its gaits on the learned height function of vx, forward
    displacement per cycle by iteration (predicted, achieved), predicted against
    achieved. ``design``: a `suds_exp.gait.design.Design`. ``learned`` None (a body
    without two actuated joints has no height function to draw): the first panel says so."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.4))
    if learned is None:
        axes[0].axis("off")
        axes[0].text(
            0.5,
            0.5,
            f"no height function:\n{len(design.joints)} actuated joint(s), not 2",
            ha="center",
            va="center",
        )
    else:
        _height_panel(fig, axes[0], design, learned)
    _displacement_panels(axes[1], axes[2], design)
    return _save(plt, fig, path)


def _height_panel(fig, ax, design, learned: LearnedConnection) -> None:
    """The design's gaits on the learned height function of vx."""
    gaits = [it.gait for it in design.iterations]
    mesh, _ = _panel(
        ax,
        learned.phi1,
        learned.phi2,
        learned.A[:, :, 0, :],
        learned.curl[:, :, 0],
        learned.inside,
        gaits,
        "designed gaits on the learned vx height function",
        "mm/rad^2",
        [f"it{it.iteration}" for it in design.iterations],
    )
    fig.colorbar(mesh, ax=ax, shrink=0.8)
    ax.legend(fontsize=7, loc="lower left")


def _displacement_panels(by_iteration, against, design) -> None:
    """Forward displacement per iteration (predicted, achieved) and predicted against
    achieved, on the two axes given."""
    its = [it.iteration for it in design.iterations]
    pred = [it.predicted.forward_mm for it in design.iterations]
    by_iteration.plot(its, pred, "o-", label="predicted")
    ach = [it.achieved.forward_mm if it.achieved else np.nan for it in design.iterations]
    if np.isfinite(ach).any():
        by_iteration.plot(its, ach, "s-", label="achieved (simulator)")
        against.plot(pred, ach, "o")
        lo, hi = np.nanmin(pred + ach), np.nanmax(pred + ach)
        against.plot([lo, hi], [lo, hi], "k--", lw=0.8)
        for i, p, a in zip(its, pred, ach, strict=True):
            against.annotate(str(i), (p, a), fontsize=8)
    by_iteration.set_xlabel("iteration")
    by_iteration.set_ylabel("forward displacement per cycle (mm)")
    by_iteration.legend()
    against.set_xlabel("predicted (mm/cycle)")
    against.set_ylabel("achieved (mm/cycle)")
    against.set_title("predicted against achieved", fontsize=9)
