"""The ceiling of gait design: the best gait found by optimising directly on the simulator.

Maximises the simulator's forward displacement per cycle (nominal robot, 1/2 Hz, the
measurement of `suds_exp.gait.truth`: gait followed exactly, mean of cycles 3-5) over the
same Fourier gaits as `suds-exp gait design` (order --order, |phi1|, |phi2| <= --bound),
derivative-free (--random random gaits and the circle O simulated in one batch, then
adaptive Nelder-Mead from the --starts best, --evals simulations each; every candidate is
projected into the bound by `within_bound`, as the designer's are), and prints the best
gait, its displacement and the paper's five for scale. No learned map, no trust region: the
number `gait design` is compared with.

Run: .venv/bin/python -m benchmarks.studies.gait_ceiling [--bound 1.3] [--order 2] [--evals 300]
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import minimize

from benchmarks._harness import script_parser
from suds_exp.gait.design import circle
from suds_exp.gait.shape import FourierGait, paper_gaits, within_bound
from suds_exp.gait.truth import simulate_forward


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--bound", type=float, default=1.3, help="joint bound, rad")
    ap.add_argument("--order", type=int, default=2, help="Fourier harmonics per joint")
    ap.add_argument("--evals", type=int, default=150, help="simulations per local search")
    ap.add_argument("--random", type=int, default=60, help="random gaits of the global look")
    ap.add_argument("--starts", type=int, default=3, help="local searches from the best")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--freq", type=float, default=0.5, help="Hz")
    args = ap.parse_args(argv)
    if args.quick:
        args.order, args.evals, args.random, args.starts = 1, 5, 3, 1
    started = time.perf_counter()
    paper = simulate_forward(paper_gaits(), args.freq)
    n_sims = 0

    def feasible(x) -> FourierGait:
        return within_bound(FourierGait.from_vector(x, "ceiling"), args.bound)

    def loss(x):
        nonlocal n_sims
        n_sims += 1
        return -float(simulate_forward([feasible(x)], args.freq)[0])

    # global look: --random random gaits (first harmonic ~ N(0, 1) rad, higher ones
    # ~ N(0, 0.3), centre ~ U(-0.3, 0.3)), projected into the bound, in one batch
    rng = np.random.default_rng(args.seed)
    n_coef = 2 + 4 * args.order
    scale = np.r_[[0.3, 0.3], np.tile([1.0] * 2 + [0.3] * 2 * (args.order - 1), 2)]
    starts = rng.normal(size=(args.random, n_coef)) * scale
    starts[:, :2] = rng.uniform(-0.3, 0.3, size=(args.random, 2))
    starts = np.vstack([circle(1.0, args.order).to_vector(), starts])
    values = simulate_forward([feasible(x) for x in starts], args.freq)
    n_sims += len(starts)
    best = None
    for i in np.argsort(-values)[: args.starts]:
        res = minimize(
            loss,
            starts[i],
            method="Nelder-Mead",
            options={"maxfev": args.evals, "xatol": 1e-3, "fatol": 1e-2, "adaptive": True},
        )
        if best is None or res.fun < best.fun:
            best = res
    gait = feasible(best.x)
    print(
        f"paper's five at {args.freq:g} Hz (mm/cycle): "
        + ", ".join(f"{g.name} {v:.1f}" for g, v in zip(paper_gaits(), paper, strict=True))
    )
    print(
        f"direct-on-simulator optimum, bound {args.bound:g} rad, order {args.order}: "
        f"{-best.fun:.1f} mm/cycle after {n_sims} simulations "
        f"({time.perf_counter() - started:.0f} s)"
    )
    print("coefficients (a0, cos, sin):", np.round(gait.to_vector(), 3).tolist())
    print(f"= {-best.fun / paper.max():.2f} x the best of the paper's five ({paper.max():.1f})")


if __name__ == "__main__":
    main()
