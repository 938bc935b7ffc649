"""The paper's own processing as a preset (`preprocess --preset paper`): r_a as Cartesian
values, segment frames from the two top markers, no shape smoothing; the learners take the
r_a dimension from the columns present."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.ingest import ingest_paths
from suds_exp.models import make_model
from suds_exp.preprocess import PRESETS, load_samples, preprocess
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db
from suds_exp.testing.synthetic_captures import MIDDLE_MM, RIGID, synthetic_trial, write_dataset

runner = CliRunner()
GAITS = ("S+", "S-", "O", "D-", "D+")


@pytest.fixture(scope="module")
def ingested(tmp_path_factory) -> Path:
    """Five synthetic trials (one per gait, 0.5 Hz, 6 cycles) ingested into a database."""
    folder = tmp_path_factory.mktemp("preset")
    manifest = write_dataset(folder / "data", frequencies=(0.5,), n_cycles=6, n_jumps=2)
    db = folder / "template.duckdb"
    ingest_paths(Store(db), [], manifest, progress=False)
    return db


@pytest.fixture(scope="module")
def paper(ingested: Path, tmp_path_factory) -> tuple[Path, int]:
    """A copy of the database preprocessed with the paper preset through the CLI."""
    db = tmp_path_factory.mktemp("paper") / "db.duckdb"
    shutil.copyfile(ingested, db)
    out = runner.invoke(app, ["preprocess", "--preset", "paper", "--db", str(db), "--json"])
    assert out.exit_code == 0, out.output
    return db, json.loads(out.stdout)["version_id"]


def test_paper_preset_samples_hold_the_cartesian_shape(paper):
    db, version = paper
    samples = load_samples(Store(db), version)
    ra = [f"ra_{i}" for i in range(1, 5)]
    dra = [f"dra_{i}" for i in range(1, 5)]
    assert {*ra, *dra, "rp_1", "rp_4", "phase", "vx"} <= set(samples.columns)
    assert "ra_5" not in samples.columns
    assert np.isfinite(samples[ra + dra].to_numpy()).all()
    stored = json.loads(Store(db).query_df("SELECT params FROM prep_versions").params[0])
    assert {k: stored[k] for k in PRESETS["paper"]} == PRESETS["paper"]
    # each outer segment's top-marker centroid in the body frame, against the known angles
    top = {s: np.mean([xyz[:2] for seg, xyz in RIGID.values() if seg == s and xyz[2] == 55], 0)
           for s in ("head", "tail")}  # fmt: skip
    for i, gait in enumerate(GAITS):
        phi = synthetic_trial(gait, 0.5, 6, seed=i).truth[["phi1", "phi2"]].to_numpy()
        s = samples[samples.trial_id == i + 1]
        rh, rt = np.hypot(*top["head"]), np.hypot(*top["tail"])
        expected = np.column_stack(
            [
                MIDDLE_MM / 2 + rh * np.cos(phi[:, 0]),
                rh * np.sin(phi[:, 0]),
                -MIDDLE_MM / 2 - rt * np.cos(phi[:, 1]),
                rt * np.sin(phi[:, 1]),
            ]
        )
        err = s[ra].to_numpy() - expected
        assert np.sqrt(np.mean(err**2)) < 1.0, gait  # mm; markers carry 0.2 mm noise


def test_default_preset_is_the_default_version(ingested, tmp_path):
    db = tmp_path / "db.duckdb"
    shutil.copyfile(ingested, db)
    store = Store(db)
    plain = preprocess(store, trials=[1], progress=False)
    named = preprocess(store, trials=[1], progress=False, preset="default")
    assert named.version_id == plain.version_id and named.skipped == [1]
    columns = load_samples(store, plain.version_id).filter(regex="^d?ra_").columns
    assert list(columns) == ["ra_1", "ra_2", "dra_1", "dra_2"]


@pytest.mark.parametrize("learner", ["phase-only", "TLS", "TLS+SUDS", "GMR", "GMR+SUDS"])
def test_each_learner_fits_and_predicts_on_the_paper_samples(paper, learner):
    db, version = paper
    samples = load_samples(Store(db), version)
    samples = samples[samples.frame % 4 == 0]  # 25 Hz: fast enough, 50 samples a cycle
    train = samples[samples.trial_id.isin([1, 2, 3, 4])]
    test = samples[samples.trial_id == 5]
    params = {"n_components": 4} if learner.startswith("GMR") else {}
    model = make_model(learner, **params).fit(train)
    pred = model.predict(test)
    assert len(pred) == len(test) and np.isfinite(pred[["vx", "vy", "wz"]].to_numpy()).all()
    if learner.startswith("TLS"):
        assert model.ra_columns_ == ["ra_1", "ra_2", "ra_3", "ra_4"]
        assert model.coefficients(test.phase.to_numpy())["A"].shape == (len(test), 3 + (
            4 if learner == "TLS+SUDS" else 0), 4)  # fmt: skip
    if learner.startswith("GMR"):
        assert {"ra_4", "dra_4"} <= set(model.columns_in_)


def test_unknown_preset_is_a_one_line_error_and_changes_nothing(ingested, tmp_path):
    db = tmp_path / "db.duckdb"
    shutil.copyfile(ingested, db)
    before = dump_db(db)
    out = runner.invoke(app, ["preprocess", "--preset", "papers", "--db", str(db)])
    assert out.exit_code == 2
    assert "--preset papers: unknown preset; expected one of default, paper" in out.output
    assert len(out.output.strip().splitlines()) == 1
    assert_same_db(before, dump_db(db))


def test_campaign_samples_keep_every_actuated_column(paper):
    from suds_exp.campaign.bank import SampleBank

    db, version = paper
    bank = SampleBank.build(load_samples(Store(db), version))
    assert [c for c in bank.columns if "ra_" in c] == [
        *(f"ra_{i}" for i in (1, 2)), *(f"dra_{i}" for i in (1, 2)),
        *(f"ra_{i}" for i in (3, 4)), *(f"dra_{i}" for i in (3, 4)),
    ]  # fmt: skip
