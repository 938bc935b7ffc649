"""Phase-only against TLS's constant term, and the phase resolution they share.

The paper's phase-only model is "the phase dependent constant term of the TLS model", so
both must describe the cycle with the same Fourier order (`fourier.PHASE_ORDER`, the
default of `PhaseOnly.order` and `TLS.gait_order`). For each Fourier order of
``--orders`` and every ordered pair of different trials of a condition (trained on the
first 30 cycles of one, tested on the whole other, as a campaign's same-condition pairs)
this prints the median RMS error of vx (mm/s) per test frequency of

- phase-only at that order;
- TLS constant: TLS at that ``gait_order`` with the shape deviations set to zero (the
  phase mean plus the bins' constants, `TLS.coefficients(phase)["C"]`);
- TLS at that ``gait_order``;

so the order where phase-only's held-out error stops falling, and whether TLS improves on
its own constant term, can be read off.

    make demo     # or any database with the default dataset preprocessed as v1
    .venv/bin/python -m benchmarks.studies.phase_only --db suds.duckdb --prep v1 \
        --orders 5,6,8,10,12
"""

from __future__ import annotations

import itertools
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks._data import QUICK_DESIGN, simulated_database
from benchmarks._harness import script_parser
from suds_exp.models import make_model
from suds_exp.preprocess import get_version
from suds_exp.store import Store

TRAIN_CYCLES = 30


def rmse(pred: np.ndarray, truth: np.ndarray) -> float:
    return float(np.sqrt(np.mean((pred - truth) ** 2)))


def compare(samples: pd.DataFrame, orders: list[int]) -> pd.DataFrame:
    """One row per (order, condition, train trial, test trial): RMS error of vx (mm/s)
    of phase-only, TLS's constant term and TLS."""
    rows = []
    for (gait, freq), cond in samples.groupby(["gait", "frequency_hz"]):
        trials = {tid: g for tid, g in cond.groupby("trial_id")}
        for a, b in itertools.permutations(sorted(trials), 2):
            train = trials[a][trials[a].cycle < trials[a].cycle.min() + TRAIN_CYCLES]
            test = trials[b]
            vx = test.vx.to_numpy(float)
            for order in orders:
                tls = make_model("TLS", gait_order=order).fit(train)
                constant = tls.coefficients(test.phase.to_numpy(float))["C"][:, 0]
                phase_only = make_model("phase-only", order=order).fit(train)
                rows.append(
                    {
                        "order": order,
                        "gait": gait,
                        "frequency_hz": round(float(freq), 2),
                        "phase_only": rmse(phase_only.predict(test).vx.to_numpy(), vx),
                        "tls_constant": rmse(constant, vx),
                        "tls": rmse(tls.predict(test).vx.to_numpy(), vx),
                    }
                )
    return pd.DataFrame(rows)


def main(argv=None) -> None:
    p = script_parser(__doc__.splitlines()[0], "a smoke run on a tiny simulated dataset")
    p.add_argument("--db", default="suds.duckdb")
    p.add_argument("--prep", default="v1")
    p.add_argument("--orders", default="5,6,8,10,12", help="Fourier orders, comma list")
    args = p.parse_args(argv)
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-phase-only-") as tmp:
            db = Path(tmp) / "quick.duckdb"
            args.db, args.prep, args.orders = db, simulated_database(db, QUICK_DESIGN), "5"
            report(args)
        return
    report(args)


def report(args) -> None:
    store = Store(args.db)
    samples = get_version(store, args.prep).samples()
    if "gait" not in samples:
        trials = store.query_df("SELECT id AS trial_id, gait, frequency_hz FROM trials")
        samples = samples.merge(trials, on="trial_id")
    table = compare(samples, [int(o) for o in args.orders.split(",")])
    cols = ["phase_only", "tls_constant", "tls"]
    med = table.groupby(["order", "frequency_hz"])[cols].median()
    med["phase_only/tls"] = med.phase_only / med.tls
    n_pairs = len(table) // table.order.nunique()
    print(f"median RMS error of vx (mm/s) over {n_pairs} same-condition pairs")
    print(med.round(2).to_string())


if __name__ == "__main__":
    main()
