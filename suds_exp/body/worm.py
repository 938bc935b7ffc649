"""A real crawling *C. elegans* end to end, checked against the tracker's own features.

A Worm Tracker 2 features file (`suds_exp.ingest.worm_tracker`) is ingested, described as
a chain of skeleton points and preprocessed; its undulation and motion are compared with
what the Schafer lab's code measured on the same skeleton (Yemini et al. 2013):

- our phase rate (Hz) against the median magnitude of the midbody bend frequency (the
  tracker signs it by the side of the current bend, so the sign alternates within a
  cycle and the median of the signed values mixes the two sides);
- our mean forward speed (vx, mm/s) against the median midbody speed (signed, + towards
  the head);
- our number of waves along the body (the phase of shape modes 1 + i 2 from head to
  tail, scaled from the span of the chord angles to the whole skeleton) against the
  median length over the median primary wavelength.

The learners are then fitted on the earlier phase cycles and tested on the later ones.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from suds_exp.body.description import Body, parse_body
from suds_exp.body.prep import preprocess_body
from suds_exp.body.real_snake import CHAIN_MODELS, holdout_by_cycles, split_errors, wave_summary
from suds_exp.errors import IngestError
from suds_exp.ingest import ingest_paths
from suds_exp.ingest.worm_tracker import skeleton_names
from suds_exp.preprocess import get_version
from suds_exp.store import Store

#: Preprocessing of a WT2 recording: the tracker blanks 5-8 frames (up to 0.27 s at
#: 30 fps) around each stage movement, longer than the swimmer's 0.25 s gap limit.
WORM_PARAMS = {"max_gap_s": 0.3}
#: Every 4th skeleton point (13 of 49, p01 .. p49): the 49 points lie ~18 um apart, so
#: the angles between their chords are mostly the skeleton's pixel noise (shape modes 1-2
#: explain 24 % of the angles' variance with 49 points, 95 % with 13); phase rate and
#: speed do not depend on the choice (docs/results/worm.md).
POINT_STEP = 4


def worm_body(step: int = POINT_STEP, modes: int = 4) -> Body:
    """The worm as a chain of every ``step``-th skeleton point, head to tail."""
    names = skeleton_names()[::step]
    listed = ", ".join(f'"{n}"' for n in names)
    text = f'name = "C. elegans, WT2 skeleton"\n[chain]\nmarkers = [{listed}]\nmodes = {modes}\n'
    return parse_body(text, f"worm body (every {step}th skeleton point)")


def tracker_reference(path: str | Path) -> dict:
    """The tracker's own features of a WT2 file (medians over the frames that have them).

    Returns ``bend_frequency_hz`` (median |midbody bend frequency|),
    ``bend_frequency_signed_hz`` (median of the signed values), ``speed_mm_s`` (median
    midbody speed), ``length_mm``, ``wavelength_mm`` (primary), ``waves_along_body``
    (length / wavelength) and ``n_frames`` with a bend frequency.
    """
    from scipy.io import loadmat

    path = Path(path)
    try:
        worm = loadmat(io.BytesIO(path.read_bytes()), squeeze_me=True, struct_as_record=False)[
            "worm"
        ]
        frequency = np.asarray(worm.locomotion.bends.midbody.frequency, dtype=float)
        speed = np.asarray(worm.locomotion.velocity.midbody.speed, dtype=float)
        length = float(np.nanmedian(worm.morphology.length)) / 1000.0
        wavelength = float(np.nanmedian(worm.posture.wavelength.primary)) / 1000.0
    except (KeyError, AttributeError, ValueError, OSError) as exc:
        raise IngestError(f"{path}: no Worm Tracker 2 features ({exc})") from None
    return {
        "bend_frequency_hz": float(np.nanmedian(np.abs(frequency))),
        "bend_frequency_signed_hz": float(np.nanmedian(frequency)),
        "speed_mm_s": float(np.nanmedian(speed)) / 1000.0,
        "length_mm": length,
        "wavelength_mm": wavelength,
        "waves_along_body": length / wavelength,
        "n_frames": int(np.isfinite(frequency).sum()),
    }


def run_worm(
    features: str | Path,
    db: str | Path,
    train_cycles: int | None = None,
    step: int = POINT_STEP,
    models=CHAIN_MODELS,
) -> dict:
    """Ingest a WT2 features file, preprocess it as a chain, compare, fit and test.

    ``train_cycles``: phase cycles the learners train on (default: the first two thirds of
    the complete ones); the later cycles test. Returns ``version``,
    ``explained_variance_ratio``, ``phase_rate_hz``, ``waves_along_body`` (between the
    first and last chord angles), ``waves_per_body_length`` (the same scaled to the whole
    skeleton, head to tail),
    ``forward_speed_mm_s`` (mean vx), ``n_samples``, ``n_cycles`` (complete cycles),
    ``train_cycles``, ``reference`` (`tracker_reference`) and ``errors`` (a DataFrame, rows
    as `suds_exp.body.real_snake.holdout_errors`) and ``in_sample`` (the same rows, fitted
    and scored on every cycle).
    """
    store = Store(db)
    ingest_paths(store, [Path(features)], progress=False)
    result = preprocess_body(store, worm_body(step), None, WORM_PARAMS, progress=False)
    version = get_version(store, result.version_id)
    samples = version.samples()
    waves = wave_summary(samples, version.pca.components_)
    # the angles sit at the inner points: they span (n - 3) of the n - 1 equal chords
    n_points = len(worm_body(step).chain.markers)
    waves["waves_per_body_length"] = waves["waves_along_body"] * (n_points - 1) / (n_points - 3)
    sizes = samples.groupby("cycle").size()
    complete = int((sizes >= 0.5 * sizes.median()).sum())
    if train_cycles is None:
        train_cycles = int(round(2 * complete / 3))
    return {
        "version": result.version_id,
        "explained_variance_ratio": result.explained_variance_ratio,
        **waves,
        "forward_speed_mm_s": float(samples.vx.mean()),
        "n_samples": len(samples),
        "n_cycles": complete,
        "train_cycles": train_cycles,
        "reference": tracker_reference(features),
        "errors": holdout_by_cycles(samples, train_cycles, models),
        # how much of vx the phase and shape explain at all, fitted and scored on every cycle
        "in_sample": split_errors(samples, samples, models),
    }
