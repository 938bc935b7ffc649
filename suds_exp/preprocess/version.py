"""A stored preprocessing version as one object: `get_version(store, ref) -> Version`;
and the writers that create a version and store its fits and samples, recording what
they did in the run's `PrepResult`.

The one way into the ``prep_*`` tables for code outside preprocessing: campaign,
discrepancy and the truth comparison find a version, its fitted state and its samples
here, by the same rules (id, name, or a unique prefix of its parameter hash; no ref =
the only version).
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import pandas as pd
import sqlalchemy as sa

from suds_exp.display import Summary
from suds_exp.errors import PreprocessError
from suds_exp.preprocess.params import actuated_dimension, params_json
from suds_exp.preprocess.phaser import Phaser
from suds_exp.preprocess.rates import Differentiator
from suds_exp.preprocess.reduction import reducer_from_state
from suds_exp.preprocess.shape import PassivePCA
from suds_exp.preprocess.tables import prep_fits, prep_pca, prep_trials, prep_versions
from suds_exp.robot import sample_columns
from suds_exp.store import Store


@dataclass
class PrepResult:
    """What a `preprocess` run did.

    ``processed``/``skipped``: trial ids written now / already done before;
    ``explained_variance_ratio``: of the k kept passive components (fraction each);
    ``interpolated_pose_frames``: frames of a segment, summed over segments and the
    trials processed now, whose pose came from interpolated tracks because too few of
    its markers were seen (a segment body's; the swimmer's pipeline reports none);
    ``warnings``: one line per fit of this run the trials did not pin down (e.g. the
    segment origins), for the command layer to show.
    """

    version_id: int
    name: str
    params_hash: str
    params: dict
    created: bool
    processed: list[int] = field(default_factory=list)
    skipped: list[int] = field(default_factory=list)
    explained_variance_ratio: list[float] = field(default_factory=list)
    n_samples: int = 0
    interpolated_pose_frames: int = 0
    seconds: float = 0.0
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(repr=False)
class Version(Summary):
    """A preprocessing version: its identity, parameters and fitted state.

    Attributes
    ----------
    id, name, params_hash : int, str, str
    params : dict
        The full parameter set (`suds_exp.preprocess.DEFAULTS` keys) as stored.
    k : int
        Passive principal components kept (r_p has k columns).
    pca : PassivePCA or None
        The fitted passive-shape PCA (None until a trial has been preprocessed); for a
        version with ``reduction`` kernel-pca or autoencoder, that reducer
        (`suds_exp.preprocess.reduction`, same transform / transform_rate face).
    phasers : dict of str -> Phaser
        The fitted Phaser of each trial group (``prep_trials.phaser_group``).
    """

    store: Store = field(repr=False)
    id: int
    name: str
    params_hash: str
    params: dict
    k: int
    pca: PassivePCA | None = None
    phasers: dict[str, Phaser] = field(default_factory=dict, repr=False)

    def _summary(self):
        from suds_exp.preprocess.params import DEFAULTS

        changed = {k: v for k, v in self.params.items() if k not in DEFAULTS or DEFAULTS[k] != v}
        return f"Version {self.id} {self.name!r}", [
            ("parameters", f"{self.params_hash[:12]}; changed from the defaults: "
             + (", ".join(f"{k}={v}" for k, v in changed.items()) or "none")),
            ("passive components", self.k),
            ("fitted", "yes" if self.pca is not None else "not yet"),
            ("trial groups", len(self.phasers)),
        ]  # fmt: skip

    def differentiator(self) -> Differentiator:
        """The version's differentiator: what made its rates (dr_a/dt, dr_p/dt, v_b)."""
        return Differentiator.from_params(self.params)

    def samples(self, trials: Iterable[int] | None = None) -> pd.DataFrame:
        """The version's samples (`suds_exp.preprocess.load_samples`), optionally of
        ``trials`` (ids) only; read by the version's id, not looked up again."""
        with self.store.read() as conn:
            return _read_samples(conn, self.id, self.k, self.params, trials)


def find_version_row(conn: sa.Connection, version: int | str) -> sa.Row:
    """The ``prep_versions`` row of ``version`` (id, name or unique hash prefix >= 6)."""
    v = prep_versions.c
    if isinstance(version, int | np.integer) or (isinstance(version, str) and version.isdigit()):
        row = conn.execute(sa.select(prep_versions).where(v.id == int(version))).first()
    else:
        row = conn.execute(sa.select(prep_versions).where(v.name == version)).first()
        if row is None and len(version) >= 6:
            found = conn.execute(
                sa.select(prep_versions).where(v.params_hash.startswith(version))
            ).fetchall()
            row = found[0] if len(found) == 1 else None
    if row is None:
        known = conn.execute(sa.select(v.id, v.name).order_by(v.id)).fetchall()
        listing = ", ".join(f"{r.id} ({r.name})" for r in known) or "none yet"
        raise PreprocessError(
            f"preprocessing version {version!r} not found; known versions: {listing}"
        )
    return row


def require_tables(conn: sa.Connection) -> None:
    """Refuse a database made before preprocessing existed (its migration not applied)."""
    found = conn.exec_driver_sql(
        "SELECT count(*) FROM information_schema.tables WHERE table_name = 'prep_versions'"
    ).scalar_one()
    if not found:
        raise PreprocessError(
            "this database has no preprocessing tables yet; preprocess trials (or upgrade "
            "the database) first",
            step=("preprocess", "init"),
        )


def load_samples(
    store: Store, version: int | str, trials: Iterable[int] | None = None
) -> pd.DataFrame:
    """The samples of a preprocessing version, ordered by trial and frame.

    Parameters
    ----------
    store : Store
    version : int or str
        Version id, name, or a unique prefix (>= 6 characters) of its parameter hash.
    trials : iterable of int, optional
        Only these trial ids.

    Returns
    -------
    DataFrame with columns ``trial_id, frame, t (s), phase (rad, unwrapped), cycle,
    ra_1, ra_2 (rad), dra_1, dra_2 (rad/s), rp_1..rp_k (mm), drp_1..drp_k (mm/s),
    vx, vy (mm/s), wz (rad/s)`` (body frame) and the trial's ``gait``, ``frequency_hz``.
    """
    with store.read() as conn:
        require_tables(conn)
        row = find_version_row(conn, version)
        return _read_samples(conn, row.id, row.k, json.loads(row.params), trials)


def _read_samples(
    conn: sa.Connection, version_id: int, k: int, params: dict, trials: Iterable[int] | None
) -> pd.DataFrame:
    """The samples of version ``version_id`` (``k`` passive PCs, parameters ``params``);
    see `load_samples`."""
    cols = sample_columns(k, actuated_dimension(params))
    select = ", ".join(f's."{c}"' for c in cols)
    where = "s.version_id = ?"
    args: list[Any] = [int(version_id)]
    if trials is not None:
        ids = sorted({int(i) for i in trials})
        where += f" AND s.trial_id IN ({', '.join('?' * len(ids))})" if ids else " AND false"
        args += ids
    return Store.frame(
        conn,
        f"SELECT {select}, t.gait, t.frequency_hz FROM samples s "
        f"JOIN trials t ON t.id = s.trial_id WHERE {where} ORDER BY s.trial_id, s.frame",
        args,
    )


def get_version(store: Store, ref: int | str | None = None) -> Version:
    """The preprocessing version ``ref`` of ``store``.

    Parameters
    ----------
    store : Store
    ref : int or str, optional
        Version id, name, or a unique prefix (>= 6 characters) of its parameter hash;
        None: the only version (an error naming them when there are several).

    Raises
    ------
    PreprocessError
        No preprocessing tables, no such version, or ``ref`` None with 0 or 2+ versions.
    """
    with store.read() as conn:
        require_tables(conn)
        if ref is None:
            v = prep_versions.c
            rows = conn.execute(sa.select(v.id, v.name).order_by(v.id)).all()
            if len(rows) != 1:
                have = ", ".join(f"{r.id} ({r.name})" for r in rows)
                raise PreprocessError(
                    "no preprocessing version; preprocess trials first"
                    if not rows
                    else f"name the preprocessing version to use (have: {have})",
                    step="preprocess" if not rows else None,
                )
            ref = int(rows[0].id)
        row = find_version_row(conn, ref)
        f = prep_fits.c
        fits = conn.execute(
            sa.select(f.kind, f.grp, f.state)
            .where(f.version_id == row.id, f.kind.in_(("pca", "reducer", "phaser")))
            .order_by(f.kind, f.grp)
        ).all()
    pca, phasers = None, {}
    for kind, grp, state in fits:
        if kind in ("pca", "reducer"):
            pca = reducer_from_state(kind, grp, state)
        else:
            phasers[grp] = Phaser.from_dict(json.loads(state))
    return Version(
        store=store,
        id=int(row.id),
        name=str(row.name),
        params_hash=str(row.params_hash),
        params=json.loads(row.params),
        k=int(row.k),
        pca=pca,
        phasers=phasers,
    )


# -- writing versions ------------------------------------------------------------------
@dataclass
class NewFit:
    """A fitted state to store in `prep_fits`: kind, group, JSON state, the trial ids it
    was fitted on and their number of frames."""

    kind: str
    grp: str
    state: str
    trial_ids: list[int]
    n_frames: int


def find_version(conn: sa.Connection, name: str | None, digest: str):
    """The `prep_versions` row with parameters hash ``digest`` (None if there is none yet);
    raises `PreprocessError` if ``name`` is already another parameter set's name."""
    v = prep_versions.c
    row = conn.execute(sa.select(prep_versions).where(v.params_hash == digest)).first()
    if name is not None:
        clash = conn.execute(sa.select(v.id, v.params_hash).where(v.name == name)).first()
        if clash is not None and clash.params_hash != digest:
            raise PreprocessError(
                f"name {name}: version {clash.id} already has that name with other "
                "parameters; choose another name",
                param="name",
            )
    return row


def stored_progress(
    conn: sa.Connection, version_id: int | None
) -> tuple[set[int], dict[tuple[str, str], str]]:
    """What version ``version_id`` already holds: the ids of its preprocessed trials and
    its fitted states by (kind, group); both empty for a version not yet created (None)."""
    if version_id is None:
        return set(), {}
    done = {
        int(r[0])
        for r in conn.execute(
            sa.select(prep_trials.c.trial_id).where(prep_trials.c.version_id == version_id)
        )
    }
    fits = {
        (r.kind, r.grp): r.state
        for r in conn.execute(sa.select(prep_fits).where(prep_fits.c.version_id == version_id))
    }
    return done, fits


def write_version(
    store: Store, result: PrepResult, new_fits: list[NewFit], pca, n_kept: int
) -> None:
    """Create the version of ``result`` if it is new (setting its id and name) and store
    its new fits, in one transaction; a new PCA's components go to `prep_pca`, the first
    ``n_kept`` kept."""
    with store.write() as conn:
        if result.version_id < 0:
            vid = int(conn.exec_driver_sql("SELECT nextval('prep_versions_id_seq')").scalar_one())
            result.name = result.name or f"v{vid}"
            conn.execute(
                sa.insert(prep_versions).values(
                    id=vid,
                    name=result.name,
                    params_hash=result.params_hash,
                    params=params_json(result.params),
                    k=result.params["k"],
                    created_at=sa.func.current_timestamp(),
                )
            )
            result.version_id = vid
        if new_fits:
            now = pd.Timestamp.now(tz="UTC").tz_localize(None)
            rows = [
                {"version_id": result.version_id, **asdict(f), "fitted_at": now} for f in new_fits
            ]
            store.insert_df(conn, prep_fits.name, pd.DataFrame(rows))
        if any(f.kind == "pca" for f in new_fits):
            write_pca(store, conn, result.version_id, pca, n_kept)


def write_pca(store: Store, conn: sa.Connection, version_id: int, pca, n_kept: int) -> None:
    """Store a fitted PCA's components (``pca``: a fitted scikit-learn PCA) in
    `prep_pca` for ``version_id``, the first ``n_kept`` marked as kept."""
    cum = np.cumsum(pca.explained_variance_ratio_)
    store.insert_df(
        conn,
        prep_pca.name,
        pd.DataFrame(
            {
                "version_id": version_id,
                "component": np.arange(1, len(cum) + 1),
                "explained_variance": pca.explained_variance_,
                "explained_variance_ratio": pca.explained_variance_ratio_,
                "cumulative_ratio": cum,
                "kept": np.arange(len(cum)) < n_kept,
                "loadings": [list(r) for r in pca.components_],
            }
        ),
    )


def write_trials(store: Store, result: PrepResult, samples: pd.DataFrame, stats: pd.DataFrame):
    """Store trials' samples and their `prep_trials` stats in one transaction, then
    record them in ``result``."""
    with store.write() as conn:
        store.insert_df(conn, "samples", samples)
        store.insert_df(conn, prep_trials.name, stats)
    result.processed.extend(int(i) for i in stats.trial_id)
    result.n_samples += len(samples)


def kept_ratio(store: Store, version_id: int, k: int) -> list[float]:
    frame = store.query_df(
        "SELECT explained_variance_ratio FROM prep_pca WHERE version_id = ? AND kept "
        "ORDER BY component",
        [version_id],
    )
    if frame.empty:  # a kernel-PCA or autoencoder version: its ratio is in its stored state
        state = store.query_df(
            "SELECT state FROM prep_fits WHERE version_id = ? AND kind = 'reducer'", [version_id]
        )
        if len(state):
            return json.loads(state.state.iloc[0])["explained_variance_ratio"][:k]
    return frame.explained_variance_ratio.tolist()[:k]


def list_versions(store: Store) -> pd.DataFrame:
    """One row per version: id, name, params_hash, k, trials done, samples, created_at,
    kept explained variance (fraction)."""
    with store.read() as conn:
        require_tables(conn)
    return store.query_df(
        """
        SELECT v.id, v.name, v.params_hash, v.k,
               (SELECT count(*) FROM prep_trials p WHERE p.version_id = v.id) AS n_trials,
               (SELECT count(*) FROM samples s WHERE s.version_id = v.id) AS n_samples,
               (SELECT sum(explained_variance_ratio) FROM prep_pca c
                 WHERE c.version_id = v.id AND c.kept) AS explained_variance_kept,
               v.created_at, v.params
        FROM prep_versions v ORDER BY v.id
        """
    )
