"""How much of the body's forward speed do shape deviations explain, beyond the gait phase?

A quick, truth-level look at what the learners of the paper can exploit in a simulator
setting (no markers, no preprocessing, no campaign): for one gait and frequency, simulate
`--repeats` trials; for every ordered pair of different trials, fit on the first and
test on the second

- phase-only: vx as a Fourier series of the commanded phase (order `--order`, by default
  the learners' `fourier.PHASE_ORDER`);
- linear in r_a: plus the deviations of (phi1, phi2) and their rates from the condition's
  mean gait, each times the same Fourier basis (a phase-varying linear map, as TLS);
- linear in r_a and flippers: plus the four flipper angles' deviations likewise;

and print the median RMS error of vx (mm/s) over the pairs and their ratios. A ratio
phase / r_a above 1 means shape deviations carry information about the motion that the
phase alone does not; r_a / (r_a + flippers) above 1, the same for the passive shape.

``--pipeline`` asks the same question of what the learners see: the whole default design
(5 gaits x 3 frequencies x 4 repeats, dataset ``--seed``) is simulated, ingested and
preprocessed (default version), and the fits use the preprocessed phase, r_a and dr_a/dt
and the k passive components r_p (and dr_p/dt) against the measured vx; one row per
setting with the median over the 15 conditions. ``--springs`` repeats everything for each
stiffness of the flippers' tape hinges (N mm/rad, `Hinges.spring_n_mm_per_rad`), on the
robot of ``--config`` (default nominal) with the effects of ``--set``.

    .venv/bin/python -m benchmarks.studies.shape_information
    .venv/bin/python -m benchmarks.studies.shape_information --gait O --freqs 1/3,1 \\
        --set servo.compliance_rad_per_n_m=0.11 servo.stall_torque_n_m=2.5 bed_packing.trial_cv=0.25
    .venv/bin/python -m benchmarks.studies.shape_information --pipeline \\
        --config examples/calibrated_robot.toml --springs 5,20,50,100,200,300
"""

from __future__ import annotations

import itertools
import tempfile
from fractions import Fraction
from pathlib import Path

import numpy as np

from benchmarks._harness import script_parser
from suds_exp.ingest import ingest_paths
from suds_exp.models import fourier
from suds_exp.preprocess import get_version, preprocess
from suds_exp.sim import (
    SimConfig,
    apply_effects,
    config_from_dict,
    load_config,
    plan_trials,
    simulate_dataset,
    simulate_trials,
)
from suds_exp.store import Store


def basis(phase: np.ndarray, order: int, x: np.ndarray | None = None) -> np.ndarray:
    """`fourier.basis` of the phase (n, 2 order + 1), and its product with each column of
    x when given (a phase-varying linear map)."""
    b = fourier.basis(phase, order)
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
    stroke = [float(np.sqrt((r**2).sum(axis=1)).mean()) for r in ra]
    return pair_errors(phase, [t["vx"] for t in truths], inputs, order), stroke


def pair_errors(phase: list, vx: list, inputs: dict, order: int) -> dict[str, float]:
    """Median over ordered pairs of trials (fit on one, test on the other) of the RMS
    error of vx (mm/s) for each input set; ``inputs[key][i]`` is trial i's (n, m) array
    of extra regressors (None: phase only)."""
    errors: dict[str, list[float]] = {k: [] for k in inputs}
    for i, j in itertools.permutations(range(len(vx)), 2):
        for key, x in inputs.items():
            coef = np.linalg.lstsq(basis(phase[i], order, x[i]), vx[i], rcond=1e-8)[0]
            pred = basis(phase[j], order, x[j]) @ coef
            errors[key].append(float(np.sqrt(np.mean((pred - vx[j]) ** 2))))
    return {k: float(np.median(v)) for k, v in errors.items()}


def pipeline(cfg: SimConfig, seed: int, order: int) -> dict[str, float]:
    """The median over the default design's 15 conditions of `pair_errors` on the
    preprocessed samples (phase, r_a, dr_a/dt, r_p, dr_p/dt and the measured vx)."""
    with tempfile.TemporaryDirectory(prefix="suds-shape-info-") as tmp:
        ds = simulate_dataset(Path(tmp) / "data", cfg, seed=seed)
        store = Store(Path(tmp) / "info.duckdb")
        ingest_paths(store, [Path(tmp) / "data"], ds.manifest, None, progress=False)
        version = get_version(store, preprocess(store, progress=False).name)
        k = version.k
        rp = [f"rp_{i}" for i in range(1, k + 1)]
        drp = [f"drp_{i}" for i in range(1, k + 1)]
        df = version.samples().sort_values(["trial_id", "frame"])
    per_condition = []
    for _, d in df.groupby(["gait", "frequency_hz"]):
        trials = [x for _, x in d.groupby("trial_id")]
        phase = [np.mod(x["phase"].to_numpy(), 2 * np.pi) for x in trials]

        def dev(cols: list[str], trials=trials, phase=phase) -> list[np.ndarray]:
            return deviations(phase, [x[cols].to_numpy() for x in trials], order)

        ra, p, dp = dev(["ra_1", "ra_2", "dra_1", "dra_2"]), dev(rp), dev(drp)
        inputs = {
            "phase": [None] * len(trials),
            "r_a": ra,
            "r_a+r_p": [np.c_[a, b] for a, b in zip(ra, p, strict=True)],
            "r_a+r_p+dr_p": [np.c_[a, b, c] for a, b, c in zip(ra, p, dp, strict=True)],
        }
        per_condition.append(
            pair_errors(phase, [x["vx"].to_numpy() for x in trials], inputs, order)
        )
    return {key: float(np.median([c[key] for c in per_condition])) for key in per_condition[0]}


def main(argv=None) -> None:
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--gait", default="O")
    ap.add_argument("--freqs", default="1/3,1", help="Hz, comma list (fractions allowed)")
    ap.add_argument("--repeats", type=int, default=4)
    ap.add_argument("--seed", type=int, default=1, help="dataset seed")
    # The learners' own phase order: at a lower order (3 was the default until
    # 2026-11-25) the mean gait's sharp features (S+'s corners) are left in the
    # residual, and any signal that tracks the phase "explains" them (nominal robot, S+
    # at 1/3 Hz: flippers 2.5x better than r_a at order 3, 0.5x at order 10).
    ap.add_argument(
        "--order", type=int, default=fourier.PHASE_ORDER, help="Fourier order in the phase"
    )
    ap.add_argument("--config", type=Path, help="simulator config file (default nominal)")
    ap.add_argument("--set", nargs="*", default=[], help="effects, EFFECT.PARAM=VALUE")
    ap.add_argument("--springs", default="", help="hinge springs to sweep, N mm/rad")
    ap.add_argument("--pipeline", action="store_true", help="the whole design, preprocessed")
    args = ap.parse_args(argv)
    if args.quick:
        args.freqs, args.repeats, args.pipeline, args.springs = "1", 2, False, ""
    base = load_config(args.config) if args.config else SimConfig()
    base = apply_effects(base, args.set, param="--set")
    springs = [float(k) for k in args.springs.split(",") if k] or [base.hinges.spring_n_mm_per_rad]
    where = f"config {args.config or 'nominal'}; effects {' '.join(args.set) or 'none'}"
    if args.pipeline:
        print(f"{where}; whole design, dataset seed {args.seed}, median over conditions")
        print(
            "| spring (N mm/rad) | phase | r_a | r_a+r_p | r_a+r_p+dr_p | phase / r_a "
            "| r_a / (r_a+r_p) | r_a / (r_a+r_p+dr_p) |"
        )
        print("|---|---|---|---|---|---|---|---|")
    else:
        print(f"{where}; gait {args.gait}, seed {args.seed}")
        print(
            "| spring (N mm/rad) | Hz | mean stroke (rad) | phase | r_a | r_a+flippers "
            "| phase / r_a | r_a / (r_a+fl) |"
        )
        print("|---|---|---|---|---|---|---|---|")
    for spring in springs:
        cfg = config_from_dict({"hinges": {"spring_n_mm_per_rad": spring}}, base=base)
        if args.pipeline:
            m = pipeline(cfg, args.seed, args.order)
            print(
                f"| {spring:g} | {m['phase']:.2f} | {m['r_a']:.2f} | {m['r_a+r_p']:.2f} | "
                f"{m['r_a+r_p+dr_p']:.2f} | {m['phase'] / m['r_a']:.2f} | "
                f"{m['r_a'] / m['r_a+r_p']:.2f} | {m['r_a'] / m['r_a+r_p+dr_p']:.2f} |",
                flush=True,
            )
            continue
        for text in args.freqs.split(","):
            freq = float(Fraction(text))
            med, stroke = condition(cfg, args.gait, freq, args.repeats, args.seed, args.order)
            print(
                f"| {spring:g} | {text} | {np.mean(stroke):.2f} | {med['phase']:.2f} | "
                f"{med['r_a']:.2f} | {med['r_a+flippers']:.2f} | "
                f"{med['phase'] / med['r_a']:.2f} | {med['r_a'] / med['r_a+flippers']:.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
