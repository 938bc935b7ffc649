"""Versions through the CLI and the library: same parameters = one version, a changed
parameter = a new one beside it, resumable runs, refused trials leave the DB unchanged."""

from __future__ import annotations

import csv
import io
import json

import duckdb
import numpy as np
import pandas as pd
import pytest

from suds_exp.ingest import ingest_paths
from suds_exp.preprocess import PreprocessError, load_samples, pipeline, preprocess, sample_columns
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db
from suds_exp.testing.synthetic_captures import synthetic_trial, write_marker_csv


def test_same_parameters_make_one_version_and_rerun_skips(dataset, cli, sql):
    first = cli("preprocess", "--db", dataset, "--json")
    assert first.exit_code == 0, first.output
    doc = json.loads(first.stdout)
    assert doc["created"] and doc["processed"] == [1, 2, 3, 4, 5] and doc["name"] == "v1"
    assert len(doc["explained_variance_ratio"]) == 4
    again = json.loads(cli("preprocess", "--db", dataset, "--json").stdout)
    assert not again["created"] and again["processed"] == [] and again["skipped"] == [1, 2, 3, 4, 5]
    assert again["version_id"] == doc["version_id"]
    assert sql(dataset, "SELECT count(*) AS n FROM prep_versions") == [{"n": 1}]
    assert sql(dataset, "SELECT count(*) AS n FROM samples") == [{"n": 5 * 800}]
    text = cli("preprocess", "--db", dataset)
    assert "reused" in text.stdout and "skipped 5 already done" in text.stdout


def test_changed_parameter_makes_a_new_version_beside_the_first(dataset, cli, sql):
    assert cli("preprocess", "--db", dataset, "-q").exit_code == 0
    assert (
        cli("preprocess", "--db", dataset, "--name", "three", "--param", "k=3", "-q").exit_code == 0
    )
    versions = sql(dataset, "SELECT id, name, k FROM prep_versions ORDER BY id")
    assert versions == [{"id": 1, "name": "v1", "k": 4}, {"id": 2, "name": "three", "k": 3}]
    # compare the two versions frame by frame in SQL
    rows = sql(
        dataset,
        "SELECT count(*) AS n, max(abs(a.ra_1 - b.ra_1)) AS d_ra, "
        "count(b.rp_4) AS rp4_in_k3, count(a.rp_4) AS rp4_in_k4 "
        "FROM samples a JOIN samples b USING (trial_id, frame) "
        "WHERE a.version_id = 1 AND b.version_id = 2",
    )
    assert rows == [{"n": 4000, "d_ra": 0.0, "rp4_in_k3": 0, "rp4_in_k4": 4000}]
    pca = sql(
        dataset,
        "SELECT version_id, sum(explained_variance_ratio) AS s FROM prep_pca GROUP BY 1 ORDER BY 1",
    )
    assert [round(r["s"], 9) for r in pca] == [1.0, 1.0]
    listed = json.loads(cli("preprocess", "--list", "--db", dataset, "--json").stdout)
    assert [(v["name"], v["n_trials"], v["n_samples"]) for v in listed] == [
        ("v1", 5, 4000),
        ("three", 5, 4000),
    ]
    table = cli("preprocess", "--list", "--db", dataset, "--csv").stdout
    rows = list(csv.DictReader(io.StringIO(table)))
    assert [(r["name"], r["params_hash"]) for r in rows] == [
        (v["name"], v["params_hash"]) for v in listed
    ]
    assert json.loads(rows[1]["params"])["k"] == 3


def test_load_samples_gives_exactly_the_standard_columns(dataset):
    store = Store(dataset)
    preprocess(store, params={"k": 3}, progress=False)
    samples = load_samples(store, "v1")
    assert list(samples.columns) == [
        "trial_id",
        "frame",
        "t",
        "phase",
        "cycle",
        "ra_1",
        "ra_2",
        "dra_1",
        "dra_2",
        "rp_1",
        "rp_2",
        "rp_3",
        "drp_1",
        "drp_2",
        "drp_3",
        "vx",
        "vy",
        "wz",
        "gait",
        "frequency_hz",
    ]
    assert sample_columns(3) == list(samples.columns[:-2])
    assert len(samples) == 4000 and not samples.drop(columns=["gait"]).isna().any().any()
    assert samples.groupby("trial_id").frame.apply(lambda f: f.is_monotonic_increasing).all()
    assert set(samples.gait) == {"S+", "S-", "O", "D-", "D+"}
    assert samples.frequency_hz.eq(0.5).all()
    one = load_samples(store, 1, trials=[2])
    assert one.trial_id.unique().tolist() == [2]
    with pytest.raises(
        PreprocessError, match=r"version 'nope' not found; known versions: 1 \(v1\)"
    ):
        load_samples(store, "nope")


def test_samples_follow_the_truth_of_the_synthetic_robot(dataset, tmp_path):
    from suds_exp.preprocess.truth import truth_errors

    store = Store(dataset)
    preprocess(store, progress=False)
    errors = truth_errors(store, 1).set_index("trial_id")
    pooled = errors.loc[-1]
    assert pooled.err_ra < 0.01
    assert pooled.err_phase < 0.05
    # 0.2 mm marker noise through a 0.1-cycle differentiator: about 5 % of RMS vx here
    assert max(pooled.err_vx, pooled.err_vy) < 0.08 * pooled.rms_vx_true


def test_a_subset_first_then_the_rest_reuses_the_fit(dataset):
    store = Store(dataset)
    part = preprocess(store, trials=[1, 2], progress=False)
    assert part.processed == [1, 2]
    rest = preprocess(store, progress=False)
    assert (
        rest.version_id == part.version_id
        and rest.processed == [3, 4, 5]
        and rest.skipped == [1, 2]
    )
    fits = store.query_df("SELECT kind, grp, trial_ids FROM prep_fits ORDER BY kind, grp")
    pca = fits[fits.kind == "pca"].iloc[0]
    assert list(pca.trial_ids) == [1, 2]  # fitted once, on the first run's trials
    assert set(fits[fits.kind == "phaser"].grp) == {"S+@0.5", "S-@0.5", "O@0.5", "D-@0.5", "D+@0.5"}


def test_an_interrupted_run_resumes_with_the_trials_not_done(dataset, monkeypatch):
    store = Store(dataset)
    monkeypatch.setattr(pipeline, "WRITE_BATCH_FRAMES", 1)  # one transaction per trial
    real = Store.insert_df
    calls = {"samples": 0}

    def failing(conn, table, df):
        if table == "samples":
            calls["samples"] += 1
            if calls["samples"] == 3:
                raise KeyboardInterrupt
        return real(conn, table, df)

    monkeypatch.setattr(Store, "insert_df", staticmethod(failing))
    with pytest.raises(KeyboardInterrupt):
        preprocess(store, progress=False)
    monkeypatch.setattr(Store, "insert_df", staticmethod(real))
    done = store.query_df("SELECT trial_id FROM prep_trials ORDER BY 1").trial_id.tolist()
    assert done == [1, 2]
    resumed = preprocess(store, progress=False)
    assert resumed.processed == [3, 4, 5] and resumed.skipped == [1, 2]
    counts = store.query_df("SELECT trial_id, count(*) AS n FROM samples GROUP BY 1 ORDER BY 1")
    assert counts.n.tolist() == [800] * 5


def test_trial_with_too_long_a_gap_is_refused_and_nothing_written(tmp_path, cli):
    trial = synthetic_trial("O", 0.5, n_cycles=4, seed=1)
    trial.xyz[100:160, 4] = np.nan  # tail_top_2 unseen for 0.6 s
    write_marker_csv(trial, tmp_path / "gap.csv")
    db = tmp_path / "db.duckdb"
    ingest_paths(Store(db), [tmp_path / "gap.csv"], progress=False)
    before = dump_db(db)
    out = cli("preprocess", "--db", db)
    assert out.exit_code == 2
    assert "trial 1 (" in out.output and "marker tail_top_2 has a gap of 60 frames" in out.output
    assert "max_gap_s" in out.output
    assert_same_db(before, dump_db(db))
    ok = cli("preprocess", "--db", db, "--param", "max_gap_s=1", "--json")
    assert ok.exit_code == 0 and json.loads(ok.stdout)["processed"] == [1]


@pytest.mark.parametrize(
    "args,message",
    [
        (["--param", "kk=3"], "--param kk: unknown parameter"),
        (["--param", "k=13"], "--param k=13: must be between 1 and 12"),
        (["--param", "k=2.5"], "expected a whole number"),
        (["--param", "phaser_group=cycle"], "phaser_group=cycle: expected one of condition"),
        (["--param", "k"], "expected KEY=VALUE"),
        (["--trials", "1,x"], "--trials '1,x': expected ids"),
        (["--trials", "9"], "--trials: no trial with id 9"),
    ],
)
def test_bad_options_exit_2_and_change_nothing(dataset, args, message, cli):
    before = dump_db(dataset)
    out = cli("preprocess", "--db", dataset, *args)
    assert out.exit_code == 2, out.output
    assert message in out.output
    assert_same_db(before, dump_db(dataset))


def test_a_name_used_by_other_parameters_is_refused(dataset, cli, sql):
    assert cli("preprocess", "--db", dataset, "--name", "base", "-q").exit_code == 0
    out = cli("preprocess", "--db", dataset, "--name", "base", "--param", "k=2")
    assert out.exit_code == 2 and "--name base: version 1 already has that name" in out.output
    same = cli("preprocess", "--db", dataset, "--name", "base", "--json")
    assert json.loads(same.stdout)["skipped"] == [1, 2, 3, 4, 5]
    frame = pd.DataFrame(sql(dataset, "SELECT name FROM prep_versions"))
    assert frame.name.tolist() == ["base"]


def test_trials_with_their_own_marker_names_are_read_through_their_layout(tmp_path):
    trial = synthetic_trial("D+", 0.5, n_cycles=4, seed=5)
    path = write_marker_csv(trial, tmp_path / "named.csv")
    text = path.read_text()
    for i in range(1, 5):
        text = text.replace(f"flipper_{i}_", f"fl{i}_")
    path.write_text(text.replace("head_spoke_", "HS_"))
    layout = tmp_path / "layout.csv"
    names = {f"flipper_{i}": f"fl{i}" for i in range(1, 5)} | {"head_spoke": "HS"}
    roles = [
        "head_top_1",
        "head_top_2",
        "head_spoke",
        "tail_top_1",
        "tail_top_2",
        "tail_spoke",
        "tail_back",
        "flipper_1",
        "flipper_2",
        "flipper_3",
        "flipper_4",
    ]
    layout.write_text("role,marker\n" + "".join(f"{r},{names.get(r, r)}\n" for r in roles))
    db = tmp_path / "db.duckdb"
    ingest_paths(Store(db), [path], layout=layout, progress=False)
    # the same capture under the default names gives the same samples
    (tmp_path / "plain").mkdir()
    plain = write_marker_csv(trial, tmp_path / "plain" / "named.csv")
    db2 = tmp_path / "db2.duckdb"
    ingest_paths(Store(db2), [plain], progress=False)
    a = load_samples(Store(db), preprocess(Store(db), progress=False).version_id)
    b = load_samples(Store(db2), preprocess(Store(db2), progress=False).version_id)
    pd.testing.assert_frame_equal(
        a.drop(columns=["gait", "frequency_hz"]), b.drop(columns=["gait", "frequency_hz"])
    )


def test_a_database_without_preprocessing_is_told_what_to_do(tmp_path):
    db = tmp_path / "old.duckdb"
    duckdb.connect(str(db)).close()
    with pytest.raises(PreprocessError, match="no preprocessing tables yet"):
        load_samples(Store(db), 1)


def test_other_variants_run_and_keep_the_phase(dataset):
    from suds_exp.preprocess.truth import truth_errors

    store = Store(dataset)
    params = {
        "phaser_channels": "ra+rp",
        "phaser_group": "all",
        "joint_fit": "trial",
        "sg_window_cycles": 0,
        "k": 2,
    }
    result = preprocess(store, params=params, progress=False)
    fits = store.query_df("SELECT kind, grp FROM prep_fits ORDER BY kind, grp")
    assert fits.values.tolist() == [["pca", ""], ["phaser", "all"]]  # no shared joints
    errors = truth_errors(store, result.version_id).set_index("trial_id")
    # one Phaser for all five gaits still tracks each trial's phase
    assert errors.loc[-1].err_phase < 0.1
    assert errors.loc[-1].err_ra < 0.02
