"""Simulator benchmark: speed on the default dataset, and the simulator page's motion tables.

Run: .venv/bin/python -m benchmarks.speed.sim [--runs 3] [--out reports/sim-benchmark]

Prints
- simulated seconds per second per core on the default dataset (5 gaits x 3 frequencies
  x 4 repeats, 10-30 cycles), physics only, median of --runs runs: per CPU second of this
  process (the per-core figure; immune to other jobs on the machine) and per wall-clock
  second (shows the machine's load); then the whole `simulate_dataset` (physics, markers,
  TSV + Parquet writing) once;
- per gait x frequency: mean forward speed (body vx) and RMS of vx, flippers free vs
  locked (same actuated drive);
- net displacement per cycle of each gait at each frequency;
and writes one figure of a simulated trial's path to --out (not in git).

``--quick``: one run on a one-trial design (O at 1 Hz, 2 cycles), the motion tables at 2
cycles, the figure into a temporary folder (a smoke run, no figure to quote).
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks._harness import script_parser, table
from suds_exp.sim import (
    FREQUENCIES_HZ,
    GAITS,
    SimConfig,
    apply_effects,
    plan_trials,
    set_effect,
    simulate_dataset,
    simulate_trials,
    truth_markers,
)

#: ``--quick``'s design: one trial of two cycles.
QUICK_DESIGN = {"gaits": ("O",), "frequencies_hz": (1.0,), "repeats": 1, "cycles": (2, 2)}


def speed(runs: int, effects: list[str] = (), design: dict | None = None) -> None:
    """Physics and `simulate_dataset` speed on the default dataset (or ``design``, the
    keywords of `plan_trials`)."""
    design = design or {}
    cfg = apply_effects(SimConfig(), effects, param="--set")
    specs = plan_trials(**design)
    simulate_trials(specs[:1], cfg)  # compile / load the numba cache
    cpu, wall = [], []
    robot_s = 0.0
    for _ in range(runs):
        w0, c0 = time.perf_counter(), time.process_time()
        truths = simulate_trials(specs, cfg)
        c1, w1 = time.process_time(), time.perf_counter()
        robot_s = sum(float(t["t"][-1]) for t in truths)
        cpu.append(robot_s / (c1 - c0))
        wall.append(robot_s / (w1 - w0))
    worst = max(float(np.nanmax(t["residual"])) for t in truths)
    print(
        f"{'design' if design else 'default dataset'}: {len(specs)} trials, "
        f"{robot_s:.0f} s of robot time"
    )
    print(
        f"physics: {statistics.median(cpu):.0f}x real time per CPU-second "
        f"(runs {', '.join(f'{v:.0f}' for v in cpu)}); "
        f"{statistics.median(wall):.0f}x per wall-clock second "
        f"(runs {', '.join(f'{v:.0f}' for v in wall)})"
    )
    print(f"max force/torque residual of any step: {worst:.2e} (scaled; tol {cfg.solver.tol})")
    with tempfile.TemporaryDirectory() as tmp:
        w0, c0 = time.perf_counter(), time.process_time()
        ds = simulate_dataset(tmp, cfg, **design)
        c1, w1 = time.process_time(), time.perf_counter()
    print(
        f"simulate_dataset (physics + markers + files): "
        f"{ds.simulated_seconds / (c1 - c0):.0f}x per CPU-second, "
        f"{ds.simulated_seconds / (w1 - w0):.0f}x per wall-clock second"
    )


def motion_tables(cycles: int = 10) -> dict:
    """Free vs locked and displacement per cycle, first cycle discarded (start-up)."""
    free_cfg = SimConfig()
    lock_cfg = set_effect(SimConfig(), "flippers=locked")
    specs = plan_trials(repeats=1, cycles=(cycles, cycles), seed=1)
    free = simulate_trials(specs, free_cfg)
    lock = simulate_trials(specs, lock_cfg)
    speed_rows, disp_rows = [], {}
    for spec, tf, tl in zip(specs, free, lock, strict=True):
        f = spec.frequency_hz
        skip = int(round(100 / f))  # first cycle
        stats = []
        for tr in (tf, tl):
            vx = tr["vx"][skip:]
            stats += [vx.mean(), np.sqrt(np.mean(vx**2))]
        speed_rows.append(
            [spec.gait, f"{f:.3g}"] + [f"{v:.1f}" for v in stats] + [f"{stats[0] / stats[2]:.2f}"]
        )
        d = np.hypot(tf["x"][-1] - tf["x"][skip], tf["y"][-1] - tf["y"][skip]) / (cycles - 1)
        disp_rows.setdefault(spec.gait, {})[f] = d
    print("\nForward speed (mean body vx) and RMS vx, mm/s, flippers free vs locked")
    print(
        table(
            ["gait", "f (Hz)", "free mean", "free RMS", "locked mean", "locked RMS", "free/locked"],
            speed_rows,
        )
    )
    print("\nNet displacement per cycle, mm (nominal robot, flippers free)")
    print(
        table(
            ["gait"] + [f"{f:.3g} Hz" for f in FREQUENCIES_HZ],
            [[g] + [f"{disp_rows[g][f]:.1f}" for f in FREQUENCIES_HZ] for g in GAITS],
        )
    )
    return {"specs": specs, "free": free}


def path_figure(specs, truths, out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = next(i for i, s in enumerate(specs) if s.gait == "D+" and s.frequency_hz == 0.5)
    tr, cfg = truths[k], SimConfig()
    markers = truth_markers(tr, cfg)
    fig, ax = plt.subplots(figsize=(7, 6))
    for j, name in ((0, "head_top_1"), (6, "tail_back"), (7, "flipper_1")):
        ax.plot(markers[:, j, 0], markers[:, j, 1], lw=0.5, label=name)
    ax.plot(tr["x"], tr["y"], "k", lw=1.5, label="body frame origin")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"simulated D+ at 0.5 Hz, {specs[k].n_cycles} cycles")
    ax.legend(fontsize=8)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "sim_path.png"
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", type=Path, default=Path("reports/sim-benchmark"))
    ap.add_argument(
        "--set", nargs="*", default=[], help="effects over the nominal robot, EFFECT.PARAM=VALUE"
    )
    ap.add_argument("--speed-only", action="store_true", help="skip the motion tables")
    args = ap.parse_args(argv)
    if args.quick:
        args.runs = 1
    speed(args.runs, args.set, QUICK_DESIGN if args.quick else None)
    if args.speed_only:
        return
    res = motion_tables(cycles=2 if args.quick else 10)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) if args.quick else args.out
        print(f"\nwrote {path_figure(res['specs'], res['free'], out)}")


if __name__ == "__main__":
    main()
