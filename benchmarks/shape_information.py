"""How much of the body's forward speed do shape deviations explain, beyond the gait phase?

A quick, truth-level look at what the learners of the paper can exploit in a simulator
setting (no markers, no preprocessing, no campaign): for one gait and frequency, simulate
`--repeats` trials; for every ordered pair of different trials, fit on the first and
test on the second

- phase-only: vx as a Fourier series of the commanded phase (order `--order`);
- linear in r_a: plus the deviations of (phi1, phi2) and their rates from the condition's
  mean gait, each times the same Fourier basis (a phase-varying linear map, as TLS);
- linear in r_a and flippers: plus the four flipper angles' deviations likewise;

and print the median RMS error of vx (mm/s) over the pairs and their ratios. A ratio
phase / r_a above 1 means shape deviations carry information about the motion that the
phase alone does not; r_a / (r_a + flippers) above 1, the same for the passive shape.

    .venv/bin/python benchmarks/shape_information.py
    .venv/bin/python benchmarks/shape_information.py --gait O --freqs 1/3,1 \\
        --set servo.compliance_rad_per_n_m=0.11 servo.stall_torque_n_m=2.5 bed_packing.trial_cv=0.25
"""

from __future__ import annotations

import argparse
import itertools
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from suds_exp.sim import SimConfig, apply_effects, plan_trials, simulate_trials  # noqa: E402


def basis(phase: np.ndarray, order: int, x: np.ndarray | None = None) -> np.ndarray:
    """Fourier basis of the phase (n, 2 order + 1), times each column of x when given."""
    cols = [np.ones_like(phase)]
    for k in range(1, order + 1):
        cols += [np.cos(k * phase), np.sin(k * phase)]
    b = np.stack(cols, axis=1)
    if x is None:
        return b
    return np.concatenate([b] + [b * c[:, None] for c in x.T], axis=1)


def deviations(phases: list[np.ndarray], values: list[np.ndarray], order: int) -> list:
    """Each trial's values minus the condition's mean gait (Fourier fit over all trials)."""
    b = basis(np.concatenate(phases), order)
    coef = np.linalg.lstsq(b, np.concatenate(values), rcond=None)[0]
    return [v - basis(p, order) @ coef for p, v in zip(phases, values, strict=True)]


def condition(cfg: SimConfig, gait: str, freq: float, repeats: int, seed: int, order: int):
    specs = plan_trials(
        gaits=(gait,), frequencies_hz=(freq,), repeats=repeats, cycles=(15, 20), seed=seed
    )
    truths = simulate_trials(specs, cfg)
    phase = [np.mod(t["phase_cmd"], 2 * np.pi) for t in truths]
    ra = [np.c_[t["phi1"], t["phi2"]] for t in truths]
    rate = [np.gradient(r, t["t"], axis=0) for r, t in zip(ra, truths, strict=True)]
    fl = [np.c_[tuple(t[f"flipper_{i}"] for i in range(1, 5))] for t in truths]
    d_ra, d_rate, d_fl = (deviations(phase, v, order) for v in (ra, rate, fl))
    inputs = {
        "phase": [None] * len(truths),
        "r_a": [np.c_[a, b] for a, b in zip(d_ra, d_rate, strict=True)],
        "r_a+flippers": [np.c_[a, b, c] for a, b, c in zip(d_ra, d_rate, d_fl, strict=True)],
    }
    errors: dict[str, list[float]] = {k: [] for k in inputs}
    for i, j in itertools.permutations(range(len(truths)), 2):
        for key, x in inputs.items():
            coef = np.linalg.lstsq(basis(phase[i], order, x[i]), truths[i]["vx"], rcond=1e-8)[0]
            pred = basis(phase[j], order, x[j]) @ coef
            errors[key].append(float(np.sqrt(np.mean((pred - truths[j]["vx"]) ** 2))))
    stroke = [float(np.sqrt((r**2).sum(axis=1)).mean()) for r in ra]
    return {k: float(np.median(v)) for k, v in errors.items()}, stroke


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gait", default="O")
    ap.add_argument("--freqs", default="1/3,1", help="Hz, comma list (fractions allowed)")
    ap.add_argument("--repeats", type=int, default=4)
    ap.add_argument("--seed", type=int, default=1, help="dataset seed")
    ap.add_argument("--order", type=int, default=3, help="Fourier order in the phase")
    ap.add_argument("--set", nargs="*", default=[], help="effects, EFFECT.PARAM=VALUE")
    args = ap.parse_args()
    cfg = apply_effects(SimConfig(), args.set, param="--set")
    print(f"setting: {' '.join(args.set) or 'nominal'}; gait {args.gait}, seed {args.seed}")
    print("| Hz | mean stroke (rad) | phase | r_a | r_a+flippers | phase / r_a | r_a / (r_a+fl) |")
    print("|---|---|---|---|---|---|---|")
    for text in args.freqs.split(","):
        freq = float(Fraction(text))
        med, stroke = condition(cfg, args.gait, freq, args.repeats, args.seed, args.order)
        print(
            f"| {text} | {np.mean(stroke):.2f} | {med['phase']:.2f} | {med['r_a']:.2f} | "
            f"{med['r_a+flippers']:.2f} | {med['phase'] / med['r_a']:.2f} | "
            f"{med['r_a'] / med['r_a+flippers']:.2f} |"
        )


if __name__ == "__main__":
    main()
