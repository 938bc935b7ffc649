"""Prediction of unseen gaits: a learned map against the simulator, forward displacement
per cycle at 1/2 Hz.

Simulates the default dataset (`suds-exp simulate`'s default design: the paper's five
gaits x 1/3, 1/2, 1 Hz x 4 repeats, 10-30 cycles, seed --seed), ingests and preprocesses it
(default version), fits the learner (--learner, default GMR) on all of it, and scores two
sets of gaits that are not among the five (the simulator runs each the same way,
`suds_exp.gait.truth`: gait followed exactly, mean of cycles 3-5):

- `UNSEEN`: twelve gaits in the annulus of shapes the five visit (circles, ellipses,
  phase-shifted ellipses, offset circles, rounded squares), fixed first; each printed
  with its distance from the data (`Support.gait_distance`, rad). Ten of them leave
  the support (distance > `SHAPE_RADIUS`), so this set is not the issue's test.
- `inside_support(INSIDE_CANDIDATES)`: the candidates within `SHAPE_RADIUS` of the data
  in the (shape, direction) metric: the issue's "inside the data's support".

Prints each gait's simulated and predicted forward displacement, the simulator's
cycle-to-cycle spread (max - min over cycles 3-5), the median relative error and
Spearman's rank correlation per set, and with --boot N both figures over N refits on
training trials resampled with replacement (median and 2.5-97.5 percentiles).

Run: .venv/bin/python -m benchmarks.studies.gait_predict [--learner GMR] [--seed 0] [--boot 0]
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

from benchmarks._data import QUICK_DESIGN, simulated_database
from benchmarks._harness import script_parser
from suds_exp.gait.predict import bootstrap_draws, decimate, fit_map
from suds_exp.gait.shape import paper_gaits
from suds_exp.gait.support import Support
from suds_exp.gait.testing import (
    INSIDE_CANDIDATES,
    UNSEEN,
    default_dataset_samples,
    inside_support,
)
from suds_exp.gait.truth import simulate_gaits
from suds_exp.preprocess import get_version
from suds_exp.store import Store


def scores(pred: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """(median relative error, Spearman) of predictions against the simulator."""
    return float(np.median(np.abs(pred - truth) / np.abs(truth))), float(spearmanr(pred, truth)[0])


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--learner", default="GMR")
    ap.add_argument("--seed", type=int, default=0, help="dataset seed")
    ap.add_argument("--boot", type=int, default=0, help="refits on resampled trials")
    args = ap.parse_args(argv)
    started, cpu = time.perf_counter(), time.process_time()
    with tempfile.TemporaryDirectory(prefix="suds-gait-predict-") as tmp:
        if args.quick:
            db = Path(tmp) / "quick.duckdb"
            name = simulated_database(db, QUICK_DESIGN, args.seed)
            samples = get_version(Store(db), name).samples()
        else:
            samples = default_dataset_samples(Path(tmp), args.seed)
    support = Support.of(decimate(samples))
    inside = inside_support(INSIDE_CANDIDATES(), support)
    sets = {"paper's five (training)": paper_gaits(), "UNSEEN": UNSEEN(), "inside support": inside}
    fitted = fit_map(samples, args.learner)
    print(
        f"| set | gait | distance from data (rad) | simulator (mm/cycle) | cycle spread (mm) "
        f"| {args.learner} (mm/cycle) | error |"
    )
    print("|---|---|---|---|---|---|---|")
    truths = {}
    for label, gaits in sets.items():
        sim = simulate_gaits(gaits, 0.5)
        truths[label] = np.array([m.forward_mm for m in sim])
        for g, m in zip(gaits, sim, strict=True):
            p = fitted.forward(g, 0.5)
            spread = np.ptp(m.per_cycle[:, 0])
            print(
                f"| {label} | {g.name} | {support.gait_distance(g):.3f} | {m.forward_mm:.1f} "
                f"| {spread:.2f} | {p:.1f} | {100 * (p - m.forward_mm) / m.forward_mm:+.0f} % |"
            )
    scored = ("UNSEEN", "inside support")
    fits = [fitted] + [
        fit_map(f, args.learner) for f in bootstrap_draws(samples, args.boot, args.seed)
    ]
    for label in scored:
        per_fit = np.array(
            [
                scores(np.array([f.forward(g, 0.5) for g in sets[label]]), truths[label])
                for f in fits
            ]
        )
        err, rho = per_fit[0]
        line = f"{label} ({len(sets[label])} gaits): median relative error {100 * err:.1f} %, "
        line += f"Spearman {rho:.2f}"
        if args.boot:
            (e_lo, e_md, e_hi), (r_lo, r_md, r_hi) = np.percentile(
                per_fit[1:], [2.5, 50, 97.5], axis=0
            ).T
            line += f"; over {args.boot} resampled fits: error {100 * e_md:.1f} % "
            line += f"[{100 * e_lo:.1f}, {100 * e_hi:.1f}], Spearman {r_md:.2f} "
            line += f"[{r_lo:.2f}, {r_hi:.2f}]"
        print(line, flush=True)
    print(f"({time.perf_counter() - started:.0f} s wall, {time.process_time() - cpu:.0f} s CPU)")


if __name__ == "__main__":
    main()
