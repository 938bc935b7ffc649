"""Which recordings teach GMR the map goal's unseen gaits: its error on them
(`suds_exp.plan.unseen_gaits`, RMS distance of predicted from simulated net displacement
per cycle, mm) learned from subsets of one balanced recording.

The recording: every paper gait at every paper frequency, two repeats of 10 cycles each
(dataset seed --seed; 300 cycles). The subsets: the three gaits whose paths lie nearest
the unseen gaits (O, D-, S-) against all five, at 1/2 Hz (the target's frequency) or at
all three frequencies, one repeat or two.

Run: .venv/bin/python -m benchmarks.studies.map_subsets [--seed 0] [--out /tmp/map_subsets]
"""

from __future__ import annotations

import atexit
import shutil
import tempfile
from pathlib import Path

import numpy as np

from benchmarks._harness import script_parser
from suds_exp.gait.predict import fit_map
from suds_exp.ingest import ingest_paths
from suds_exp.plan import Target, TargetTruth
from suds_exp.preprocess import get_version, preprocess
from suds_exp.robot import GAITS
from suds_exp.sim import SimConfig, simulate_dataset
from suds_exp.sim.dataset import draw_trial, trial_seed
from suds_exp.store import Store

FREQS = (1 / 3, 0.5, 1.0)
NEAR = ["O", "D-", "S-"]


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0], "a smoke run: 4-cycle trials, 1 repeat")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=Path("/tmp/map_subsets"))
    args = ap.parse_args(argv)
    cycles, repeats = (10, 10), (1, 2)
    if args.quick:
        cycles, repeats = (4, 4), (1,)
        args.out = Path(tempfile.mkdtemp(prefix="suds-map-subsets-quick-"))
        atexit.register(shutil.rmtree, args.out, True)
    args.out.mkdir(parents=True, exist_ok=True)
    store = Store(args.out / "subsets.duckdb")
    if not store.path.exists():
        specs = [
            draw_trial(g, f, r, trial_seed(args.seed, g, f, r), cycles)
            for g in GAITS
            for f in FREQS
            for r in repeats
        ]
        ds = simulate_dataset(args.out / "data", SimConfig(), specs=specs)
        ingest_paths(store, [], manifest=ds.manifest, progress=False)
        preprocess(store, progress=False)
    s = get_version(store).samples()
    truth = TargetTruth(Target())
    first = s["trial_id"].isin(s.groupby(["gait", "frequency_hz"])["trial_id"].min())
    half = np.isclose(s["frequency_hz"], 0.5)
    near = s["gait"].isin(NEAR)
    every = np.ones(len(s), bool)
    for mask, label in (
        (half & first & near, "O, D-, S- at 1/2 Hz, 1 repeat"),
        (half & near, "O, D-, S- at 1/2 Hz, 2 repeats"),
        (first & near, "O, D-, S- at 3 frequencies, 1 repeat"),
        (half & first, "5 gaits at 1/2 Hz, 1 repeat"),
        (half, "5 gaits at 1/2 Hz, 2 repeats"),
        (first, "15 conditions, 1 repeat"),
        (every, "15 conditions, 2 repeats"),
    ):
        part = s[mask]
        cycles = part.groupby("trial_id")["cycle"].nunique().sum()
        error = truth.map_error(fit_map(part))
        print(f"{label:40s} {cycles:4d} cycles  error {error:.3f} mm", flush=True)


if __name__ == "__main__":
    main()
