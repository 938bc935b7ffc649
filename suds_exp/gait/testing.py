"""Fixtures shared by the gait tests and benchmarks: the set of unseen gaits, and the
default dataset (simulated, ingested, preprocessed) as samples."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.gait.shape import TWO_PI, FourierGait, Gait, SampledGait, ellipse
from suds_exp.gait.support import SHAPE_RADIUS, Support


def rounded_square(radius: float, power: float, name: str) -> SampledGait:
    """phi = radius (sgn(cos) |cos|^p, sgn(sin) |sin|^p) (rad); p < 1 squares the circle."""
    theta = TWO_PI * np.arange(200) / 200
    c, s = np.cos(theta), np.sin(theta)
    phi = radius * np.column_stack(
        [np.sign(c) * np.abs(c) ** power, np.sign(s) * np.abs(s) ** power]
    )
    return SampledGait(theta, phi, name)


def UNSEEN() -> list[Gait]:  # noqa: N802 (a constant set, built fresh each call)
    """Twelve gaits other than the paper's five inside the annulus of shapes the five
    visit (radius about 0.75-1.3 rad): circles, ellipses, phase-shifted ellipses, offset
    circles, rounded squares. Fixed before any was scored."""
    return [
        ellipse(1.2, 1.2, name="circle 1.2"),
        ellipse(1.2, 1.2, 0.5, name="ellipse 1.2, shift 0.5"),
        ellipse(1.1, 1.1, 0.3, name="ellipse 1.1, shift 0.3"),
        ellipse(1.1, 1.1, -0.3, name="ellipse 1.1, shift -0.3"),
        ellipse(1.1, 1.1, 0.5, name="ellipse 1.1, shift 0.5"),
        ellipse(1.0, 1.2, 0.4, name="ellipse 1.0 x 1.2, shift 0.4"),
        ellipse(1.2, 0.9, name="ellipse 1.2 x 0.9"),
        ellipse(0.9, 1.2, name="ellipse 0.9 x 1.2"),
        ellipse(1.0, 1.0, 0, 0.15, 0, name="circle 1.0 offset phi1 +0.15"),
        ellipse(1.0, 1.0, 0, 0, 0.15, name="circle 1.0 offset phi2 +0.15"),
        rounded_square(1.0, 0.6, "rounded square 1.0, p 0.6"),
        rounded_square(0.95, 0.4, "rounded square 0.95, p 0.4"),
    ]


def third_harmonic(c: float, d: float, scale: float = 1.0) -> FourierGait:
    """phi1 = s (cos t + c cos 3t), phi2 = s (sin t - d sin 3t) (rad): the paper's family
    (c = d = 1/k) with the joints' harmonics set apart and the amplitude scaled."""
    a = np.zeros((3, 2))
    b = np.zeros((3, 2))
    a[0, 0], a[2, 0], b[0, 1], b[2, 1] = scale, scale * c, scale, -scale * d
    return FourierGait([0.0, 0.0], a, b, f"3rd harmonic {c:+g}/{d:+g} x{scale:g}")


def INSIDE_CANDIDATES() -> list[Gait]:  # noqa: N802 (a constant set, built fresh each call)
    """Thirty-four gaits other than the paper's five, written to lie near the shapes and
    directions the five visit: the paper's third-harmonic family at other weights, with
    the joints' weights apart and scaled by 0.93 and 1.07; circles tilted by +-0.1, 0.15
    rad of lag, squashed by 5 %, offset by 0.07 rad; rounded squares. Fixed, and filtered
    by `inside_support`, before any was scored."""
    out: list[Gait] = [third_harmonic(q, q) for q in (-0.2, -0.15, -0.07, 0.07, 0.15, 0.2)]
    pairs = ((0.25, 0.11), (0.11, 0.25), (-0.25, -0.11), (-0.11, -0.25))
    pairs += ((0.25, 0.0), (0.0, 0.25), (-0.25, 0.0), (0.0, -0.25))
    out += [third_harmonic(c, d) for c, d in pairs]
    out += [third_harmonic(q, q, s) for q in (-0.25, 0.0, 0.25) for s in (0.93, 1.07)]
    out += [
        ellipse(1.0, 1.0, h, name=f"ellipse 1.0, shift {h:+g}") for h in (-0.15, -0.1, 0.1, 0.15)
    ]
    out += [
        ellipse(a1, a2, name=f"ellipse {a1:g} x {a2:g}") for a1, a2 in ((1.05, 0.95), (0.95, 1.05))
    ]
    offsets = ((0.07, 0.0), (-0.07, 0.0), (0.0, 0.07), (0.0, -0.07))
    out += [
        ellipse(1.0, 1.0, 0, c1, c2, name=f"circle 1.0 offset ({c1:+g}, {c2:+g})")
        for c1, c2 in offsets
    ]
    out += [
        rounded_square(r, p, f"rounded square {r:g}, p {p:g}")
        for r, p in ((1.0, 0.8), (1.0, 0.7), (0.95, 0.6), (1.0, 0.5))
    ]
    return out


def inside_support(gaits, support: Support, radius: float = SHAPE_RADIUS) -> list[Gait]:
    """The gaits whose every sample lies within ``radius`` rad of a training sample in the
    (shape, direction of shape velocity) metric (`Support.gait_distance`): the issue's
    "inside the data's support", with the support's own radius."""
    return [g for g in gaits if support.gait_distance(g) <= radius]


def default_dataset_samples(work: Path, seed: int = 0) -> pd.DataFrame:
    """Samples of the default design (`suds-exp simulate` then `suds-exp preprocess`
    with defaults), built in ``work``."""
    from suds_exp.ingest import ingest_paths
    from suds_exp.preprocess import get_version, preprocess
    from suds_exp.sim import simulate_dataset
    from suds_exp.store import Store

    ds = simulate_dataset(Path(work) / "data", seed=seed)
    store = Store(Path(work) / "default.duckdb")
    ingest_paths(store, [], ds.manifest, progress=False)
    return get_version(store, preprocess(store, progress=False).name).samples()
