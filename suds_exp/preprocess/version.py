"""A stored preprocessing version as one object: `get_version(store, ref) -> Version`.

The one way into the ``prep_*`` tables for code outside preprocessing: campaign,
discrepancy and the truth comparison find a version, its fitted state and its samples
here, by the same rules (id, name, or a unique prefix of its parameter hash; no ref =
the only version).
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
import sqlalchemy as sa

from suds_exp.display import Summary
from suds_exp.errors import PreprocessError
from suds_exp.preprocess.params import actuated_dimension
from suds_exp.preprocess.phaser import Phaser
from suds_exp.preprocess.rates import Differentiator
from suds_exp.preprocess.reduction import reducer_from_state
from suds_exp.preprocess.shape import PassivePCA
from suds_exp.preprocess.tables import prep_fits, prep_versions
from suds_exp.robot import sample_columns
from suds_exp.store import Store


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
