"""Phaser benchmark: our `suds_exp.preprocess.Phaser` against the authors' reference code,
both trained on 3 trials and applied to 3 others whose true phase is known.

Usage::

    .venv/bin/python -m benchmarks.studies.phaser [--json] [--seed 0]

Cases (each: error to truth of both estimators, and their ratio ours / reference):

- ``gait-2ch@F``: our default input, the smoothed r_a = (ra_1, ra_2) of the default
  preprocessing of simulated trials of gait D+ at F Hz (true phase: the commanded one);
- ``gait-4ch@F``: a 4-D gait with flippers, (ra_1, ra_2, rp_1, rp_2) of the same trials;
- ``relax-2ch``, ``relax-4ch``: a relaxation oscillator (the van der Pol limit cycle,
  mu = 4, run at a drifting, diffusing phase that is the truth) seen through 2 or 4
  channels with unequal measurement noise, 100 frames a cycle.

Error: RMS over the test trials' frames of the wrapped phase difference to the truth,
after removing one constant offset per trial (the phase zero is a Poincare section, not
the truth's zero). Both estimators use Fourier order 10 and the same Poincare section
(channel 0 crossing its training mean upwards). Done when ``ratio <= 1.10`` on every case.

The reference is the authors' ``phaser.py`` (2015) of https://github.com/sheim/phaser
(S. Revzen, S. Wilshin; GPL-3.0; cite Revzen & Guckenheimer, Phys. Rev. E 78, 051907,
2008). Its code is not part of this project (the library's Phaser is written
independently from the paper): give ``--reference FILE``, a Python 3 file of yours that
defines ``ReferencePhaser(records, order, section)`` (records: list of (n_channels,
n_frames) arrays; section: callable on one frame) returning a callable from a
(n_channels, n_frames) record to its phase (rad) -- e.g. a Python 3 port of the
reference's ``Phaser`` class. Without it only our error to the truth is printed.
"""

from __future__ import annotations

import json
import tempfile
import warnings
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from benchmarks._harness import script_parser
from suds_exp.commands.simulate import simulate_command
from suds_exp.preprocess import Phaser, load_samples, preprocess
from suds_exp.preprocess.truth import truth_path
from suds_exp.sim.dataset import SimDesign
from suds_exp.store import Store

ORDER = 10
TWO_PI = 2 * np.pi
#: the user's reference implementation (see --reference), or None
REFERENCE = None


def load_reference(path: str):
    """``ReferencePhaser`` from the Python file ``path``."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("phaser_reference", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.ReferencePhaser


# == cases ===================================================================================
def _section(mean0: float):
    return lambda x: x[0] - mean0


def phase_error(estimates: list[np.ndarray], truths: list[np.ndarray]) -> float:
    """Pooled RMS (rad) of wrapped estimate - truth, one constant offset removed per trial."""
    parts = []
    for est, true in zip(estimates, truths, strict=True):
        d = np.angle(np.exp(1j * (est - true)))
        d = np.angle(np.exp(1j * (d - np.angle(np.mean(np.exp(1j * d))))))
        parts.append(d)
    return float(np.sqrt(np.mean(np.square(np.concatenate(parts)))))


def compare(train: list[np.ndarray], test: list[np.ndarray], truth: list[np.ndarray]) -> dict:
    """Both estimators on (n_frames, n_channels) records; errors (rad) and ratio."""
    ours = Phaser(order=ORDER).fit(train)
    mean0 = float(np.concatenate(train)[:, 0].mean())
    e_ours = phase_error([ours.transform(x) for x in test], truth)
    e_ref = float("nan")
    if REFERENCE is not None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ref = REFERENCE([x.T for x in train], ORDER, _section(mean0))
        e_ref = phase_error([ref(x.T) for x in test], truth)
    return {
        "channels": train[0].shape[1],
        "ours_rad": e_ours,
        "reference_rad": e_ref,
        "ratio": e_ours / e_ref,
        "weights": [round(float(w), 3) for w in ours.weights_],
    }


def gait_cases(seed: int, frequencies=(1 / 3, 0.5, 1.0)) -> dict[str, dict]:
    """Simulated D+ trials, default preprocessing: the 2- and 4-channel cases per frequency."""
    out = {}
    with tempfile.TemporaryDirectory(prefix="suds-phaser-bench-") as tmp:
        store = Store(Path(tmp) / "bench.duckdb")
        design = SimDesign(("D+",), frequencies, repeats=6, cycles=(12, 16), seed=seed)
        simulate_command(Path(tmp) / "data", store=store, design=design)
        preprocess(store, progress=False)
        samples = load_samples(store, 1)
        files = store.query_df("SELECT id, source_file FROM trials")
        import pandas as pd

        for f in frequencies:
            ids = sorted(samples.trial_id[np.isclose(samples.frequency_hz, f)].unique())
            chans, truths = {2: [], 4: []}, []
            for tid in ids:
                s = samples[samples.trial_id == tid]
                truth = pd.read_parquet(truth_path(files.source_file[files.id == tid].iloc[0]))
                truths.append(truth.phase_cmd.to_numpy())
                chans[2].append(s[["ra_1", "ra_2"]].to_numpy())
                chans[4].append(s[["ra_1", "ra_2", "rp_1", "rp_2"]].to_numpy())
            for m in (2, 4):
                out[f"gait-{m}ch@{f:.3g}Hz"] = compare(chans[m][:3], chans[m][3:6], truths[3:6])
    return out


def _limit_cycle(mu: float = 4.0, n: int = 2000) -> np.ndarray:
    """One period of the van der Pol limit cycle at uniform time, (n, 2): x, dx/dt."""

    def f(_, s):
        return [s[1], mu * (1 - s[0] ** 2) * s[1] - s[0]]

    warm = solve_ivp(f, (0, 200), [2.0, 0.0], rtol=1e-10, atol=1e-10)
    s0 = warm.y[:, -1]
    # one period: from an upward crossing of x = 0 to the next
    ev = lambda _, s: s[0]  # noqa: E731
    ev.direction = 1
    run = solve_ivp(f, (0, 60), s0, events=ev, rtol=1e-10, atol=1e-10, dense_output=True)
    t0, t1 = run.t_events[0][:2]
    return run.sol(np.linspace(t0, t1, n, endpoint=False)).T


def relaxation_cases(seed: int) -> dict[str, dict]:
    """Van der Pol waveforms at a known, drifting, diffusing phase; unequal channel noise."""
    cycle = _limit_cycle()
    scaled = cycle / cycle.std(axis=0)
    rng = np.random.default_rng(seed)
    records, truths = [], []
    for _ in range(6):
        n = int(rng.integers(1500, 2500))  # 15-25 cycles at 100 frames a cycle
        theta = (
            TWO_PI * np.arange(n) / 100
            + 0.3 * np.sin(TWO_PI * np.arange(n) / 1700 + rng.uniform(0, TWO_PI))
            + np.cumsum(rng.normal(0, 0.01, n))
            + rng.uniform(0, TWO_PI)
        )
        at = (np.mod(theta, TWO_PI) / TWO_PI * len(cycle)).astype(int) % len(cycle)
        x, v = scaled[at, 0], scaled[at, 1]
        clean = np.column_stack([x, v, x + 0.5 * v, np.tanh(2 * x) - 0.3 * v])
        records.append(clean)
        truths.append(theta)
    noise = np.array([0.05, 0.4, 0.15, 0.8])
    noisy = [r + rng.normal(0, 1, r.shape) * noise for r in records]
    out = {}
    for m in (2, 4):
        x = [r[:, :m] for r in noisy]
        out[f"relax-{m}ch"] = compare(x[:3], x[3:], truths[3:])
    return out


def main(argv=None) -> None:
    parser = script_parser(__doc__.split("\n\n")[0], "a smoke run: the 1 Hz trials")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--reference", help="Python file defining ReferencePhaser (see above)")
    args = parser.parse_args(argv)
    global REFERENCE
    REFERENCE = load_reference(args.reference) if args.reference else None
    freqs = (1.0,) if args.quick else (1 / 3, 0.5, 1.0)
    cases = {**gait_cases(args.seed, freqs), **relaxation_cases(args.seed)}
    if args.json:
        print(json.dumps(cases, indent=1))
        return
    print(f"{'case':<16} {'ours rad':>9} {'ref rad':>9} {'ratio':>6}  weights")
    for name, c in cases.items():
        print(
            f"{name:<16} {c['ours_rad']:9.4f} {c['reference_rad']:9.4f} {c['ratio']:6.2f}  "
            f"{c['weights']}"
        )
    if REFERENCE is None:
        print("no --reference given: the reference columns are NaN")
        return
    worst = max(c["ratio"] for c in cases.values())
    print(f"worst ratio ours/reference: {worst:.2f} (target <= 1.10)")


if __name__ == "__main__":
    main()
