"""Someone else's model as the measurement: Hatton's granular connection of the classic
three-link swimmer drives the "measured" body, our simulator is the model.

Each trial's actuated shape comes from our actuator (same design, gaits and seeds as the
discrepancy benchmark); the body velocity is the published connection's,
xi = T(alpha) alpha_dot, read raw as the shared notes describe (no minus sign; link 1 at
the -x end, so alpha1 = phi2 (tail joint) and alpha2 = phi1 (head joint); translations per
unit link length, scaled here by our middle segment's length; grid labels x 1.142, the
notes' probable relabelling). The pose is integrated from xi; the flipper hinge angles
(the published model has no flippers) are our nominal simulator's for the same drive.
Markers -> measurement noise -> QTM files -> ingest -> preprocess -> the workflow from
the nominal model, discovery on.

    .venv/bin/python -m benchmarks.studies.discrepancy_hatton --out hatton-run

Needs ../shared/refdata/hatton_granular_three_link_connection.mat (or --table).
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.interpolate import RegularGridInterpolator
from scipy.io import loadmat

from benchmarks._harness import ROOT, script_parser
from suds_exp.discrepancy import DiscrepancyOptions, run_discrepancy
from suds_exp.sim.config import SimConfig
from suds_exp.sim.dataset import plan_trials, simulate_trials, truth_markers
from suds_exp.sim.files import write_manifest, write_qtm_tsv
from suds_exp.sim.markers import MARKER_NAMES, measure

#: The table in the reference data, ../shared beside the repository or $SUDS_SHARED.
SHARED = Path(os.environ.get("SUDS_SHARED") or ROOT.parent / "shared")
TABLE = SHARED / "refdata" / "hatton_granular_three_link_connection.mat"
#: The notes' probable relabelling of the table's grid (true angle = label x 1.142).
GRID_SCALE = 1.142
DESIGN = dict(gaits=("S+", "O", "D+"), frequencies_hz=(1 / 3, 0.5, 1.0), repeats=4, cycles=(4, 6))
#: ``--quick``'s design (a smoke run).
QUICK_DESIGN = dict(gaits=("O", "D+"), frequencies_hz=(0.5, 1.0), repeats=2, cycles=(3, 3))


def connection(path: Path):
    """(alpha1, alpha2) rad -> T (3, 2): body velocity per unit shape rate, raw sign."""
    m = loadmat(path)
    a1 = m["alpha1"][:, 0] * GRID_SCALE
    a2 = m["alpha2"][0, :] * GRID_SCALE
    rows = [("Ax1", "Ax2"), ("Ay1", "Ay2"), ("Atheta1", "Atheta2")]
    stack = np.stack([np.stack([m[a], m[b]], axis=-1) for a, b in rows], axis=-2)
    return RegularGridInterpolator((a1, a2), stack, bounds_error=False, fill_value=None)


def hatton_truth(truth: dict, T, link_mm: float) -> dict:
    """Replace the body motion of a simulated trial by the connection's."""
    t = np.asarray(truth["t"])
    alpha = np.column_stack([truth["phi2"], truth["phi1"]])
    dt = float(np.median(np.diff(t)))
    alpha_dot = np.gradient(alpha, dt, axis=0)
    xi = np.einsum("nij,nj->ni", T(alpha), alpha_dot)
    xi[:, :2] *= link_mm
    theta = truth["theta"][0] + np.concatenate(
        [[0.0], np.cumsum(0.5 * (xi[1:, 2] + xi[:-1, 2]) * dt)]
    )
    c, s = np.cos(theta), np.sin(theta)
    wx, wy = c * xi[:, 0] - s * xi[:, 1], s * xi[:, 0] + c * xi[:, 1]
    out = dict(truth)
    out["theta"] = theta
    out["x"] = truth["x"][0] + np.concatenate([[0.0], np.cumsum(0.5 * (wx[1:] + wx[:-1]) * dt)])
    out["y"] = truth["y"][0] + np.concatenate([[0.0], np.cumsum(0.5 * (wy[1:] + wy[:-1]) * dt)])
    out["vx"], out["vy"], out["wz"] = xi[:, 0], xi[:, 1], xi[:, 2]
    return out


def make_dataset(work: Path, table: Path, seed: int, design: dict = DESIGN):
    """Write the Hatton-driven capture files, ingest and preprocess them; return the store."""
    from suds_exp.ingest import ingest_paths
    from suds_exp.preprocess import preprocess
    from suds_exp.store import Store

    cfg = SimConfig()
    data = work / "data"
    data.mkdir(parents=True, exist_ok=True)
    T = connection(table)
    specs = plan_trials(
        design["gaits"], design["frequencies_hz"], design["repeats"], design["cycles"], seed
    )
    rows = []
    for spec, truth in zip(specs, simulate_trials(specs, cfg), strict=True):
        ours = hatton_truth(truth, T, cfg.geometry.middle_length_mm)
        rng = np.random.default_rng(np.random.SeedSequence(spec.seed + (2,)))
        tsv = data / f"{spec.name}.tsv"
        write_qtm_tsv(
            tsv,
            measure(cfg, truth_markers(ours, cfg), rng),
            MARKER_NAMES,
            cfg.measurement.sample_rate_hz,
            # distinct session clocks, one minute apart (ingest keys trials by them)
            _dt.datetime(2026, 1, 1, 9, 0, 0) + _dt.timedelta(minutes=len(rows)),
        )
        rows.append(
            {
                "file": tsv.name,
                "gait": spec.gait,
                "frequency_hz": f"{spec.frequency_hz:.6f}",
                "repeat": spec.repeat,
                "notes": "Hatton granular connection body, nominal flippers",
            }
        )
    write_manifest(data / "manifest.csv", rows)
    store = Store(work / "suds.duckdb")
    ingest_paths(store, [data], data / "manifest.csv", None, progress=False)
    preprocess(store, "v1", progress=False)
    return store


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0], "a smoke run on a tiny design")
    ap.add_argument("--out", type=Path, default=Path("hatton-run"))
    ap.add_argument("--table", type=Path, default=TABLE)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-hatton-quick-") as tmp:
            args.out = Path(tmp)
            study(args, QUICK_DESIGN, {"max_effects": 1, "refine": False, "discover": False})
        return
    study(args)


def study(args, design: dict = DESIGN, options: dict | None = None) -> None:
    started = time.perf_counter()
    store = make_dataset(args.out, args.table, args.seed, design)
    res = run_discrepancy(
        store,
        "v1",
        SimConfig(),
        name="hatton",
        options=DiscrepancyOptions(seed=args.seed, **(options or {})),
        out=args.out / "report",
        progress=not args.quick,
    )
    doc = res.to_dict()
    summary = {
        "named": [(n["candidate"], n["value"], n["ci"], n["gap_closed"]) for n in res.named],
        "gap_before": res.gap_before,
        "gap_after_named": res.gap_after,
        "gap_after_correction": res.gap_after_correction,
        "rmse_vx_before_mm_s": doc["rmse_vx_before"],
        "rmse_vx_after_mm_s": doc["rmse_vx_after"],
        "discovery": doc["discovery"],
        "outcome": res.outcome,
        "seconds": time.perf_counter() - started,
    }
    print(json.dumps(summary, indent=1, default=str))


if __name__ == "__main__":
    main()
