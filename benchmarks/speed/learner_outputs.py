"""Record every learner's outputs on a fixed data set, or compare them with a record.

The guard of the speed work: an optimisation must leave each learner's fitted
predictions as they were (bit-identical where the arithmetic is unchanged).

Usage (from the repository root)::

    .venv/bin/python -m benchmarks.speed.learner_outputs --save /tmp/before.npz
    # ... change a learner ...
    .venv/bin/python -m benchmarks.speed.learner_outputs --compare /tmp/before.npz

Data: the closed-form synthetic swimmer (`suds_exp.testing.synthetic_swimmer`,
passive="travel", velocity="finsler", seeds fixed), 30 training cycles of O at 1/2 Hz
(with the training trial split in two so per-trial code paths run), tested on a
different trial of O at 1/2 Hz, of O at 1 Hz and of D+ at 1/2 Hz. Each learner of
`MODELS`, the survey's baselines, the SUDS learners' rollout mode and the A-GBR
variants (dilation, filter, history, BIC) are fitted once; the record holds every
prediction array, keyed by learner and test trial. `--compare` prints, per array, the
largest absolute difference and whether the bits are equal; exit status 1 if any
array differs by more than `--tol` (default 0: bit-identical). ``--quick``: phase-only and
TLS recorded into a temporary file and compared with it (a smoke run).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks._data import GMR_VARIANTS, PAPER, SURVEY, swimmer_samples
from suds_exp.models import make_model

CASES = [*PAPER, *GMR_VARIANTS, *SURVEY]


def data():
    """(training frame of two trials, {test name: frame})."""
    train = pd.concat([swimmer_samples(15, "O", 0.5, 11, 1), swimmer_samples(15, "O", 0.5, 12, 2)])
    train = train.reset_index(drop=True)
    tests = {
        "O@0.5": swimmer_samples(10, "O", 0.5, 13, 3),
        "O@1": swimmer_samples(10, "O", 1.0, 14, 4),
        "D+@0.5": swimmer_samples(10, "D+", 0.5, 15, 5),
    }
    return train, tests


def record(cases=CASES) -> dict[str, np.ndarray]:
    """{"learner | test trial": predictions} of each of ``cases``."""
    train, tests = data()
    out = {}
    for name, params in cases:
        m = make_model(name, **params).fit(train)
        label = name + "".join(f" {k}={v}" for k, v in sorted(params.items()))
        for tname, test in tests.items():
            out[f"{label} | {tname}"] = m.predict(test).to_numpy(dtype=float)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--save", help="write the record to this .npz file")
    g.add_argument("--compare", help="compare with the record in this .npz file")
    g.add_argument("--quick", action="store_true", help="a smoke run: record, then compare")
    ap.add_argument("--tol", type=float, default=0.0, help="largest absolute difference allowed")
    a = ap.parse_args(argv)
    if a.quick:
        with tempfile.TemporaryDirectory() as tmp:
            path = str(Path(tmp) / "record.npz")
            np.savez(path, **record(PAPER[:2]))
            return compare(dict(np.load(path)), record(PAPER[:2]), a.tol)
    now = record()
    if a.save:
        np.savez(a.save, **now)
        print(f"recorded {len(now)} prediction arrays in {a.save}")
        return 0
    return compare(dict(np.load(a.compare)), now, a.tol)


def compare(old: dict, now: dict, tol: float) -> int:
    """Print each array's largest difference; 1 if any differs by more than ``tol``."""
    bad = 0
    for key in sorted(set(old) | set(now)):
        if key not in old or key not in now:
            print(f"MISSING {key}")
            bad += 1
            continue
        same = old[key].shape == now[key].shape and np.array_equal(
            old[key].view(np.uint64), now[key].view(np.uint64)
        )
        diff = float(np.nanmax(np.abs(old[key] - now[key]))) if not same else 0.0
        ok = same or diff <= tol
        bad += not ok
        print(f"{'bit-identical' if same else f'max |diff| {diff:.3g}':>22}  {key}")
    print(f"{len(now) - bad} of {len(set(old) | set(now))} arrays within tol={tol}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
