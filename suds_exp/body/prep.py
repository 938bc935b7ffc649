"""`preprocess_body`: preprocessing driven by a body description.

The swimmer's description runs the standard pipeline (`suds_exp.preprocess.preprocess`)
unchanged. Any other description of rigid segments runs the same pipeline with its own
geometry (`suds_exp.body.segments.SegmentModel`, the pipeline's body hook). A chain
description (snake, fish) gives a version whose samples hold:

- ``ra_1, ra_2``: the first two shape modes (rad; PCA of the chord angles, fitted on the
  version's trials), the driven travelling wave whose phase Phaser estimates;
- ``rp_1..rp_k``: the next k = modes - 2 shape modes (rad, not passive states: a chain
  body is actuated all along), and their rates ``drp_*`` (rad/s);
- ``vx, vy, wz``: velocity of the chain's frame (centroid, mean chord heading).

The version's parameters are the usual ones plus the description (``body``), so another
description is another version, and re-running skips the trials already done.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
import pandas as pd
import sqlalchemy as sa

from suds_exp.body.chain_shape import chain_geometry
from suds_exp.body.description import Body, BodyError, check_markers
from suds_exp.body.segments import SWIMMER_ONLY, SegmentModel
from suds_exp.errors import PreprocessError
from suds_exp.preprocess.clean import clean_tracks
from suds_exp.preprocess.params import DEFAULTS, params_hash, resolve_params
from suds_exp.preprocess.phaser import Phaser, cycles
from suds_exp.preprocess.pipeline import PLANAR_Z, new_result, preprocess, trial_meta
from suds_exp.preprocess.rates import body_velocity, derivative, differentiator_window
from suds_exp.preprocess.shape import PassivePCA
from suds_exp.preprocess.tables import (
    DRP_COLUMNS,
    RP_COLUMNS,
)
from suds_exp.preprocess.version import (
    NewFit,
    PrepResult,
    find_version,
    stored_progress,
    write_trials,
    write_version,
)
from suds_exp.progress import progress_bar
from suds_exp.store import Store


def preprocess_body(
    store: Store,
    body: Body,
    name: str | None = None,
    params: Mapping[str, Any] | None = None,
    trials: Iterable[int] | None = None,
    progress: bool = True,
    preset: str | None = None,
) -> PrepResult:
    """Preprocess trials of ``body``: the standard pipeline for the swimmer, the pipeline
    with the body's geometry for other segment bodies, else a chain.

    Parameters as `suds_exp.preprocess.preprocess` (a ``preset`` is the swimmer's only).
    For a segment body, the swimmer-only parameters default to their generic values
    (``body_fit=segments``, ``tail_fit=rigid``, ``ra_repr=angles``) and ``k`` to at
    most the size of its passive state; for a chain
    ``params["k"]`` is set from its ``modes`` (k = modes - 2). Raises `BodyError` for a
    description the trials do not fit (an unknown marker), a body the generic pipeline
    cannot preprocess (`SegmentModel`), or a ``reduction`` other than PCA;
    `PreprocessError` as the standard pipeline does.
    """
    if body.is_swimmer():
        return preprocess(
            store, name, _swimmer_params(body, params), trials, progress, preset=preset
        )
    if preset is not None:
        raise BodyError(
            f"{body.source}: preset {preset!r} describes the swimmer; this body takes params only"
        )
    if body.chain is None:
        model = SegmentModel(body)
        # k defaults to the swimmer's 4 unless the body's passive state has fewer numbers
        given = {"k": min(DEFAULTS["k"], model.n_passive), **SWIMMER_ONLY, **dict(params or {})}
        return preprocess(store, name, given, trials, progress, body=model)
    return _preprocess_chain(store, body, name, params, trials, progress)


def _swimmer_params(body: Body, params: Mapping[str, Any] | None) -> dict[str, Any]:
    """``params`` with the middle segment's ``length_mm`` as ``joint_distance_mm``: the
    standard pipeline reads the distance between the motor axes from its parameters."""
    given = dict(params or {})
    length = next(s.length_mm for s in body.segments if s.name == body.body_frame)
    if length is None:
        return given
    if float(given.get("joint_distance_mm") or length) != length:
        raise BodyError(
            f"{body.source}: segments.{body.body_frame}.length_mm = {length:g} but "
            f"joint_distance_mm = {given['joint_distance_mm']}; give one of them"
        )
    return {**given, "joint_distance_mm": length}


def _chain_tracks(conn: sa.Connection, body: Body, meta_row) -> tuple[np.ndarray, ...]:
    names = body.chain.markers
    df = Store.frame(
        conn,
        f"SELECT frame, t, list_position($names, marker) - 1 AS k, x, y, {PLANAR_Z} AS z "
        "FROM markers "
        "WHERE trial_id = $tid AND list_contains($names, marker) ORDER BY frame, k",
        {"names": list(names), "tid": int(meta_row.id)},
    )
    frames, inverse = np.unique(df.frame.to_numpy(), return_inverse=True)
    xyz = np.full((len(frames), len(names), 3), np.nan)
    xyz[inverse, df.k.to_numpy()] = df[["x", "y", "z"]].to_numpy(dtype=float)
    t = np.zeros(len(frames))
    t[inverse] = df.t.to_numpy()
    return frames, t, xyz


def _preprocess_chain(store, body, name, params, trials_, progress) -> PrepResult:
    with store.locked("preprocess", name):
        return _locked_chain(store, body, name, params, trials_, progress)


def _locked_chain(store, body, name, params, trials_, progress) -> PrepResult:
    started = time.perf_counter()
    given = dict(params or {})
    given["k"] = body.chain.modes - 2
    params = resolve_params(given)
    if params["reduction"] != "pca":
        # ra_1, ra_2 are the chain's first two PCA modes, the travelling wave Phaser reads
        raise BodyError(
            f"{body.source}: reduction {params['reduction']!r} is for the swimmer's passive "
            "shape; a chain's shape modes are PCA modes (reduction=pca)"
        )
    params["body"] = body.to_dict()
    digest = params_hash(params)
    with store.write() as conn:
        row = find_version(conn, name, digest)
        meta = _chain_meta(conn, trials_)
        done, fits = stored_progress(conn, None if row is None else row.id)
        todo = meta[~meta.id.isin(done)]
        for r in todo.itertuples(index=False):
            check_markers(body, list(r.marker_names), f"trial {r.id} ({r.source_file})")
        raw = {int(r.id): _chain_tracks(conn, body, r) for r in todo.itertuples(index=False)}
    result = new_result(row, name, params, digest, skipped=meta.id[meta.id.isin(done)])
    if todo.empty:
        result.seconds = time.perf_counter() - started
        return result
    items = _clean_chain(body, todo, raw, params)
    pca, phasers, new_fits = _fit_chain(body, items, params, fits)
    write_version(store, result, new_fits, pca, body.chain.modes)
    with progress_bar("Preprocessing", total=len(items), enabled=progress, unit="trials") as adv:
        for tid, rate, frames, t, clean, geom in items:
            vid = result.version_id
            samples = chain_samples(vid, tid, rate, frames, t, geom, pca, phasers[tid], params)
            stats = _chain_stats(body, vid, tid, t, clean, geom)
            write_trials(store, result, samples, pd.DataFrame([stats]))
            adv()
    result.explained_variance_ratio = pca.explained_variance_ratio_[: body.chain.modes].tolist()
    result.seconds = time.perf_counter() - started
    return result


def _chain_meta(conn: sa.Connection, trial_ids) -> pd.DataFrame:
    meta = trial_meta(conn, trial_ids, ("id", "source_file", "sample_rate_hz", "marker_names"))
    if meta.empty:
        raise PreprocessError("no trials to preprocess; ingest some first", step="ingest")
    return meta


def _clean_chain(body: Body, todo: pd.DataFrame, raw: dict, params: dict) -> list[tuple]:
    items = []
    for r in todo.itertuples(index=False):
        frames, t, xyz = raw[int(r.id)]
        rate = float(r.sample_rate_hz)
        label = f"trial {r.id} ({r.source_file})"
        if len(frames) < 8:
            raise PreprocessError(f"{label}: only {len(frames)} frames; need at least 8")
        max_gap = int(np.floor(params["max_gap_s"] * rate + 1e-9))
        try:
            clean = clean_tracks(xyz, params["jump_mm"], max_gap, body.chain.markers)
        except PreprocessError as exc:
            raise PreprocessError(f"{label}: {exc}", param=exc.param) from None
        items.append((int(r.id), rate, frames, t, clean, chain_geometry(clean.xyz, body.chain.up)))
    return items


def _fit_chain(body: Body, items: list[tuple], params: dict, fits: dict):
    """The shape PCA and one Phaser per trial (stored ones reused) and the new fits."""
    n_frames = {i[0]: len(i[2]) for i in items}

    def new_fit(kind, grp, state, ids):
        return NewFit(kind, grp, state, ids, int(sum(n_frames[i] for i in ids)))

    new_fits = []
    if ("pca", "") in fits:
        pca = PassivePCA.from_dict(json.loads(fits[("pca", "")]))
    else:
        pca = PassivePCA(body.chain.modes).fit(np.concatenate([g.angles for *_, g in items]))
        new_fits.append(new_fit("pca", "", json.dumps(pca.to_dict()), [i[0] for i in items]))
    phasers = {}
    for tid, *_, geom in items:
        group = f"trial:{tid}"
        if ("phaser", group) in fits:
            phasers[tid] = Phaser.from_dict(json.loads(fits[("phaser", group)]))
            continue
        try:
            phasers[tid] = Phaser(params["phaser_order"], params["phaser_pad_cycles"]).fit(
                [pca.transform(geom.angles)[:, :2]]
            )
        except PreprocessError as exc:
            raise PreprocessError(f"phase of trial {tid}: {exc}") from None
        new_fits.append(new_fit("phaser", group, json.dumps(phasers[tid].to_dict()), [tid]))
    return pca, phasers, new_fits


def _chain_stats(body: Body, vid: int, tid: int, t, clean, geom) -> dict:
    return {
        "version_id": vid,
        "trial_id": tid,
        "n_frames": len(t),
        "n_jumps": clean.n_jumps,
        "removed_fraction": clean.removed_fraction,
        "filled_fraction": clean.filled_fraction,
        "longest_gap_frames": clean.longest_gap,
        "plane_normal": [float(a == body.chain.up) for a in "xyz"],
        "middle_length_mm": float(geom.length.mean()),
        "joint_rms_mm": float(geom.length.std()),
        "phaser_group": f"trial:{tid}",
        "done_at": pd.Timestamp.now(tz="UTC").tz_localize(None),
    }


def chain_samples(vid, tid, rate, frames, t, geom, pca, phaser, params) -> pd.DataFrame:
    """The samples rows of one chain trial (columns of the ``samples`` table)."""
    dt = 1.0 / rate
    w = differentiator_window(params, rate, None, len(t))
    po, kernel = params["sg_polyorder"], params["sg_kernel"]
    modes = pca.transform(geom.angles)
    rates = pca.transform_rate(derivative(geom.angles, dt, w, po, kernel))
    vb = body_velocity(geom.origin, geom.heading, dt, w, po, kernel)
    phase = phaser.transform(modes[:, :2])
    n, k = len(t), params["k"]
    cols: dict[str, Any] = {
        "version_id": np.full(n, vid, dtype=np.int32),
        "trial_id": np.full(n, tid, dtype=np.int32),
        "frame": np.asarray(frames, dtype=np.int32),
        "t": t,
        "phase": phase,
        "cycle": cycles(phase).astype(np.int32),
        "ra_1": modes[:, 0],
        "ra_2": modes[:, 1],
        "dra_1": rates[:, 0],
        "dra_2": rates[:, 1],
    }
    for i in range(len(RP_COLUMNS)):
        cols[RP_COLUMNS[i]] = modes[:, 2 + i] if i < k else np.full(n, np.nan)
        cols[DRP_COLUMNS[i]] = rates[:, 2 + i] if i < k else np.full(n, np.nan)
    cols.update(vx=vb[:, 0], vy=vb[:, 1], wz=vb[:, 2])
    return pd.DataFrame(cols)
