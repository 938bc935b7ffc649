"""`preprocess`: markers -> samples as a stored, versioned parameter set.

A run resolves its version (same parameters = same version), reads the markers of the
trials not yet done, cleans them and measures their geometry (any refused trial stops the
run before anything is written), fits what the version lacks (segment origins, passive
PCA, one Phaser per trial group) on those trials and stores it, then writes the trials'
samples with their stats in batches, each batch in one transaction. An interrupted run
therefore resumes with the trials not yet done, reusing the stored fit. Versions are read
and written in `version.py`.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
import sqlalchemy as sa

from suds_exp.errors import PreprocessError
from suds_exp.preprocess.body_model import BodyModel, SwimmerModel, require_markers
from suds_exp.preprocess.clean import CleanResult, clean_tracks
from suds_exp.preprocess.kinematics import Kinematics
from suds_exp.preprocess.params import params_hash, resolve_params
from suds_exp.preprocess.phaser import Phaser, cycles
from suds_exp.preprocess.rates import Differentiator, smooth, window_frames
from suds_exp.preprocess.reduction import passive_reducer
from suds_exp.preprocess.shape import PassivePCA
from suds_exp.preprocess.version import (
    NewFit,
    PrepResult,
    find_version,
    kept_ratio,
    stored_progress,
    write_trials,
    write_version,
)
from suds_exp.progress import progress_bar
from suds_exp.robot import DRP_COLUMNS, RP_COLUMNS
from suds_exp.store import Store
from suds_exp.store.tables import trials

#: A 2-D track (keypoints: z stored NULL where x, y are present) lies in the plane z = 0.
PLANAR_Z = "CASE WHEN missing THEN z ELSE coalesce(z, 0) END"

#: Trials are written in batches of about this many frames, one transaction each (fewer
#: transactions are faster; a batch is what an interrupted run may have to redo).
WRITE_BATCH_FRAMES = 50_000


@dataclass
class _Trial:
    """One trial in flight: metadata, cleaned tracks, measured geometry, kinematics."""

    id: int
    label: str
    group: str
    rate_hz: float
    frequency_hz: float | None
    frame: np.ndarray
    t: np.ndarray
    clean: CleanResult
    measured: Any  # the body model's per-trial geometry (`BodyModel.measure`)
    kin: Kinematics | None = None


def _group_key(kind: str, trial_id: int, gait: str | None, frequency_hz: float | None) -> str:
    if kind == "all":
        return "all"
    if kind == "trial" or gait is None:
        return f"trial:{trial_id}"
    if kind == "gait":
        return gait
    return f"{gait}@{round(float(frequency_hz), 6):g}"


# -- reading ------------------------------------------------------------------------------
def _read_tracks(conn: sa.Connection, meta: pd.DataFrame, model: BodyModel) -> dict[int, tuple]:
    """trial id -> (frame (n,), t (n,), xyz (n, n_labels, 3) in the order of
    ``model.labels``, NaN = missing).

    Trials sharing a marker layout are read in one query that maps marker names to label
    numbers in SQL, so only numbers cross into Python.
    """
    out = {}
    labels = model.labels
    by_layout: dict[tuple[str, ...], list[int]] = {}
    for tid, stored in zip(meta.id, meta.layout, strict=True):
        names = model.marker_names(stored if isinstance(stored, str) else None)
        by_layout.setdefault(tuple(names), []).append(int(tid))
    for names, ids in by_layout.items():
        df = Store.frame(
            conn,
            "SELECT trial_id, frame, t, list_position($names, marker) - 1 AS role, x, y, "
            f"{PLANAR_Z} AS z "
            "FROM markers WHERE trial_id IN (SELECT unnest($ids::INTEGER[])) "
            "AND list_contains($names, marker) ORDER BY trial_id, frame, role",
            {"names": list(names), "ids": ids},
        )
        tid_col = df.trial_id.to_numpy()
        bounds = np.searchsorted(tid_col, ids + [np.iinfo(np.int32).max], side="left")
        for j, tid in enumerate(ids):
            part = df.iloc[bounds[j] : bounds[j + 1]]
            role = part.role.to_numpy()
            require_markers(model, tid, np.unique(role))
            values = part[["x", "y", "z"]].to_numpy(dtype=float)
            frame_col = part.frame.to_numpy()
            n = len(part) // len(labels)
            if len(part) == n * len(labels) and np.array_equal(
                role, np.tile(np.arange(len(labels)), n)
            ):
                xyz = values.reshape(n, len(labels), 3)
                frames = frame_col[:: len(labels)]
                t = part.t.to_numpy()[:: len(labels)]
            else:  # a frame lacks some marker rows: scatter
                frames, inverse = np.unique(frame_col, return_inverse=True)
                xyz = np.full((len(frames), len(labels), 3), np.nan)
                xyz[inverse, role] = values
                t = np.zeros(len(frames))
                t[inverse] = part.t.to_numpy()
            out[tid] = (frames, t, xyz)
    return out


#: The columns of `trials` the standard pipeline reads.
META_COLUMNS = ("id", "source_file", "gait", "frequency_hz", "sample_rate_hz", "n_frames", "layout")


def trial_meta(
    conn: sa.Connection, trial_ids: Iterable[int] | None, columns: Sequence[str] = META_COLUMNS
) -> pd.DataFrame:
    """The rows of `trials` with ids ``trial_ids`` (None: every trial), by id, with
    ``columns``; a `PreprocessError` names any id the store does not hold."""
    wanted = None if trial_ids is None else sorted({int(i) for i in trial_ids})
    query = sa.select(*(trials.c[c] for c in columns)).order_by(trials.c.id)
    meta = Store.frame(conn, query)
    if wanted is not None:
        unknown = sorted(set(wanted) - set(int(i) for i in meta.id))
        if unknown:
            raise PreprocessError(
                f"trials: no trial with id {', '.join(map(str, unknown))}; see the stored trials",
                param="trials",
                step="trials",
            )
        meta = meta[meta.id.isin(wanted)]
    return meta.reset_index(drop=True)


# -- per-trial computation ------------------------------------------------------------------
def _prepare(meta_row, tracks, params: dict, model: BodyModel) -> _Trial:
    tid = int(meta_row.id)
    label = f"trial {tid} ({meta_row.source_file})"
    frame, t, xyz = tracks
    rate = float(meta_row.sample_rate_hz)
    if len(frame) < 8:
        raise PreprocessError(f"{label}: only {len(frame)} frames; need at least 8")
    max_gap = int(np.floor(params["max_gap_s"] * rate + 1e-9))
    try:
        cleaned = clean_tracks(xyz, params["jump_mm"], max_gap, [f"{r}" for r in model.labels])
        measured = model.measure(cleaned.xyz, params, cleaned.filled)
    except PreprocessError as exc:
        raise PreprocessError(f"{label}: {exc}", param=exc.param) from None
    gait = meta_row.gait if isinstance(meta_row.gait, str) else None
    freq = None if pd.isna(meta_row.frequency_hz) else float(meta_row.frequency_hz)
    group = _group_key(params["phaser_group"], tid, gait, freq)
    return _Trial(tid, label, group, rate, freq, frame, t, cleaned, measured)


#: Phaser channel order of the Cartesian r_a (head x, head y, tail x, tail y): the y values
#: first, since Phaser's channel 0 sets the Poincare section and the reference rate, and a
#: segment's x (cos of its angle) goes round twice per gait cycle.
_CARTESIAN_PHASER_ORDER = [1, 3, 0, 2]


def _phaser_input(tr: _Trial, pca: PassivePCA, params: dict) -> np.ndarray:
    ra, passive = _smoothed(tr, params)
    if params.get("ra_repr", "angles") == "cartesian":
        ra = ra[:, _CARTESIAN_PHASER_ORDER]
    if params["phaser_channels"] == "ra+rp":
        return np.column_stack([ra, pca.transform(passive)])
    return ra


def _smoothed(tr: _Trial, params: dict) -> tuple[np.ndarray, np.ndarray]:
    w = window_frames(params["shape_window_s"], tr.rate_hz, params["shape_polyorder"], len(tr.t))
    return smooth(tr.kin.ra, w, params["shape_polyorder"]), smooth(
        tr.kin.passive, w, params["shape_polyorder"]
    )


def _samples_frame(tr: _Trial, version_id: int, pca: PassivePCA, phaser: Phaser, params: dict):
    k = params["k"]
    dt = 1.0 / tr.rate_hz
    ra, passive = _smoothed(tr, params)
    diff = Differentiator.from_params(params)
    w = diff.window(tr.rate_hz, tr.frequency_hz, len(tr.t))
    dra = diff(tr.kin.ra, dt, w)
    drp = pca.transform_rate(diff(tr.kin.passive, dt, w), passive)
    rp = pca.transform(passive)
    vb = diff.body_velocity(tr.kin.xy, tr.kin.heading, dt, w)
    phase = phaser.transform(_phaser_input(tr, pca, params))
    n = len(tr.t)
    cols: dict[str, Any] = {
        "version_id": np.full(n, version_id, dtype=np.int32),
        "trial_id": np.full(n, tr.id, dtype=np.int32),
        "frame": tr.frame.astype(np.int32),
        "t": tr.t,
        "phase": phase,
        "cycle": cycles(phase).astype(np.int32),
    }
    for i in range(ra.shape[1]):
        cols[f"ra_{i + 1}"] = ra[:, i]
    for i in range(ra.shape[1]):
        cols[f"dra_{i + 1}"] = dra[:, i]
    for i in range(len(RP_COLUMNS)):
        cols[RP_COLUMNS[i]] = rp[:, i] if i < k else np.full(n, np.nan)
        cols[DRP_COLUMNS[i]] = drp[:, i] if i < k else np.full(n, np.nan)
    cols.update(vx=vb[:, 0], vy=vb[:, 1], wz=vb[:, 2])
    return pd.DataFrame(cols)


def _stats_row(tr: _Trial, version_id: int, joints: Any, model: BodyModel) -> dict:
    c = tr.clean
    normal, length, rms = model.stats(tr.measured, joints)
    return {
        "version_id": version_id,
        "trial_id": tr.id,
        "n_frames": len(tr.t),
        "n_jumps": c.n_jumps,
        "removed_fraction": c.removed_fraction,
        "filled_fraction": c.filled_fraction,
        "longest_gap_frames": c.longest_gap,
        "plane_normal": normal,
        "middle_length_mm": length,
        "joint_rms_mm": rms,
        "phaser_group": tr.group,
        "done_at": pd.Timestamp.now(tz="UTC").tz_localize(None),
    }


# -- the run ------------------------------------------------------------------------------
@dataclass
class Fitted:
    """What a version holds for its trials: segment origins by trial id, the passive PCA,
    one Phaser per trial group, the fits this run made (`NewFit`, not yet stored) and
    one line per thing those fits could not pin down."""

    joints: dict[int, Any]
    pca: PassivePCA
    phasers: dict[str, Phaser]
    new: list[NewFit] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)


def preprocess(
    store: Store,
    name: str | None = None,
    params: Mapping[str, Any] | None = None,
    trials: Iterable[int] | None = None,
    progress: bool = True,
    preset: str | None = None,
    body: BodyModel | None = None,
) -> PrepResult:
    """Create or reuse the preprocessing version of ``params`` and fill its samples.

    Parameters
    ----------
    store : Store
    name : str, optional
        Name of a new version (default ``v<id>``); a version with the same parameters is
        reused whatever its name. A name already used by other parameters is refused.
    params : mapping, optional
        Parameters over `suds_exp.preprocess.params.DEFAULTS` (values may be text).
    trials : iterable of int, optional
        Trial ids to process (default: every trial in the store).
    progress : bool
        Show progress bars on stderr.
    preset : str, optional
        A named parameter set (`suds_exp.preprocess.params.PRESETS`: ``default``,
        ``paper``) under ``params``.
    body : BodyModel, optional
        The body's geometry (`suds_exp.preprocess.body_model`; `suds_exp.body` makes one
        from a description of rigid segments); default the paper's swimmer.

    Returns
    -------
    PrepResult

    Raises `PreprocessError` (nothing written) for a trial that cannot be used, e.g. a
    gap longer than ``max_gap_s``; `ConfigError` for a bad parameter.
    """
    started = time.perf_counter()
    model = SwimmerModel() if body is None else body
    params = model.version_params(resolve_params(params, preset))
    # One writer at a time from reading what is done to the last sample stored: two
    # runs of the same version never both find a trial to do (store/lock.py).
    with store.locked("preprocess", name):
        return _preprocess(store, name, params, trials, progress, started, model)


def _preprocess(store, name, params, trials, progress, started, model) -> PrepResult:
    digest = params_hash(params)
    with store.write() as conn:
        row = find_version(conn, name, digest)
        meta = trial_meta(conn, trials)
        done, fits = stored_progress(conn, None if row is None else row.id)
        todo = meta[~meta.id.isin(done)]
        tracks = _read_tracks(conn, todo, model) if len(todo) else {}
    if meta.empty:
        raise PreprocessError("no trials to preprocess; ingest some first", step="ingest")
    result = new_result(row, name, params, digest, skipped=meta.id[meta.id.isin(done)])
    items = clean(todo, tracks, params, progress, model)
    if not items:
        result.explained_variance_ratio = kept_ratio(store, result.version_id, params["k"])
        result.seconds = time.perf_counter() - started
        return result
    fitted = fit(items, params, fits, model)
    write_version(store, result, fitted.new, fitted.pca, params["k"])
    write_samples(store, result, items, fitted, params, progress, model)
    result.explained_variance_ratio = fitted.pca.explained_variance_ratio_[: params["k"]].tolist()
    result.warnings = fitted.warnings
    result.seconds = time.perf_counter() - started
    return result


def new_result(row, name: str | None, params: dict, digest: str, skipped) -> PrepResult:
    """The `PrepResult` of a run on version ``row`` (None: to be created as ``name``)."""
    return PrepResult(
        version_id=row.id if row is not None else -1,
        name=row.name if row is not None else (name or ""),
        params_hash=digest,
        params=params,
        created=row is None,
        skipped=sorted(int(i) for i in skipped),
    )


def clean(
    todo: pd.DataFrame,
    tracks: dict[int, tuple],
    params: dict,
    progress: bool,
    model: BodyModel | None = None,
):
    """Clean and measure every trial of ``todo`` (rows of `trial_meta`, their tracks from
    `_read_tracks`); any refusal raises `PreprocessError` before anything is written."""
    model = SwimmerModel() if model is None else model
    items: list[_Trial] = []
    with progress_bar(
        "Cleaning", total=len(todo), enabled=progress and bool(len(todo)), unit="trials"
    ) as advance:
        for meta_row in todo.itertuples(index=False):
            items.append(_prepare(meta_row, tracks.pop(int(meta_row.id)), params, model))
            advance()
    return items


def fit(
    items: list[_Trial],
    params: dict,
    fits: dict[tuple[str, str], str],
    model: BodyModel | None = None,
) -> Fitted:
    """Fit what the version lacks (``fits``: its stored states by (kind, group)) on the
    trials of this run, and set each trial's kinematics."""
    model = SwimmerModel() if model is None else model
    new: list[NewFit] = []
    warnings: list[str] = []
    if params["joint_fit"] == "version":
        if ("joints", "") in fits:
            shared = model.joints_from(fits[("joints", "")])
        else:
            shared = model.fit_joints([tr.measured for tr in items], params)
            new.append(_new_fit("joints", "", model.joints_state(shared), items))
            warnings += [w for w in [model.joints_warning(shared)] if w]
        joints = {tr.id: shared for tr in items}
    else:
        joints = {tr.id: model.fit_joints([tr.measured], params) for tr in items}
        poor = {tid: w for tid, j in joints.items() if (w := model.joints_warning(j))}
        if poor:
            warnings.append(f"trials {', '.join(map(str, poor))}: {next(iter(poor.values()))}")
    for tr in items:
        tr.kin = model.kinematics(tr.measured, joints[tr.id], params, tr.rate_hz, tr.frequency_hz)
    # the passive reducer (PCA, kernel PCA or autoencoder: suds_exp.preprocess.reduction)
    pca, fitted = passive_reducer(
        params, fits, lambda: np.concatenate([_smoothed(tr, params)[1] for tr in items])
    )
    if fitted is not None:
        new.append(_new_fit(*fitted, items))
    phasers: dict[str, Phaser] = {}
    for group in sorted({tr.group for tr in items}):
        if ("phaser", group) in fits:
            phasers[group] = Phaser.from_dict(json.loads(fits[("phaser", group)]))
            continue
        members = [tr for tr in items if tr.group == group]
        try:
            phasers[group] = Phaser(params["phaser_order"], params["phaser_pad_cycles"]).fit(
                [_phaser_input(tr, pca, params) for tr in members]
            )
        except PreprocessError as exc:
            raise PreprocessError(f"phase of trial group {group}: {exc}") from None
        new.append(_new_fit("phaser", group, json.dumps(phasers[group].to_dict()), members))
    return Fitted(joints, pca, phasers, new, warnings)


def write_samples(
    store: Store,
    result: PrepResult,
    items: list[_Trial],
    fitted: Fitted,
    params: dict,
    progress: bool,
    model: BodyModel | None = None,
) -> None:
    """Phase, rates and samples of every trial, with its stats; each batch of about
    `WRITE_BATCH_FRAMES` frames in one transaction, recorded in ``result`` once written."""
    vid = result.version_id
    model = SwimmerModel() if model is None else model
    with progress_bar(
        "Preprocessing", total=len(items), enabled=progress, unit="trials"
    ) as advance:
        batch: list[_Trial] = []
        for i, tr in enumerate(items):
            batch.append(tr)
            if sum(len(b.t) for b in batch) >= WRITE_BATCH_FRAMES or i == len(items) - 1:
                frames = [
                    _samples_frame(b, vid, fitted.pca, fitted.phasers[b.group], params)
                    for b in batch
                ]
                stats = pd.DataFrame(
                    [_stats_row(b, vid, fitted.joints[b.id], model) for b in batch]
                )
                write_trials(store, result, pd.concat(frames, ignore_index=True), stats)
                result.interpolated_pose_frames += sum(
                    model.interpolated_frames(b.measured) for b in batch
                )
                advance(len(batch))
                batch = []


def _new_fit(kind: str, grp: str, state: str, items: list[_Trial]) -> NewFit:
    return NewFit(kind, grp, state, [tr.id for tr in items], int(sum(len(tr.t) for tr in items)))
