"""A real crawling C. elegans end to end: Worm Tracker 2 features file -> ingest -> chain
-> preprocess -> comparison with the tracker's own features -> learners on later cycles.

Usage::

    .venv/bin/python examples/worm.py [FEATURES.mat] [TRAIN_CYCLES] [STEP]

FEATURES.mat defaults to ``refdata/worm_schafer_wt2/short_worm_features.mat`` in
``../shared`` (or in the folder ``SUDS_SHARED`` names);
TRAIN_CYCLES (default: two thirds of the complete cycles) is how many phase cycles the
learners train on, the later ones test; STEP (default 4) takes every STEP-th skeleton
point into the chain. Prints the shape modes' explained variance, our
phase rate, forward speed and waves along the body beside the tracker's, and the
held-out errors (RMS of vx as % of the test RMS of vx).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from suds_exp.body.worm import POINT_STEP, run_worm  # noqa: E402

HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("SUDS_SHARED") or HERE.parents[1] / "shared")
DEFAULT = SHARED / "refdata" / "worm_schafer_wt2" / "short_worm_features.mat"


def main() -> None:
    features = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT
    train = int(sys.argv[2]) if len(sys.argv) > 2 and sys.argv[2] != "-" else None
    step = int(sys.argv[3]) if len(sys.argv) > 3 else POINT_STEP
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        out = run_worm(features, Path(tmp) / "worm.duckdb", train_cycles=train, step=step)
    ref = out["reference"]
    ev = ", ".join(f"{100 * r:.1f}%" for r in out["explained_variance_ratio"])
    print(f"chain of every {step}th skeleton point")
    print(f"{out['n_samples']} samples, {out['n_cycles']} complete cycles; shape modes {ev}")
    rows = [
        ("phase rate / bend frequency (Hz)", out["phase_rate_hz"][0], ref["bend_frequency_hz"]),
        ("forward speed (mm/s)", out["forward_speed_mm_s"], ref["speed_mm_s"]),
        ("waves along the body", out["waves_per_body_length"], ref["waves_along_body"]),
    ]
    print(f"{'':34s} {'ours':>8s} {'tracker':>8s} {'diff':>7s}")
    for label, ours, theirs in rows:
        print(f"{label:34s} {ours:8.3f} {theirs:8.3f} {100 * (ours / theirs - 1):+6.1f}%")
    print(
        f"(waves between the first and last chord angles: {out['waves_along_body']:.3f}; "
        f"tracker: median signed bend frequency {ref['bend_frequency_signed_hz']:.3f} Hz)"
    )
    print(f"learners: train on cycles 1-{out['train_cycles']}, test on the later ones")
    print(out["errors"].round(1).to_string(index=False))
    print("in sample (fitted and scored on every cycle)")
    print(out["in_sample"].round(1).to_string(index=False))
    print(f"{time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
