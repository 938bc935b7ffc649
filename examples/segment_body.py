"""A described body of rigid links against known truth: generate, ingest, preprocess.

Usage::

    .venv/bin/python examples/segment_body.py [N_SEGMENTS] [PASSIVE_JOINT ...]

Builds a chain of N_SEGMENTS links (default 4) with the given joints passive (default
2), moves it with the kinematic generator (known joint angles and body path; 0.1 mm
noise, two gaps per marker), ingests the markers, preprocesses them through the body's
description and prints the recovery errors: each actuated joint angle (RMS, rad) and the
body velocity (RMS of the (vx, vy) error over the RMS speed).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from suds_exp.body import preprocess_body  # noqa: E402
from suds_exp.ingest import ingest_paths  # noqa: E402
from suds_exp.preprocess import load_samples  # noqa: E402
from suds_exp.store import Store  # noqa: E402
from suds_exp.testing.kinematic_body import serial_body, write_body_trial  # noqa: E402


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 4
    passive = tuple(int(a) for a in sys.argv[2:]) if len(sys.argv) > 2 else (2,)
    planar = serial_body(n, passive, fin=not passive)
    with tempfile.TemporaryDirectory() as tmp:
        path, truth = write_body_trial(planar, Path(tmp) / "body.csv")
        store = Store(Path(tmp) / "body.duckdb")
        ingest_paths(store, [path], progress=False)
        result = preprocess_body(store, planar.body, progress=False)
        samples = load_samples(store, result.version_id)
    truth = truth.iloc[samples.frame.to_numpy() - 1]
    kinds = ", ".join(f"{j.name} {j.kind}" for j in planar.body.joints)
    print(f"{n} links ({kinds}); k = {result.params['k']}, {len(samples)} samples")
    actuated = [j.name for j in planar.body.joints if j.kind == "actuated"]
    for i, name in enumerate(actuated):
        error = samples[f"ra_{i + 1}"].to_numpy() - truth[name].to_numpy()
        print(f"  {name}: RMS error {np.sqrt(np.mean(error**2)):.4f} rad")
    speed = np.sqrt(np.mean(truth.vx**2 + truth.vy**2))
    error = np.sqrt(np.mean((samples.vx - truth.vx) ** 2 + (samples.vy - truth.vy) ** 2))
    print(f"  body velocity: RMS error {error / speed:.1%} of the RMS speed {speed:.1f} mm/s")


if __name__ == "__main__":
    main()
