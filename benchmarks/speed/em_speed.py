"""EM alone: the baseline commit's `fit_mixture` against the working tree's, in one process.

Usage (from the repository root)::

    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.speed.em_speed [--baseline c2aa7be] \
        [--rounds 7] [--quick]

The baseline's `suds_exp/models/mixture.py` is read with `git show` and loaded beside the
current one. The inputs are the standardised training matrices GMR and GMR+SUDS hand to
EM on the first 4 bootstrap draws of the campaign benchmarks' data
(`benchmarks._data`, 30 cycles, 3000 samples; D = 7 and 11), K = 16, the learners'
defaults. Old and new alternate on each matrix (`--rounds` times), single-threaded BLAS;
the fitted mixtures must be equal (np.array_equal). Prints per D the median CPU ms of
each and the median of the paired ratios old / new. ``--quick``: baseline HEAD, one
round on one draw of 5 cycles, K = 4 (a smoke run, no figure).
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

import suds_exp.models.gmr as gmr_module
from benchmarks import _data
from benchmarks._harness import ROOT, comparison_parser
from suds_exp.models import make_model
from suds_exp.models import mixture as new


def _old_mixture(commit: str, folder: Path):
    src = subprocess.run(
        ["git", "show", f"{commit}:suds_exp/models/mixture.py"],
        cwd=ROOT,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    path = folder / "old_mixture.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("old_mixture", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["old_mixture"] = mod
    spec.loader.exec_module(mod)
    return mod


def em_inputs(n_draws: int = 4, cycles: int = 30, trial_cycles: int = 25) -> list[np.ndarray]:
    """The matrices GMR and GMR+SUDS pass to fit_mixture on the first draws."""
    samples = _data.paper_like_samples(n_cycles=trial_cycles)
    seen = []
    real = gmr_module.fit_mixture

    def grab(X, *a, **k):
        seen.append(X.copy())
        return real(X, *a, **k)

    gmr_module.fit_mixture = grab
    try:
        for train, _ in _data.small_grid_jobs(samples, 1, cycles, limit=n_draws):
            make_model("GMR").fit(train)
            make_model("GMR+SUDS").fit(train)
    finally:
        gmr_module.fit_mixture = real
    return seen


def main(argv=None) -> int:
    ap = comparison_parser(__doc__.splitlines()[0], "c2aa7be", 7)
    a = ap.parse_args(argv)
    k, sizes = 16, {}
    if a.quick:
        a.baseline, a.rounds, k = "HEAD", 1, 4
        sizes = {"n_draws": 1, "cycles": 5, "trial_cycles": 8}
    with tempfile.TemporaryDirectory() as tmp:
        old = _old_mixture(a.baseline, Path(tmp))
        pairs: dict[int, list] = {}
        inputs = em_inputs(**sizes)
        with threadpool_limits(limits=1):
            for _ in range(a.rounds):
                for X in inputs:
                    w = np.ones(len(X))
                    fits, cpu = [], []
                    for mod in (old, new):
                        c0 = time.process_time()
                        rng = np.random.default_rng([0, k])
                        fits.append(mod.fit_mixture(X, k, w, 60, 1e-3, 1e-3, rng))
                        cpu.append(time.process_time() - c0)
                    same = all(
                        np.array_equal(getattr(fits[0], f), getattr(fits[1], f))
                        for f in ("priors", "means", "covariances")
                    )
                    if not same:
                        print(f"DIFFERENT mixtures for D={X.shape[1]}")
                        return 1
                    pairs.setdefault(X.shape[1], []).append(cpu)
    print(f"| EM of D | {a.baseline} ms | now ms | speed-up (median of pairs) | pairs |")
    print("|---|---|---|---|---|")
    for d, v in pairs.items():
        o, n = np.array(v).T
        print(
            f"| {d} | {np.median(o) * 1e3:.1f} | {np.median(n) * 1e3:.1f} | "
            f"{np.median(o / n):.2f}x | {len(v)} |"
        )
    print("fitted mixtures identical (np.array_equal) in every pair")
    return 0


if __name__ == "__main__":
    sys.exit(main())
