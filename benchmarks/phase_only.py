"""Our phase-only baseline against the paper's definition of it.

The paper's phase-only model is "the phase dependent constant term of the TLS model";
`PhaseOnly` is its own least-squares Fourier series in phase. For each condition of a
preprocessed database, fit both (and TLS) on the condition's longest trial and test on
each of its other trials; print the median RMS error of vx (mm/s) per test frequency of

- phase-only: `make_model("phase-only")`;
- TLS constant: TLS's prediction with the shape deviations set to zero, the phase mean
  plus the bins' constants (`TLS.coefficients(phase)["C"]`);
- TLS: the full TLS prediction;

and the ratio TLS constant / phase-only over the pairs (median and range).

    make demo     # or any database with the default dataset preprocessed as v1
    .venv/bin/python benchmarks/phase_only.py --db suds.duckdb --prep v1
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from suds_exp.models import make_model  # noqa: E402
from suds_exp.preprocess import get_version  # noqa: E402
from suds_exp.store import Store  # noqa: E402


def rmse(pred: np.ndarray, truth: np.ndarray) -> float:
    return float(np.sqrt(np.mean((pred - truth) ** 2)))


def compare(samples: pd.DataFrame) -> pd.DataFrame:
    """One row per (condition, test trial): RMS error of vx of the three predictors."""
    rows = []
    for (gait, freq), cond in samples.groupby(["gait", "frequency_hz"]):
        sizes = cond.groupby("trial_id").size().sort_values()
        train = cond[cond.trial_id == sizes.index[-1]]
        phase_only = make_model("phase-only").fit(train)
        tls = make_model("TLS").fit(train)
        for tid in sizes.index[:-1]:
            test = cond[cond.trial_id == tid]
            vx = test.vx.to_numpy(float)
            constant = tls.coefficients(test.phase.to_numpy(float))["C"][:, 0]
            rows.append(
                {
                    "gait": gait,
                    "frequency_hz": round(float(freq), 2),
                    "test_trial": int(tid),
                    "phase_only": rmse(phase_only.predict(test).vx.to_numpy(), vx),
                    "tls_constant": rmse(constant, vx),
                    "tls": rmse(tls.predict(test).vx.to_numpy(), vx),
                }
            )
    return pd.DataFrame(rows)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--db", default="suds.duckdb")
    p.add_argument("--prep", default="v1")
    args = p.parse_args()
    store = Store(args.db)
    samples = get_version(store, args.prep).samples()
    if "gait" not in samples:
        trials = store.query_df("SELECT id AS trial_id, gait, frequency_hz FROM trials")
        samples = samples.merge(trials, on="trial_id")
    table = compare(samples)
    cols = ["phase_only", "tls_constant", "tls"]
    print("median RMS error of vx (mm/s) by test frequency")
    print(table.groupby("frequency_hz")[cols].median().round(2).to_string())
    ratio = table.tls_constant / table.phase_only
    print(
        f"TLS constant / phase-only over {len(table)} pairs: median {ratio.median():.3f} "
        f"(range {ratio.min():.3f}-{ratio.max():.3f})"
    )


if __name__ == "__main__":
    main()
