"""Segment origins fitted from trials that may not pin them down, against the simulator's truth.

For each design (one gait alone, two gaits, every gait; dataset seeds), simulate, ingest
and preprocess twice: with the motor axes' distance fitted (the default, reporting the
fit's `noise_shift` and whether `preprocess` warned) and given as the simulated robot's
100 mm (``joint_distance_mm``). Prints one Markdown row per design and seed: the noise
shift (mm), the fitted distance (mm), the r_a error (rad) and the vx error (% of RMS vx)
against the truth files, both ways.

Run: ``python -m benchmarks.studies.joint_distance [--seeds 0,1]``; ``--quick`` runs one
design.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

from benchmarks._harness import script_parser
from suds_exp.preprocess import preprocess
from suds_exp.preprocess.truth import truth_errors
from suds_exp.robot import GAITS
from suds_exp.sim.config import SimConfig
from suds_exp.sim.dataset import SimDesign
from suds_exp.store import Store
from suds_exp.workflows.simulate import simulate_and_ingest

ONE = {"repeats": 1, "cycles": (4, 4)}
DESIGNS: dict[str, dict] = {
    **{g: {"gaits": (g,), **ONE} for g in GAITS},
    "O x2, 12-16 cycles": {"gaits": ("O",), "repeats": 2, "cycles": (12, 16)},
    "O, D+": {"gaits": ("O", "D+"), **ONE},
    "O, S-": {"gaits": ("O", "S-"), **ONE},
    "every gait": ONE,
    "the default design": {},
}


def row(folder: Path, name: str, design: dict, seed: int) -> str:
    store = Store(folder / "db.duckdb")
    simulate_and_ingest(store, folder / "data", design=SimDesign(seed=seed, **design))
    fitted = preprocess(store, name="fitted", progress=False)
    truth = SimConfig().geometry.middle_length_mm
    known = preprocess(store, name="known", params={"joint_distance_mm": truth}, progress=False)
    state = json.loads(
        store.query_df(
            "SELECT f.state FROM prep_fits f JOIN prep_versions v ON v.id = f.version_id "
            "WHERE v.name = 'fitted' AND f.kind = 'joints'"
        ).state.iloc[0]
    )
    cells = [name, str(seed), f"{state['noise_shift_mm']:.2f}", f"{state['length_mm']:.2f}"]
    for result in (fitted, known):
        e = truth_errors(store, result.version_id).set_index("trial_id").loc[-1]
        cells += [f"{e.err_ra:.4f}", f"{100 * e.err_vx / e.rms_vx_true:.2f}"]
    cells.append("yes" if fitted.warnings else "no")
    return "| " + " | ".join(cells) + " |"


def main(argv=None) -> None:
    ap = script_parser(__doc__.split("\n\n")[0], "a smoke run: gait O, seed 0")
    ap.add_argument("--seeds", default="0,1", help="dataset seeds, comma-separated")
    args = ap.parse_args(argv)
    designs = {"O": DESIGNS["O"]} if args.quick else DESIGNS
    seeds = [0] if args.quick else [int(s) for s in args.seeds.split(",")]
    print(
        "| trials | seed | noise shift (mm) | fitted distance (mm) | r_a error, fitted (rad) "
        "| vx error, fitted (%) | r_a error, 100 mm given (rad) | vx error, given (%) "
        "| warned |\n|---|---:|---:|---:|---:|---:|---:|---:|---|"
    )
    for seed in seeds:
        for name, design in designs.items():
            with tempfile.TemporaryDirectory(prefix="suds-joints-") as tmp:
                print(row(Path(tmp), name, design, seed), flush=True)


if __name__ == "__main__":
    main()
