"""Fixtures shared by the gait tests and benchmarks: the set of unseen gaits, and the
default dataset (simulated, ingested, preprocessed) as samples."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.gait.shape import TWO_PI, Gait, SampledGait, ellipse


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
