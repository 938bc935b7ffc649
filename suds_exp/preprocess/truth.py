"""Compare a version's samples with simulator truth files (``<trial>.truth.parquet``).

The truth file sits beside the capture file and has one row per frame (`t`, body-frame
`vx`, `vy`, `wz`, `phi1`, `phi2`, commanded `phase_cmd`, ...). Errors are RMS over frames:
body velocity (mm/s, rad/s), r_a (rad, both joints pooled) and phase (rad, after removing
one constant offset per trial, since the phase zero is a Poincare section, not the
command's zero).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.errors import PreprocessError
from suds_exp.preprocess.version import get_version
from suds_exp.store import Store


def truth_path(source_file: str | Path) -> Path:
    """``/x/trial.tsv`` -> ``/x/trial.truth.parquet``."""
    source = Path(source_file)
    return source.with_name(source.stem + ".truth.parquet")


def _phase_error(phase: np.ndarray, cmd: np.ndarray) -> np.ndarray:
    diff = np.angle(np.exp(1j * (phase - cmd)))
    offset = np.angle(np.mean(np.exp(1j * diff)))
    return np.angle(np.exp(1j * (diff - offset)))


def truth_errors(store: Store, version: int | str) -> pd.DataFrame:
    """Per-trial errors of a version against the truth files, plus a pooled ``all`` row.

    Columns: ``trial_id`` (``-1`` = all trials pooled), ``gait``, ``frequency_hz``,
    ``n``, ``rms_vx_true`` (mm/s), ``err_vx``, ``err_vy`` (mm/s), ``err_wz`` (rad/s),
    ``err_ra`` (rad; NaN for a version with r_a as Cartesian values), ``err_phase`` (rad),
    and ``err_vx_band``, ``err_vy_band``,
    ``err_wz_band``: the body-velocity errors against the truth pose passed through the
    version's own differentiator, i.e. what the markers and the body frame cost, without
    the truth's content above the differentiator's band. Trials without a truth file are
    left out.
    """
    prep = get_version(store, version)
    samples, diff = prep.samples(), prep.differentiator()
    files = store.query_df("SELECT id, source_file, sample_rate_hz FROM trials")
    source = dict(zip(files.id, files.source_file, strict=True))
    rate = dict(zip(files.id, files.sample_rate_hz, strict=True))
    rows, pooled = [], []
    # r_a as Cartesian values (mm) has no joint angles to compare: err_ra is NaN then
    no_angles = np.nan if prep.params.get("ra_repr", "angles") != "angles" else 0.0
    for tid, s in samples.groupby("trial_id", sort=True):
        path = truth_path(source[tid])
        if not path.is_file():
            continue
        truth = pd.read_parquet(path)
        if len(truth) != len(s):
            raise PreprocessError(f"{path}: {len(truth)} rows, but trial {tid} has {len(s)} frames")
        heading = np.unwrap(truth.theta.to_numpy())
        window = diff.window(rate[tid], s.frequency_hz.iloc[0], len(truth))
        band = diff.body_velocity(truth[["x", "y"]].to_numpy(), heading, 1.0 / rate[tid], window)
        e = pd.DataFrame(
            {
                "vx": s.vx.to_numpy() - truth.vx.to_numpy(),
                "vy": s.vy.to_numpy() - truth.vy.to_numpy(),
                "wz": s.wz.to_numpy() - truth.wz.to_numpy(),
                "ra1": s.ra_1.to_numpy() - truth.phi1.to_numpy() + no_angles,
                "ra2": s.ra_2.to_numpy() - truth.phi2.to_numpy() + no_angles,
                "phase": _phase_error(s.phase.to_numpy(), truth.phase_cmd.to_numpy()),
                "vx_band": s.vx.to_numpy() - band[:, 0],
                "vy_band": s.vy.to_numpy() - band[:, 1],
                "wz_band": s.wz.to_numpy() - band[:, 2],
                "vx_true": truth.vx.to_numpy(),
            }
        )
        pooled.append(e)
        rows.append(_summary(e, tid, s.gait.iloc[0], s.frequency_hz.iloc[0]))
    if not rows:
        raise PreprocessError("no truth files (<trial>.truth.parquet) beside the version's trials")
    rows.append(_summary(pd.concat(pooled), -1, None, None))
    return pd.DataFrame(rows)


def _summary(e: pd.DataFrame, tid, gait, freq) -> dict:
    def rms(x):
        return float(np.sqrt(np.mean(np.square(x))))

    return {
        "trial_id": int(tid),
        "gait": gait,
        "frequency_hz": freq,
        "n": len(e),
        "rms_vx_true": rms(e.vx_true),
        "err_vx": rms(e.vx),
        "err_vy": rms(e.vy),
        "err_wz": rms(e.wz),
        "err_ra": rms(np.concatenate([e.ra1, e.ra2])),
        "err_phase": rms(e.phase),
        "err_vx_band": rms(e.vx_band),
        "err_vy_band": rms(e.vy_band),
        "err_wz_band": rms(e.wz_band),
    }
