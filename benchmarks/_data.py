"""The data sets and learner settings several benchmarks share.

- `paper_like_samples`: the campaign benchmarks' synthetic swimmer, 5 gaits x 3 frequencies
  x 4 trials at 100 samples a cycle, as in the paper's data; `SMALL`, `BOOTS` and `CYCLES`
  are the small grid they run on it, `small_grid_jobs` its jobs' (train, test) frames;
- `PAPER`, `GMR_VARIANTS`, `SURVEY` and `swimmer_samples`: the learner benchmarks' settings
  (registry name, parameters) and the one-trial swimmer they learn.

Everything here imports `suds_exp` lazily or from modules old baselines also have, since a
commit comparison's worker imports this module beside the baseline's `suds_exp`.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import pandas as pd

#: The small grid of the campaign benchmarks: train x test over these conditions.
SMALL = "O@1/3,O@1,D+@0.5,S-@1"
#: Draws a cell and training cycles of the small grid (30 cycles, as in the paper).
BOOTS = 3
CYCLES = 30


def paper_like_samples(seed: int = 0, n_cycles: int = 25) -> pd.DataFrame:
    """5 gaits x 3 frequencies x 4 trials x ``n_cycles`` cycles at 100 samples a cycle
    (synthetic swimmer, Finsler velocity): the samples frame, trial ids from 1."""
    from suds_exp.robot import FREQUENCIES_HZ, GAITS
    from suds_exp.testing.synthetic_swimmer import make_samples

    frames, tid = [], 1
    for g in GAITS:
        for f in FREQUENCIES_HZ:
            s = make_samples(
                n_cycles=n_cycles,
                gait=g,
                frequency_hz=f,
                n_trials=4,
                samples_per_cycle=int(round(100 / f)),
                velocity="finsler",
                substeps=2,
                first_trial_id=tid,
                seed=seed + tid,
            )
            frames.append(s)
            tid += 4
    return pd.concat(frames, ignore_index=True)


def small_grid_jobs(
    samples: pd.DataFrame,
    boots: int = BOOTS,
    cycles: int = CYCLES,
    sweep: list[int] | None = None,
    limit: int | None = None,
) -> list[tuple[pd.DataFrame, pd.DataFrame]]:
    """(train, test) sample frames of the small grid's draws on ``samples``, in the order
    a campaign enumerates them (at most ``limit``): ``boots`` draws a cell, ``cycles``
    training cycles, ``sweep`` sizes on the same-condition pairs."""
    from suds_exp.campaign import SampleBank, enumerate_draws
    from suds_exp.campaign.bank import rounded_conditions
    from suds_exp.campaign.conditions import select_conditions
    from suds_exp.campaign.sampling import draw_sample

    chosen = select_conditions(SMALL, rounded_conditions(samples), "--x")
    bank = SampleBank.build(samples, chosen)
    jobs = []
    for d in enumerate_draws("bench", chosen, chosen, boots, cycles, sweep or []):
        s = draw_sample(bank, d, cycles)
        jobs.append(
            (bank.frame([bank.rows(*r) for r in s.train]), bank.frame([bank.rows(*s.test)]))
        )
        if len(jobs) == limit:
            break
    return jobs


def fresh_store(folder: Path, tag: str):
    """A new, migrated database: creating the schema is a once-per-database cost."""
    from suds_exp.store import Store

    store = Store(folder / f"{tag}_{time.perf_counter_ns()}.duckdb")
    store.upgrade()
    return store


#: The paper's learners in both prediction modes of the SUDS variants.
PAPER = [
    ("phase-only", {}),
    ("TLS", {}),
    ("TLS+SUDS", {}),
    ("TLS+SUDS", {"mode": "rollout"}),
    ("GMR", {}),
    ("GMR+SUDS", {}),
    ("GMR+SUDS", {"mode": "rollout"}),
]

#: GMR's augmentation, branching and K-selection variants.
GMR_VARIANTS = [
    ("GMR", {"augment": "dilation"}),
    ("GMR", {"augment": "none", "branching": "filter"}),
    ("GMR+SUDS", {"branching": "history"}),
    ("GMR+SUDS", {"branching": "filter", "mode": "rollout"}),
    ("GMR", {"select_k": "bic", "k_candidates": (4, 8)}),
]

#: The survey's scikit-learn baselines (suds_exp/models/baselines.py).
SURVEY = [
    ("MLP", {"random_state": 0}),
    ("MLP+SUDS", {"random_state": 0}),
    ("MLP+SUDS", {"random_state": 0, "mode": "rollout"}),
    ("GBT", {"random_state": 0}),
    ("kNN", {}),
    ("KRR", {"random_state": 0}),
]


def swimmer_samples(n_cycles: int, gait: str, frequency_hz: float, seed: int, trial_id: int):
    """One trial of the closed-form rate-independent swimmer (passive="travel",
    velocity="finsler") with noise on r_p and dr_p/dt: the samples frame of
    `suds_exp.testing.synthetic_swimmer.make_samples`, trial id `trial_id`."""
    from suds_exp.testing.synthetic_swimmer import make_samples

    return make_samples(
        n_cycles,
        gait=gait,
        frequency_hz=frequency_hz,
        passive="travel",
        velocity="finsler",
        noise_r=0.005,
        noise_dr=0.05,
        seed=seed,
        first_trial_id=trial_id,
    )


#: A simulated design small enough for a smoke run (keywords of `simulate_dataset`): 2
#: gaits x 2 frequencies x 2 repeats of 4 cycles.
QUICK_DESIGN = {"gaits": ("O", "D+"), "frequencies_hz": (0.5, 1.0), "repeats": 2, "cycles": (4, 4)}


def simulated_database(db: Path, design: dict | None = None, seed: int = 0, config=None) -> str:
    """Simulate ``design`` (keywords of `simulate_dataset`; default the paper's) with the
    robot ``config`` (default nominal), ingest it into the new database ``db`` and
    preprocess it with the defaults; returns the preprocessing version's name."""
    from suds_exp.ingest import ingest_paths
    from suds_exp.preprocess import preprocess
    from suds_exp.sim import simulate_dataset
    from suds_exp.store import Store

    store = Store(db)
    store.upgrade()
    with tempfile.TemporaryDirectory(prefix="suds-bench-data-") as tmp:
        data = simulate_dataset(tmp, config, seed=seed, **(design or {}))
        ingest_paths(store, [Path(tmp)], manifest=data.manifest, progress=False)
    return preprocess(store, progress=False).name


def ensure_data(store, gaits: list[str]) -> None:
    """The survey studies' data: the default design's ``gaits`` simulated, ingested and
    preprocessed as ``v1`` in ``store``, each step when the database does not hold it yet."""
    from suds_exp.ingest import ingest_paths, list_trials
    from suds_exp.preprocess import list_versions, preprocess
    from suds_exp.sim.dataset import simulate_dataset

    store.upgrade()
    if list_trials(store).empty:
        with tempfile.TemporaryDirectory() as folder:
            sim = simulate_dataset(folder, gaits=gaits)
            ingest_paths(store, [Path(folder)], sim.manifest, None, progress=False)
    if "v1" not in list_versions(store)["name"].astype(str).tolist():
        preprocess(store, name="v1", progress=False)


def decimated(store, prep: str) -> pd.DataFrame:
    """The version's samples, every trial decimated (plain, from its first sample) to the
    smallest samples per cycle of the whole dataset, as `campaign.bank` does for a grid
    over every condition."""
    import numpy as np

    from suds_exp.preprocess import get_version

    frame = get_version(store, prep).samples().sort_values(["trial_id", "t"])
    per_trial = frame.groupby("trial_id").agg(
        dt=("t", lambda t: float(np.median(np.diff(t.to_numpy())))), hz=("frequency_hz", "first")
    )
    spc = 1.0 / (per_trial["dt"] * per_trial["hz"])
    step = (spc / round(float(spc.min()))).round().clip(lower=1).astype(int)
    index = frame.groupby("trial_id").cumcount().to_numpy()
    return frame[index % step.reindex(frame["trial_id"]).to_numpy() == 0]
