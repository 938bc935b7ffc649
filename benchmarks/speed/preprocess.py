"""Preprocessing benchmark: time of `preprocess` on the default simulated dataset, and its
errors against the simulator's truth.

Usage::

    .venv/bin/python -m benchmarks.speed.preprocess [--db FILE] [--repeats 3] [--json] [--body FILE]

Data: the default design of `suds-exp simulate` (5 gaits x 3 frequencies x 4 repeats,
10-30 cycles, seed 0: 60 trials, about 240k frames at 100 Hz), simulated into a temporary
folder and ingested unless ``--db`` names a database that already holds it (its trials'
truth files must sit beside their captures). Each repeat preprocesses a fresh copy of the
ingested database with the default parameters (read markers, clean, fit, write samples).
Figures:

- seconds: median wall time of `preprocess` over ``--repeats`` runs (and each run);
  target < 30 s. The machine is shared: the load average is printed beside it.
- explained variance of the 4 passive principal components;
- errors against the truth (pooled RMS over all frames): body velocity vx, vy (mm/s)
  and wz (rad/s) as a percentage of the RMS of the true vx, both against the raw truth
  and against the truth pose passed through the same differentiator (``*_band``);
  r_a (rad); phase vs the commanded phase after one offset per trial (rad).

``--quick``: one run on 8 trials of 4 cycles (O and D+ at 0.5 and 1 Hz, 2 repeats), a
smoke run whose figures mean nothing.
"""

from __future__ import annotations

import json
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from benchmarks._harness import script_parser
from suds_exp.body import load_body, preprocess_body
from suds_exp.commands.simulate import simulate_command
from suds_exp.preprocess import preprocess
from suds_exp.preprocess.truth import truth_errors
from suds_exp.sim.dataset import SimDesign
from suds_exp.store import Store

#: ``--quick``'s design (keywords of `SimDesign`).
QUICK_DESIGN = {"gaits": ("O", "D+"), "frequencies_hz": (0.5, 1.0), "repeats": 2, "cycles": (4, 4)}


def main(argv=None) -> None:
    parser = script_parser(__doc__.split("\n\n")[0])
    parser.add_argument("--db", type=Path, help="Database already holding the dataset.")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--json", action="store_true")
    parser.add_argument(
        "--body", help="Preprocess through this body description (e.g. swimmer) instead."
    )
    args = parser.parse_args(argv)
    design = {}
    if args.quick:
        args.repeats, design = 1, QUICK_DESIGN

    with tempfile.TemporaryDirectory(prefix="suds-prep-bench-") as tmp:
        tmp = Path(tmp)
        source = args.db
        if source is None:
            source = tmp / "source.duckdb"
            t0 = time.perf_counter()
            simulate_command(tmp / "data", store=Store(source), design=SimDesign(seed=0, **design))
            print(f"simulated and ingested in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        runs, result, copy = [], None, None
        for i in range(args.repeats):
            copy = tmp / f"run{i}.duckdb"
            shutil.copyfile(source, copy)
            store = Store(copy)
            started = time.perf_counter()
            if args.body:
                result = preprocess_body(store, load_body(args.body), progress=False)
            else:
                result = preprocess(store, progress=False)
            runs.append(time.perf_counter() - started)
        errors = truth_errors(Store(copy), result.version_id).set_index("trial_id").loc[-1]
    rms_vx = float(errors.rms_vx_true)
    figures = {
        "n_trials": len(result.processed),
        "n_frames": result.n_samples,
        "seconds_median": statistics.median(runs),
        "seconds_runs": runs,
        "load_average": os.getloadavg()[0],
        "explained_variance_ratio": result.explained_variance_ratio,
        "explained_variance_kept": sum(result.explained_variance_ratio),
        "rms_vx_true_mm_s": rms_vx,
        **{
            f"{c}_pct_of_rms_vx": 100 * float(errors[c]) / rms_vx
            for c in ("err_vx", "err_vy", "err_wz", "err_vx_band", "err_vy_band", "err_wz_band")
        },
        "err_ra_rad": float(errors.err_ra),
        "err_phase_rad": float(errors.err_phase),
    }
    if args.json:
        print(json.dumps(figures))
        return
    print(
        f"preprocess: {figures['n_trials']} trials, {figures['n_frames']} frames in "
        f"{figures['seconds_median']:.1f} s median of {args.repeats} "
        f"({', '.join(f'{s:.1f}' for s in runs)}; load {figures['load_average']:.1f}); "
        "target < 30 s"
    )
    ev = ", ".join(f"{100 * r:.1f}%" for r in figures["explained_variance_ratio"])
    print(f"passive PCs: {ev} (total {100 * figures['explained_variance_kept']:.1f}%)")
    pct = {c: figures[f"{c}_pct_of_rms_vx"] for c in ("err_vx", "err_vy", "err_wz")}
    band = {c: figures[f"{c}_band_pct_of_rms_vx"] for c in ("err_vx", "err_vy", "err_wz")}
    print(
        f"body velocity error, % of RMS vx ({rms_vx:.1f} mm/s), target <= 5: raw truth "
        f"vx {pct['err_vx']:.2f}, vy {pct['err_vy']:.2f}, wz {pct['err_wz']:.2f}; "
        f"band-limited truth vx {band['err_vx']:.2f}, vy {band['err_vy']:.2f}, "
        f"wz {band['err_wz']:.2f}"
    )
    print(
        f"r_a error {figures['err_ra_rad']:.4f} rad (target <= 0.01); phase error "
        f"{figures['err_phase_rad']:.4f} rad (target <= 0.05)"
    )


if __name__ == "__main__":
    main()
