"""Prediction of unseen gaits: a learned map against the simulator, forward displacement
per cycle at 1/2 Hz.

Simulates the default dataset (`suds-exp simulate`'s default design: the paper's five
gaits x 1/3, 1/2, 1 Hz x 4 repeats, 10-30 cycles, seed --seed), ingests and preprocesses it
(default version), fits the learner (--learner, default GMR) on all of it, and predicts the
net motion per cycle of `UNSEEN`, twelve gaits that are not among the five but lie in the
annulus of shapes they visit (circles, ellipses, phase-shifted ellipses, offset circles,
rounded squares); the simulator runs each the same way (`suds_exp.gait.truth`, gait
followed exactly, mean of cycles 3-5). Prints each gait's simulated and predicted forward
displacement, the median relative error over the set and Spearman's rank correlation.
The paper's five are printed too, for scale (they are training gaits, not in the scores).

Run: .venv/bin/python benchmarks/gait_predict.py [--learner GMR] [--seed 0]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from suds_exp.gait.predict import predict_gaits  # noqa: E402
from suds_exp.gait.shape import paper_gaits  # noqa: E402
from suds_exp.gait.testing import UNSEEN, default_dataset_samples  # noqa: E402
from suds_exp.gait.truth import simulate_forward  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--learner", default="GMR")
    ap.add_argument("--seed", type=int, default=0, help="dataset seed")
    args = ap.parse_args()
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="suds-gait-predict-") as tmp:
        samples = default_dataset_samples(Path(tmp), args.seed)
    gaits = paper_gaits() + UNSEEN()
    truth = simulate_forward(gaits, 0.5)
    pred = np.array([p.motion.forward_mm for p in predict_gaits(samples, gaits, 0.5, args.learner)])
    print(f"| gait | simulator (mm/cycle) | {args.learner} (mm/cycle) | error |")
    print("|---|---|---|---|")
    for g, a, b in zip(gaits, truth, pred, strict=True):
        print(f"| {g.name} | {a:.1f} | {b:.1f} | {100 * (b - a) / a:+.0f} % |")
    unseen = slice(len(paper_gaits()), None)
    err = np.abs(pred[unseen] - truth[unseen]) / np.abs(truth[unseen])
    rho = spearmanr(pred[unseen], truth[unseen])[0]
    print(
        f"unseen gaits ({len(err)}): median relative error {100 * np.median(err):.1f} %, "
        f"Spearman {rho:.2f} ({time.perf_counter() - started:.0f} s)"
    )


if __name__ == "__main__":
    main()
