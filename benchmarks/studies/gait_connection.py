"""Learned connection against the simulator's own, on flippers-locked simulated data.

Simulates the default design (5 gaits x 3 frequencies x 4 repeats, 10-30 cycles) with
``flippers=locked`` and, with ``--extra``, the same design of extra gaits given as gait
files (`simulate --gait-file`): two "flowers" (phi = (1 + 0.3 cos(n theta)) (cos theta,
sin theta), n = 5, 7) and ellipses of amplitude 1.1 phase-shifted by +-0.6 rad, which cross
the paper's annulus of shapes in other directions. Ingests and preprocesses all, fits
GMR on the paper's five gaits alone and on all gaits, and prints the normalised RMS
difference of the learned connection from `suds-exp connection`'s (least squares over 8
directions, flippers locked) inside the support (shapes within 0.1 rad of a training
shape), per row of A and their mean, and how far the learned map itself is from the
simulator's quasi-static body velocity at the training samples' own shapes and directions
of shape velocity. Draws both (--out).

Why the extra gaits: the paper's five gaits all circle the origin in one sense, so at any
shape the data hold one direction of shape velocity (the five cross at shallow angles);
the second column of A is then an extrapolation of the learner, not a measurement.

Run: .venv/bin/python -m benchmarks.studies.gait_connection [--extra]
    [--out reports/gait-connection] [--quick]
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks._data import QUICK_DESIGN
from benchmarks._harness import script_parser
from suds_exp.gait.connection import compare_connections, learned_connection
from suds_exp.gait.plots import draw_connection
from suds_exp.gait.predict import decimate, fit_map
from suds_exp.gait.shape import TWO_PI, SampledGait, ellipse, paper_gaits
from suds_exp.gait.trials import simulate_gait_file
from suds_exp.ingest import ingest_paths
from suds_exp.preprocess import get_version, preprocess
from suds_exp.sim import SimConfig, local_connection, set_effect, simulate_dataset
from suds_exp.sim.connection import body_twists, robot_config
from suds_exp.store import Store


def flower(petals: int, name: str) -> SampledGait:
    theta = TWO_PI * np.arange(400) / 400
    r = 1.0 + 0.3 * np.cos(petals * theta)
    return SampledGait(theta, np.c_[r * np.cos(theta), r * np.sin(theta)], name)


def extra_gaits() -> list:
    return [
        flower(5, "flower5.csv"),
        flower(7, "flower7.csv"),
        ellipse(1.1, 1.1, 0.6, name="ellipse+0.6.toml"),
        ellipse(1.1, 1.1, -0.6, name="ellipse-0.6.toml"),
    ]


class QuasiStatic:
    """The simulator's quasi-static body velocity (flippers locked) as a fitted map's
    ``predict``: v_b for each row's (r_a, dr_a/dt), so `learned_connection` can fit the
    simulator from exactly the directions it fits the learner from."""

    def __init__(self, config):
        self.config = config

    def predict(self, frame):
        ra = frame[["ra_1", "ra_2"]].to_numpy(float)
        dra = frame[["dra_1", "dra_2"]].to_numpy(float)
        speed = np.linalg.norm(dra, axis=1, keepdims=True)
        xi, _ = body_twists(self.config, ra, dra / speed)
        return frame.assign(
            vx=xi[:, 0] * speed[:, 0], vy=xi[:, 1] * speed[:, 0], wz=xi[:, 2] * speed[:, 0]
        )


def at_data_directions(model, samples, n: int = 2000, seed: int = 0) -> np.ndarray:
    """Normalised RMS difference (vx, vy, wz) of the learned map from the simulator's
    quasi-static body velocity (flippers locked) at n training samples' own shape and
    direction of shape velocity, per unit shape speed: the map where it has data."""
    rng = np.random.default_rng(seed)
    rows = samples.iloc[rng.choice(len(samples), size=min(n, len(samples)), replace=False)]
    ra = rows[["ra_1", "ra_2"]].to_numpy(float)
    dra = rows[["dra_1", "dra_2"]].to_numpy(float)
    unit = dra / np.linalg.norm(dra, axis=1, keepdims=True)
    sim, _ = body_twists(robot_config(SimConfig()), ra, unit)
    speed = float(np.median(np.linalg.norm(samples[["dra_1", "dra_2"]].to_numpy(float), axis=1)))
    ask = rows.assign(dra_1=unit[:, 0] * speed, dra_2=unit[:, 1] * speed)
    ask = ask.assign(trial_id=np.arange(len(ask)) + 1)
    learned = model.predict(ask)[["vx", "vy", "wz"]].to_numpy(float) / speed
    return np.sqrt(((learned - sim) ** 2).mean(0)) / np.sqrt((sim**2).mean(0))


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--extra", action="store_true", help="add the extra gaits")
    ap.add_argument("--grid", type=int, default=41)
    ap.add_argument("--range", type=float, default=2.0, dest="half_range")
    ap.add_argument("--out", type=Path, default=Path("reports/gait-connection"))
    args = ap.parse_args(argv)
    design = {}
    if args.quick:
        args.extra, args.grid, design = False, 9, QUICK_DESIGN
        args.out = Path(tempfile.mkdtemp(prefix="suds-gait-conn-quick-"))
    started = time.perf_counter()
    cfg = set_effect(SimConfig(), "flippers=locked")
    with tempfile.TemporaryDirectory(prefix="suds-gait-conn-") as tmp:
        store = Store(Path(tmp) / "locked.duckdb")
        ds = simulate_dataset(Path(tmp) / "paper", cfg, **design)
        ingest_paths(store, [], ds.manifest, progress=False)
        if args.extra:
            for g in extra_gaits():
                simulate_gait_file(
                    Path(tmp) / g.name, g, cfg, (1 / 3, 0.5, 1.0), 4, (10, 30), 0, store
                )
        version = get_version(store, preprocess(store, progress=False).name)
        samples = version.samples()
    reference = local_connection(args.grid, args.half_range, "robot", SimConfig()).A
    sets = {"paper's five": samples[samples["gait"].isin([g.name for g in paper_gaits()])]}
    if args.extra:
        sets["five + extra"] = samples
    args.out.mkdir(parents=True, exist_ok=True)
    print(
        "| training gaits | samples | directions fitted | spread >= | shapes | vx | vy | wz | mean "
        "| simulator fitted the same way: vx, vy, wz, mean |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    oracle = QuasiStatic(robot_config(SimConfig()))
    for label, s in sets.items():
        fitted = fit_map(s, "GMR")
        d = decimate(s)
        for directions in ("uniform", "visited"):
            conn = learned_connection(
                fitted.model, d, args.grid, args.half_range, directions=directions
            )
            sim = learned_connection(oracle, d, args.grid, args.half_range, directions=directions)
            for least in (0.0, 0.05, 0.15) if directions == "visited" else (0.0,):
                n = compare_connections(conn, reference, min_spread=least)
                o = compare_connections(sim, reference, min_spread=least)
                print(
                    f"| {label} | {len(s)} | {directions} | {least} | {n['n_inside']} "
                    f"| {n['vx']:.2f} | {n['vy']:.2f} | {n['wz']:.2f} | {n['mean']:.2f} "
                    f"| {o['vx']:.2f}, {o['vy']:.2f}, {o['wz']:.2f}, {o['mean']:.2f} |",
                    flush=True,
                )
            name = "paper" if label.startswith("paper") else "extra"
            gaits = paper_gaits() + (extra_gaits() if name == "extra" else [])
            draw_connection(
                conn, args.out / f"connection-{name}-{directions}.png", reference, gaits
            )
        a = at_data_directions(fitted.model, d)
        print(f"{label}: map at the data's own directions: {a[0]:.2f}, {a[1]:.2f}, {a[2]:.2f}")
    print(f"({time.perf_counter() - started:.0f} s; figures in {args.out})")


if __name__ == "__main__":
    main()
