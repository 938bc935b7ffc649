"""EM alone: the baseline commit's `fit_mixture` against the working tree's, in one process.

Usage (from the repository root)::

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/em_speed.py [--baseline c2aa7be] [--rounds 7]

The baseline's `suds_exp/models/mixture.py` is read with `git show` and loaded beside the
current one. The inputs are the standardised training matrices GMR and GMR+SUDS hand to
EM on the first 4 bootstrap draws of the campaign benchmark's data
(`benchmarks/campaign.py`, 30 cycles, 3000 samples; D = 7 and 11), K = 16, the learners'
defaults. Old and new alternate on each matrix (`--rounds` times), single-threaded BLAS;
the fitted mixtures must be equal (np.array_equal). Prints per D the median CPU ms of
each and the median of the paired ratios old / new.
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import campaign as cb  # noqa: E402

import suds_exp.models.gmr as gmr_module  # noqa: E402
from suds_exp.campaign import SampleBank, enumerate_draws  # noqa: E402
from suds_exp.campaign.bank import rounded_conditions  # noqa: E402
from suds_exp.campaign.conditions import select_conditions  # noqa: E402
from suds_exp.campaign.sampling import draw_sample  # noqa: E402
from suds_exp.models import make_model  # noqa: E402
from suds_exp.models import mixture as new  # noqa: E402


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


def em_inputs(n_draws: int = 4) -> list[np.ndarray]:
    """The matrices GMR and GMR+SUDS pass to fit_mixture on the first draws."""
    samples = cb.paper_like_samples()
    chosen = select_conditions(cb.SMALL, rounded_conditions(samples), "--x")
    bank = SampleBank.build(samples, chosen)
    seen = []
    real = gmr_module.fit_mixture

    def grab(X, *a, **k):
        seen.append(X.copy())
        return real(X, *a, **k)

    gmr_module.fit_mixture = grab
    try:
        for i, d in enumerate(enumerate_draws("bench", chosen, chosen, 1, 30, [])):
            if i == n_draws:
                break
            s = draw_sample(bank, d, 30)
            train = bank.frame([bank.rows(*r) for r in s.train])
            make_model("GMR").fit(train)
            make_model("GMR+SUDS").fit(train)
    finally:
        gmr_module.fit_mixture = real
    return seen


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="c2aa7be")
    ap.add_argument("--rounds", type=int, default=7)
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        old = _old_mixture(a.baseline, Path(tmp))
        pairs: dict[int, list] = {}
        inputs = em_inputs()
        with threadpool_limits(limits=1):
            for _ in range(a.rounds):
                for X in inputs:
                    w = np.ones(len(X))
                    fits, cpu = [], []
                    for mod in (old, new):
                        c0 = time.process_time()
                        rng = np.random.default_rng([0, 16])
                        fits.append(mod.fit_mixture(X, 16, w, 60, 1e-3, 1e-3, rng))
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
