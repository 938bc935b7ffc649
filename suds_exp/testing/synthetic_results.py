"""Synthetic ``results`` rows with effects of known size, for tests, benchmarks and demos
(and `finished_rows`: rows that stand for a finished campaign).

Each learner result's ``100 ln(rmse_vx)`` is a sum of planted GLM coefficients (named as
the GLM table names its terms), a power law in the number of training cycles, and
Gaussian noise; phase-only results get the intercept plus an offset. So fitting the GLM
and the sample-efficiency slopes to these rows should give back what was planted.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pandas as pd

from suds_exp.models.registry import (
    GMR,
    GMR_SUDS,
    LEARNERS,
    PHASE_ONLY,
    SUDS_SUFFIX,
    TLS,
    TLS_SUDS,
)
from suds_exp.robot import FREQUENCIES_HZ, GAITS

#: The paper's first-order-interactions GLM (its Table "GLM coefficient comparison"), used
#: as the default truth so a synthetic report can be read beside the paper's.
PAPER_INTERACTIONS = {
    "Intercept": 91.36,
    "GMR": -56.32,
    "SUDS": -47.53,
    "SUDS:GMR": 40.36,
    "model-period<data-period": -19.80,
    "model-period=data-period": -18.98,
    "SUDS:(model-period<data-period)": 17.34,
    "GMR:(model-period<data-period)": 15.99,
    "GMR:(model-period=data-period)": 10.11,
    "SUDS:(model-period=data-period)": 8.52,
    "GMR:(model-gait far from data-gait)": 6.59,
    "(model-period<data-period):(model-gait far from data-gait)": 5.73,
    "SUDS:(model-gait far from data-gait)": 4.52,
    "(model-period=data-period):(model-gait far from data-gait)": 4.01,
    "model-gait=data-gait": -4.07,
    "(model-period=data-period):(model-gait=data-gait)": -3.02,
    "model-gait far from data-gait": -1.58,
    "(model-period<data-period):(model-gait=data-gait)": -1.34,
    "SUDS:(model-gait=data-gait)": -0.26,
    "GMR:(model-gait=data-gait)": -0.19,
}

#: Default log-log slopes of RMS error against training cycles.
DEFAULT_SLOPES = {PHASE_ONLY: 0.0, TLS: -0.05, TLS_SUDS: -0.1, GMR: -0.3, GMR_SUDS: -0.5}


def _indicators(frame: pd.DataFrame) -> dict[str, np.ndarray]:
    return {
        "SUDS": frame["model"].str.endswith(SUDS_SUFFIX).to_numpy(),
        "GMR": frame["model"].str.startswith(GMR).to_numpy(),
        "model-period<data-period": (
            frame["train_frequency_hz"] > frame["test_frequency_hz"] + 1e-9
        ).to_numpy(),
        "model-period=data-period": (
            np.abs(frame["train_frequency_hz"] - frame["test_frequency_hz"]) <= 1e-9
        ).to_numpy(),
        "model-gait=data-gait": (frame["_steps"] == 0).to_numpy(),
        "model-gait far from data-gait": (frame["_steps"] > 1).to_numpy(),
    }


def term_indicator(term: str, basic: dict[str, np.ndarray]) -> np.ndarray:
    """0/1 column of a GLM term named as the GLM table names it (``A:(B)`` = A and B)."""
    n = len(next(iter(basic.values())))
    if term == "Intercept":
        return np.ones(n)
    out = np.ones(n)
    for part in term.split(":"):
        out = out * basic[part.strip("()")]
    return out


def synthetic_results(
    campaign: str = "synthetic",
    effects: dict[str, float] | None = None,
    *,
    n_boot: int = 4,
    n_cycles=(30,),
    slopes: dict[str, float] | None = None,
    phase_only_offset: float = 60.0,
    noise: float = 30.0,
    models=LEARNERS,
    seed: int = 0,
) -> pd.DataFrame:
    """Rows in the ``results`` table's columns, one per (model, train, test, n_cycles, boot).

    Parameters
    ----------
    campaign : str
    effects : dict term -> coefficient, optional
        Planted GLM coefficients on the ``100 ln(rmse_vx / (mm/s))`` scale, for the learner
        rows; terms absent are 0. Default `PAPER_INTERACTIONS`.
    n_boot : int
        Bootstrap repeats per (model, train condition, test condition, n_cycles).
    n_cycles : sequence of int
        Training sizes; every size gets the full 15 x 15 condition grid.
    slopes : dict model -> float, optional
        Log-log slope of RMS error against ``n_cycles`` (relative to the largest size);
        default `DEFAULT_SLOPES`.
    phase_only_offset : float
        Phase-only results: intercept plus this, on the same scale.
    noise : float
        Standard deviation of the Gaussian noise on the ``100 ln`` scale.
    models : sequence of str
    seed : int

    Returns
    -------
    DataFrame with the ``results`` columns (``rmse_vx``, ``rmse_vy`` mm/s, ``rmse_wz`` rad/s).
    """
    effects = dict(PAPER_INTERACTIONS if effects is None else effects)
    slopes = {**DEFAULT_SLOPES, **(slopes or {})}
    rng = np.random.default_rng(seed)
    grid = _job_grid(models, n_cycles, n_boot)
    y = _planted_log_rmse(grid, effects, slopes, phase_only_offset, max(n_cycles))
    y += rng.normal(0.0, noise, len(grid))
    grid["rmse_vx"] = np.exp(y / 100.0)
    _fill_bookkeeping(grid, campaign, rng)
    return grid.drop(columns="_steps")


def finished_rows(keys, campaign: str, n_cycles: int, rmse_vx=1.0) -> pd.DataFrame:
    """One stored-looking ``results`` row for each job of ``keys`` as if it had run (no
    learner runs): to stand for a finished campaign, as when resuming one.

    Parameters
    ----------
    keys : sequence of (draw, model name)
        A draw as `suds_exp.campaign.Draw`: ``train`` and ``test`` (gait, frequency Hz)
        and ``boot``.
    campaign : str
    n_cycles : int
        Training cycles of every job (its ranges span that many cycles).
    rmse_vx : float or array of one per key
        mm/s; the other errors, the trials and the timings are constants.

    Returns
    -------
    DataFrame with the ``results`` columns (select ``RESULT_COLUMNS`` for their order).
    """
    return pd.DataFrame(
        {
            "campaign": campaign,
            "model": [m for _, m in keys],
            "train_gait": [d.train[0] for d, _ in keys],
            "train_frequency_hz": [d.train[1] for d, _ in keys],
            "test_gait": [d.test[0] for d, _ in keys],
            "test_frequency_hz": [d.test[1] for d, _ in keys],
            "boot": [d.boot for d, _ in keys],
            "n_cycles": n_cycles,
            "train_trials": "[1]",
            "train_ranges": f"[[1, 0, {n_cycles - 1}]]",
            "test_trial": 2,
            "test_range": f"[0, {n_cycles - 1}]",
            "rmse_vx": rmse_vx,
            "rmse_vy": 1.0,
            "rmse_wz": 0.1,
            "n_test": 100,
            "fit_seconds": 0.1,
            "predict_seconds": 0.01,
            "finished_at": pd.Timestamp("2026-01-01"),
            "error": None,
        }
    )


def _job_grid(models, n_cycles, n_boot: int) -> pd.DataFrame:
    """One row per (model, train condition, test condition, n_cycles, boot), with the
    gait-axis distance between train and test gaits in ``_steps``."""
    conditions = [(g, round(f, 6)) for g in GAITS for f in FREQUENCIES_HZ]
    grid = pd.DataFrame(
        [
            (m, tg, tf, dg, df, n, b)
            for m, (tg, tf), (dg, df), n, b in itertools.product(
                models, conditions, conditions, n_cycles, range(n_boot)
            )
        ],
        columns=[
            "model",
            "train_gait",
            "train_frequency_hz",
            "test_gait",
            "test_frequency_hz",
            "n_cycles",
            "boot",
        ],
    )
    pos = {g: i for i, g in enumerate(GAITS)}
    grid["_steps"] = np.abs(grid["train_gait"].map(pos) - grid["test_gait"].map(pos))
    return grid


def _planted_log_rmse(
    grid: pd.DataFrame, effects: dict, slopes: dict, phase_only_offset: float, max_cycles: int
) -> np.ndarray:
    """``100 ln(rmse_vx)`` of each row without noise, shape (n_rows,): the planted GLM
    terms, phase-only's offset and each model's log-log slope in ``n_cycles``."""
    basic = _indicators(grid)
    y = np.zeros(len(grid))
    for term, coef in effects.items():
        y += coef * term_indicator(term, basic)
    phase_only = (grid["model"] == PHASE_ONLY).to_numpy()
    y[phase_only] = effects.get("Intercept", 0.0) + phase_only_offset
    slope = grid["model"].map(slopes).fillna(0.0).to_numpy()
    y += 100.0 * slope * np.log(grid["n_cycles"].to_numpy() / max_cycles)
    return y


def _fill_bookkeeping(grid: pd.DataFrame, campaign: str, rng: np.random.Generator) -> None:
    """The ``results`` columns other than ``rmse_vx``, in place: rmse_vy (mm/s) and
    rmse_wz (rad/s) as noise, trials, ranges, timings."""
    n = len(grid)
    grid["rmse_vy"] = np.exp(rng.normal(0.0, 0.3, n))
    grid["rmse_wz"] = np.exp(rng.normal(-3.0, 0.3, n))
    grid["campaign"] = campaign
    trial = rng.integers(1, 61, size=(n, 2))
    grid["train_trials"] = [json.dumps([int(t)]) for t in trial[:, 0]]
    grid["train_ranges"] = [
        json.dumps([[int(t), 0, int(c) - 1]])
        for t, c in zip(trial[:, 0], grid["n_cycles"], strict=True)
    ]
    grid["test_trial"] = trial[:, 1]
    grid["test_range"] = json.dumps([0, 9])
    grid["n_test"] = 1000
    grid["fit_seconds"] = rng.uniform(0.01, 1.0, n)
    grid["predict_seconds"] = rng.uniform(0.01, 0.1, n)
    grid["finished_at"] = pd.Timestamp("2026-01-01")
