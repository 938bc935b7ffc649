"""Passive coordinates beyond PCA: kernel-PCA and autoencoder versions beside the PCA one,
their stored reducers, their rates, and a refused reduction leaving the database alone."""

from __future__ import annotations

import json

import numpy as np
import pytest
from sklearn.decomposition import KernelPCA

from suds_exp.preprocess import get_version
from suds_exp.preprocess.reduction import AutoencoderReducer, KernelPCAReducer
from suds_exp.preprocess.shape import PassivePCA
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db


def passive_loop(n=600, seed=0):
    """A noisy closed curve in 12 dimensions (mm): a passive state with 2 degrees of freedom."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 4 * np.pi, n)
    basis = rng.standard_normal((4, 12))
    feats = np.column_stack([np.cos(t), np.sin(t), np.cos(2 * t) ** 2, np.sin(t) ** 3])
    return 5.0 * feats @ basis + 0.01 * rng.standard_normal((n, 12)), t


@pytest.mark.parametrize(
    "reducer", [KernelPCAReducer(3, landmarks=300), AutoencoderReducer(3)], ids=lambda r: r.method
)
def test_reducer_rates_are_the_derivative_of_its_coordinates_and_state_round_trips(reducer):
    x, t = passive_loop()
    reducer.fit(x)
    # along a smooth path, dz/dt = J(x) dx/dt: compare with a finite difference of z
    path = lambda s: x[100] + s * (x[101] - x[100])  # noqa: E731
    h = 1e-4
    rate = (path(h) - path(-h)) / (2 * h)
    z = reducer.transform(np.stack([path(-h), path(h)]))
    numeric = (z[1] - z[0]) / (2 * h)
    exact = reducer.transform_rate(rate[None, :], path(0.0)[None, :])[0]
    np.testing.assert_allclose(exact, numeric, rtol=1e-4, atol=1e-6)
    again = type(reducer).from_dict(json.loads(json.dumps(reducer.to_dict())))
    np.testing.assert_allclose(again.transform(x[:50]), reducer.transform(x[:50]))
    assert reducer.transform(x).shape == (len(x), 3)


def test_kernel_pca_coordinates_are_scikit_learns():
    x, _ = passive_loop(300)
    ours = KernelPCAReducer(3, landmarks=300).fit(x)
    theirs = KernelPCA(3, kernel="rbf", gamma=ours.gamma_, eigen_solver="dense").fit(x)
    np.testing.assert_allclose(ours.transform(x[::7]), theirs.transform(x[::7]), atol=1e-8)
    assert 0 < ours.explained_variance_ratio_.sum() < 1


def test_pca_ignores_the_state_its_rate_is_linear():
    x, _ = passive_loop(200)
    pca = PassivePCA(3).fit(x)
    rate = np.ones((5, 12))
    np.testing.assert_allclose(pca.transform_rate(rate, x[:5]), pca.transform_rate(rate))


def test_reducer_versions_coexist_with_the_pca_version(dataset, cli, sql):  # noqa: F811
    for args in ([], ["--param", "reduction=kernel-pca"], ["--param", "reduction=autoencoder"]):
        out = cli("preprocess", "--db", dataset, "--json", *args)
        assert out.exit_code == 0, out.output
    versions = sql(
        dataset,
        "SELECT id, json_extract_string(params, '$.reduction') AS r FROM prep_versions ORDER BY id",
    )
    assert versions == [
        {"id": 1, "r": "pca"},
        {"id": 2, "r": "kernel-pca"},
        {"id": 3, "r": "autoencoder"},
    ]
    fits = sql(
        dataset,
        "SELECT version_id AS v, kind, grp FROM prep_fits WHERE kind IN ('pca', 'reducer') "
        "ORDER BY 1",
    )
    assert fits == [
        {"v": 1, "kind": "pca", "grp": ""},
        {"v": 2, "kind": "reducer", "grp": "kernel-pca"},
        {"v": 3, "kind": "reducer", "grp": "autoencoder"},
    ]
    # the PCA components table describes the PCA version only
    assert sql(dataset, "SELECT DISTINCT version_id AS v FROM prep_pca") == [{"v": 1}]
    # same frames in every version, same r_a, different r_p
    rows = sql(
        dataset,
        "SELECT version_id AS v, count(*) AS n, sum(ra_1) AS ra, count(rp_4) AS rp, "
        "sum(abs(rp_1)) AS a FROM samples GROUP BY 1 ORDER BY 1",
    )
    assert len({r["n"] for r in rows}) == 1 and all(r["rp"] == r["n"] for r in rows)
    assert max(r["ra"] for r in rows) - min(r["ra"] for r in rows) < 1e-6
    assert len({round(r["a"], 3) for r in rows}) == 3
    # a rerun reuses the stored reducer and writes nothing new
    again = json.loads(
        cli("preprocess", "--db", dataset, "--json", "--param", "reduction=autoencoder").stdout
    )
    assert not again["created"] and again["processed"] == []
    assert len(again["explained_variance_ratio"]) == 1  # the decoder's share, stored
    # the version's reducer is what library users (e.g. the discrepancy replay) get
    store = Store(dataset)
    assert get_version(store, 2).pca.method == "kernel-pca"
    assert isinstance(get_version(store, 1).pca, PassivePCA)


def test_bad_reduction_is_one_line_naming_the_parameter_and_changes_nothing(dataset, cli):  # noqa: F811
    assert cli("preprocess", "--db", dataset, "-q").exit_code == 0
    before = dump_db(dataset)
    out = cli("preprocess", "--db", dataset, "--param", "reduction=umap")
    assert out.exit_code == 2
    line = out.output.strip()
    assert "\n" not in line and "reduction=umap" in line and "kernel-pca" in line
    assert_same_db(before, dump_db(dataset))
