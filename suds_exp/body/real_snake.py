"""Real recordings end to end: a flying-snake glide through ingest, a chain description,
preprocessing and learners fitted on one part of the glide and tested on the rest.

The campaign machinery draws train and test sets by condition (gait, frequency); a
recorded animal has neither, so this fits the learners directly: the first
``train_fraction`` of each trial's frames train, the rest test (a later stretch of the
same glide, never seen in training). Errors follow the paper's metric, RMS error of vx
as a percentage of the RMS of the true vx, beside a constant predictor (the training
mean), without which the figures cannot be read.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.body.description import load_body
from suds_exp.body.prep import preprocess_body
from suds_exp.ingest import ingest_paths
from suds_exp.models import make_model
from suds_exp.models.registry import GMR, PHASE_ONLY, TLS
from suds_exp.preprocess import get_version
from suds_exp.store import Store

#: Learners compared on a chain (the +SUDS ones need passive states a snake has not).
CHAIN_MODELS = (PHASE_ONLY, TLS, GMR)


def holdout_errors(
    samples: pd.DataFrame, models=CHAIN_MODELS, train_fraction: float = 0.7
) -> pd.DataFrame:
    """Fit each learner on the first ``train_fraction`` of every trial, test on the rest.

    Returns one row per learner (and ``constant``: the training mean) with ``vx_pct``,
    ``vy_pct`` (RMS error as % of the test RMS of vx) and ``wz_pct`` (% of the test RMS
    of wz), and the numbers of train and test samples.
    """
    position = samples.groupby("trial_id").cumcount()
    size = samples.groupby("trial_id").trial_id.transform("size")
    is_train = position < np.floor(train_fraction * size)
    return split_errors(samples[is_train], samples[~is_train], models)


def holdout_by_cycles(samples: pd.DataFrame, train_cycles: int, models=CHAIN_MODELS):
    """Fit each learner on the first ``train_cycles`` phase cycles of every trial (its
    ``cycle`` below the trial's first cycle + ``train_cycles``), test on the later ones.
    Rows as `holdout_errors`."""
    first = samples.groupby("trial_id").cycle.transform("min")
    is_train = samples.cycle < first + train_cycles
    return split_errors(samples[is_train], samples[~is_train], models)


def split_errors(train: pd.DataFrame, test: pd.DataFrame, models=CHAIN_MODELS) -> pd.DataFrame:
    """Each learner fitted on ``train`` and tested on ``test`` (samples frames), beside
    the constant predictor (the training mean): rows as `holdout_errors`."""
    rms_vx = float(np.sqrt(np.mean(test.vx**2)))
    rms_wz = float(np.sqrt(np.mean(test.wz**2)))

    def row(name: str, pred: pd.DataFrame) -> dict:
        err = {c: float(np.sqrt(np.mean((pred[c] - test[c]) ** 2))) for c in ("vx", "vy", "wz")}
        return {
            "model": name,
            "vx_pct": 100 * err["vx"] / rms_vx,
            "vy_pct": 100 * err["vy"] / rms_vx,
            "wz_pct": 100 * err["wz"] / rms_wz,
            "n_train": len(train),
            "n_test": len(test),
        }

    constant = pd.DataFrame({c: np.full(len(test), train[c].mean()) for c in ("vx", "vy", "wz")})
    rows = [row("constant", constant.set_index(test.index))]
    for name in models:
        rows.append(row(name, make_model(name).fit(train).predict(test)))
    return pd.DataFrame(rows)


def wave_summary(samples: pd.DataFrame, loadings: np.ndarray) -> dict:
    """Undulation figures: phase rate (Hz, slope of the unwrapped phase), and the number
    of waves along the body from the first two shape modes (the phase of mode 1 + i mode 2
    unwrapped from head to tail, over 2 pi)."""
    rates = [
        abs(np.polyfit(g.t, g.phase, 1)[0]) / (2 * np.pi) for _, g in samples.groupby("trial_id")
    ]
    spatial = np.unwrap(np.angle(loadings[0] + 1j * loadings[1]))
    return {
        "phase_rate_hz": [float(r) for r in rates],
        "waves_along_body": float(abs(spatial[-1] - spatial[0]) / (2 * np.pi)),
    }


def run_real_snake(
    captures: list[Path], body_file: Path, db: Path, train_fraction: float = 0.7
) -> dict:
    """Ingest ``captures``, preprocess them with the chain ``body_file``, fit and test.

    Returns ``{"version": ..., "explained_variance_ratio": [...], "phase_rate_hz": [...],
    "waves_along_body": ..., "errors": DataFrame (see `holdout_errors`)}``.
    """
    store = Store(db)
    ingest_paths(store, list(captures), progress=False)
    # the snake glides at ~7 m/s (~40 mm a frame at 179 Hz): the swimmer's 9 mm jump
    # threshold would call its motion jumps
    result = preprocess_body(store, load_body(body_file), None, {"jump_mm": 30}, progress=False)
    version = get_version(store, result.version_id)
    samples = version.samples()
    loadings = version.pca.components_
    return {
        "version": result.version_id,
        "explained_variance_ratio": result.explained_variance_ratio,
        **wave_summary(samples, loadings),
        "errors": holdout_errors(samples, train_fraction=train_fraction),
    }
