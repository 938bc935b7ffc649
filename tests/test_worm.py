"""A real crawling C. elegans (Worm Tracker 2 features file in ../shared/refdata): ingest
keeps only segmented frames as data, the chain preprocesses, and our phase rate and
forward speed agree with the tracker's own features; a file that is not a WT2 features
file is a one-line error that leaves the database as it was."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.io import savemat
from typer.testing import CliRunner

from cli import app
from suds_exp.body.worm import run_worm, tracker_reference
from suds_exp.ingest import ingest_paths
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db

runner = CliRunner()


@pytest.fixture
def features(shared):
    return shared / "refdata" / "worm_schafer_wt2" / "short_worm_features.mat"


def test_only_segmented_frames_are_data(tmp_path, features):
    store = Store(tmp_path / "w.duckdb")
    (result,) = ingest_paths(store, [features], progress=False)
    assert result.status == "ingested"
    trial = store.query_df("SELECT * FROM trials").iloc[0]
    # frames 0-498 (the failures from 499 on end the recording), 49 skeleton points
    assert trial.format == "wt2-features" and trial.n_frames == 499
    assert list(trial.marker_names) == [f"p{i:02d}" for i in range(1, 50)]
    assert trial.sample_rate_hz == pytest.approx(30.03, abs=0.01)
    counts = store.query_df(
        "SELECT count(DISTINCT frame) FILTER (WHERE NOT missing) AS seen, "
        "count(DISTINCT frame) FILTER (WHERE missing) AS gaps, count(z) AS with_z, "
        "max(x) - min(x) AS span_mm FROM markers"
    ).iloc[0]
    # 400 segmented frames; the 99 stage-movement and dropped frames are gaps
    assert counts.seen == 400 and counts.gaps == 99 and counts.with_z == 0
    assert 1.0 < counts.span_mm < 20.0  # microns -> mm: the worm crawls a few mm


def test_worm_agrees_with_the_tracker(tmp_path, features):
    out = run_worm(features, tmp_path / "w.duckdb")
    ref = tracker_reference(features)
    assert ref["bend_frequency_hz"] == pytest.approx(0.442, abs=0.001)
    # tolerances a tracked animal's phase rate must meet
    assert out["phase_rate_hz"][0] == pytest.approx(ref["bend_frequency_hz"], rel=0.15)
    assert out["forward_speed_mm_s"] == pytest.approx(ref["speed_mm_s"], rel=0.30)
    assert sum(out["explained_variance_ratio"][:2]) > 0.9  # a travelling wave: 2 modes
    errors = out["errors"].set_index("model")
    assert list(errors.index) == ["constant", "phase-only", "TLS", "GMR"]
    assert (errors.n_train > 0).all() and (errors.n_test > 0).all()
    assert np.isfinite(errors.vx_pct).all()


def test_a_mat_file_that_is_not_wt2_features_is_one_line(tmp_path):
    path = tmp_path / "other.mat"
    savemat(path, {"data": np.zeros((3, 3))})
    db = tmp_path / "w.duckdb"
    assert runner.invoke(app, ["init", "--db", str(db)]).exit_code == 0
    before = dump_db(db)
    out = runner.invoke(app, ["ingest", str(path), "--db", str(db)])
    assert out.exit_code == 2
    message = out.stderr.strip()
    assert len(message.splitlines()) == 1, message
    assert f"{path}: not a Worm Tracker 2 features file" in message, message
    assert_same_db(before, dump_db(db))
