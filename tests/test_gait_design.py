"""Predict, design (and verify) through the CLI on a small simulated dataset; the stored
iterations; bad input leaves the database unchanged."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.gait.shape import ellipse, paper_gaits
from suds_exp.gait.truth import simulate_forward
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db

runner = CliRunner()


def ok(*args: str) -> str:
    r = runner.invoke(app, list(args))
    assert r.exit_code == 0, r.output + (r.stderr or "")
    return r.stdout


@pytest.fixture(scope="module")
def small(tmp_path_factory, simulated_db) -> Path:
    """O and D+ at 1/2 Hz, 2 repeats of 6 cycles, ingested and preprocessed."""
    return simulated_db(tmp_path_factory.mktemp("gait-small"), "O,D+", "1/2", repeats=2, cycles=6)


@pytest.fixture
def db(small, tmp_path) -> Path:
    copy = tmp_path / "db.duckdb"
    shutil.copy(small, copy)
    return copy


def test_the_simulator_reproduces_the_issue_figures():
    # nominal robot, gait followed exactly at 1/2 Hz, mean of cycles 3-5
    gaits = paper_gaits() + [ellipse(1.2, 1.2), ellipse(1.2, 1.2, 0.5)]
    got = simulate_forward(gaits, 0.5)
    np.testing.assert_allclose(got, [23.9, 27.9, 24.3, 22.7, 30.6, 32.5, 54.4], atol=0.051)


def _predict(db: Path, gait: Path, boot: str) -> dict:
    args = ["--gait-file", str(gait), "--freqs", "1/2", "--boots", boot, "--db", str(db)]
    return json.loads(ok("gait", "predict", *args, "--json"))


def test_predict_json_has_the_motion_keys_and_the_support_flag(db, tmp_path):
    g = tmp_path / "circle.toml"
    g.write_text(ellipse(1.0, 1.0, name="c").to_toml())
    doc = _predict(db, g, "0")
    assert doc["joints"] == ["phi1", "phi2"] and doc["n_boot"] == 0 and doc["interval"] == {}
    for key in ("forward_mm", "lateral_mm", "turn_rad", "mean_vx_mm_s"):
        assert np.isfinite(doc[key])
    # the circle O is a training gait here: inside the support, and the prediction is
    # near the simulator's
    assert doc["support"]["inside"] is True, doc["support"]
    assert doc["forward_mm"] == pytest.approx(simulate_forward(paper_gaits()[2:3])[0], rel=0.25)


@pytest.mark.slow
def test_predict_interval_holds_its_estimate_or_says_why(db, tmp_path):
    # 40 GMR refits on this dataset: 88 s measured
    g = tmp_path / "circle.toml"
    g.write_text(ellipse(1.0, 1.0, name="c").to_toml())
    doc = _predict(db, g, "40")
    assert doc["n_boot"] == 40
    for key in ("forward_mm", "lateral_mm", "turn_rad", "mean_vx_mm_s"):
        lo, hi = doc["interval"][key]
        # every estimate lies inside its interval, or a note says why not
        assert lo <= doc[key] <= hi or "outside its interval" in doc["interval_notes"][key]


def test_design_with_verify_stores_every_iteration_and_adds_trials(db, tmp_path):
    before = Store(db).query_df("SELECT count(*) AS n FROM trials")["n"].iloc[0]
    doc = json.loads(
        ok(
            "gait",
            "design",
            "--bound",
            "1.3",
            "--iterations",
            "2",
            "--verify",
            "--order",
            "1",
            "--out",
            str(tmp_path / "out"),
            "--db",
            str(db),
            "--json",
        )
    )
    its = doc["iterations"]
    assert [it["iteration"] for it in its] == [1, 2]
    for it in its:
        assert len(it["phase_rad"]) == len(it["phi1_rad"]) == len(it["phi2_rad"]) > 10
        assert max(np.abs(it["phi1_rad"]).max(), np.abs(it["phi2_rad"]).max()) <= 1.3
        for part in ("predicted", "achieved"):
            assert set(it[part]) == {"forward_mm", "lateral_mm", "turn_rad", "mean_vx_mm_s"}
    stored = Store(db).query_df(
        "SELECT * FROM gait_design_iterations WHERE design_id = ? ORDER BY iteration",
        [doc["design_id"]],
    )
    assert len(stored) == 2 and stored["trial_id"].notna().all()
    np.testing.assert_allclose(
        stored["achieved_forward_mm"], [it["achieved"]["forward_mm"] for it in its], atol=1e-3
    )
    after = Store(db).query_df("SELECT count(*) AS n FROM trials")["n"].iloc[0]
    assert after == before + 2
    # the verify trials are preprocessed into the same (only) version
    n_versions = Store(db).query_df("SELECT count(*) AS n FROM prep_versions")["n"].iloc[0]
    assert n_versions == 1
    assert (Path(doc["report"])).is_file()
    # and are levels of the stored design: a plain run and report take them
    added = Store(db).query_df("SELECT level FROM experiment_levels WHERE added_by IS NOT NULL")
    assert sorted(added.level) == [f"design-{doc['design_id']}-it{i}.toml" for i in (1, 2)]
    ok("run", "after", "--models", "TLS", "--boots", "1", "--train-cycles", "3",
       "--db", str(db), "-q")  # fmt: skip
    ok("report", "after", "--out", str(tmp_path / "report"), "--db", str(db))
    # SQL (results_axis_pairs) and Python classify the pairs alike; a designed gait has no
    # place on the ordered gait axis: same as itself, else far
    from suds_exp.analysis import load_results
    from suds_exp.analysis.design_tables import label_pairs
    from suds_exp.ingest import stored_design

    store = Store(db)
    py = label_pairs(load_results(store, "after"), stored_design(store))
    sql = store.query_df(
        "SELECT train_gait, test_gait, category FROM results_axis_pairs "
        "WHERE campaign = 'after' AND axis = 'gait'"
    )
    pairs = {tuple(r) for r in py[["train_gait", "test_gait", "gait_pair"]].to_numpy()}
    assert pairs == {tuple(r) for r in sql.to_numpy()}
    assert {c for t, d, c in pairs if t != d and ".toml" in t + d} == {"far"}


def test_design_without_verify_changes_no_trials(db, tmp_path):
    doc = json.loads(
        ok(
            "gait",
            "design",
            "--iterations",
            "1",
            "--order",
            "1",
            "--out",
            str(tmp_path / "o"),
            "--db",
            str(db),
            "--json",
        )
    )
    assert "achieved" not in doc["iterations"][0]
    assert Store(db).query_df("SELECT count(*) AS n FROM trials")["n"].iloc[0] == 4


@pytest.mark.parametrize(
    "args",
    [
        ["gait", "design", "--model", "NoSuchLearner"],
        ["gait", "predict", "--model", "NoSuchLearner", "--gait-file", "G"],
        ["gait", "design", "--bound", "-1"],
    ],
    ids=["design-learner", "predict-learner", "design-bound"],
)
def test_bad_options_are_one_line_and_leave_the_db_unchanged(db, tmp_path, args):
    g = tmp_path / "g.toml"
    g.write_text(ellipse(1.0, 1.0).to_toml())
    args = [str(g) if a == "G" else a for a in args]
    before = dump_db(db)
    r = runner.invoke(
        app,
        [
            *args,
            "--out" if args[1] == "design" else "--freqs",
            str(tmp_path / "o") if args[1] == "design" else "0.5",
            "--db",
            str(db),
        ],
    )
    assert r.exit_code == 2, r.output
    assert len(r.stderr.strip().splitlines()) == 1
    assert_same_db(before, dump_db(db))


def test_the_designer_s_tilted_start_is_the_phase_shifted_ellipse():
    from suds_exp.gait.design import LAGS_RAD, circle

    theta = np.linspace(0.0, 2 * np.pi, 50)
    for lag in LAGS_RAD:
        np.testing.assert_allclose(
            circle(1.0, 2, lag=lag).shape(theta), ellipse(1.0, 1.0, lag).shape(theta), atol=1e-12
        )


def test_a_loop_traced_twice_a_cycle_is_the_loop_at_twice_the_phase():
    from suds_exp.errors import ConfigError
    from suds_exp.gait.design import circle
    from suds_exp.gait.shape import FourierGait

    theta = np.linspace(0.0, 2 * np.pi, 50)
    loop = ellipse(1.1, 0.9, 0.4, c1=0.1)
    twice = loop.traced(2, order=2)
    assert twice.order == 2
    np.testing.assert_allclose(twice.shape(theta), loop.shape(2 * theta), atol=1e-12)
    np.testing.assert_allclose(twice.rate(theta), 2 * loop.rate(2 * theta), atol=1e-12)
    np.testing.assert_allclose(
        circle(1.0, 2, lag=0.3, traces=2).shape(theta),
        circle(1.0, 1, lag=0.3).shape(2 * theta),
        atol=1e-12,
    )
    # an order-2 gait keeps only what fits: its first harmonic, traced twice
    mixed = FourierGait([0.0, 0.0], [[1.0, 0.0], [0.2, 0.1]], [[0.0, 1.0], [0.0, 0.3]])
    np.testing.assert_allclose(
        mixed.traced(2, order=2).shape(theta),
        FourierGait([0.0, 0.0], [[1.0, 0.0]], [[0.0, 1.0]]).shape(2 * theta),
        atol=1e-12,
    )
    with pytest.raises(ConfigError, match="traces"):
        circle(1.0, 2, traces=3)
    with pytest.raises(ConfigError, match="times"):
        loop.traced(0, order=2)


def test_an_unknown_trust_radius_rule_is_refused():
    from suds_exp.errors import ConfigError
    from suds_exp.gait.design import DesignOptions

    DesignOptions(radius_rule="ratio").check()
    with pytest.raises(ConfigError, match="radius_rule"):
        DesignOptions(radius_rule="guess").check()


def test_connection_compares_the_learned_map_with_the_simulators(db, tmp_path):
    out = tmp_path / "conn.csv"
    docs = {
        d: json.loads(
            ok(
                "gait",
                "connection",
                "--out",
                str(out),
                "--grid",
                "7",
                "--compare",
                "--directions",
                d,
                "--db",
                str(db),
                "--json",
            )
        )
        for d in ("visited", "uniform")
    }
    for d, doc in docs.items():
        assert doc["directions"] == d and doc["n_inside"] > 0
        assert np.isfinite(doc["normalised_rms"]["mean"])
    assert out.is_file() and out.with_suffix(".png").is_file()
    r = runner.invoke(
        app, ["gait", "connection", "--out", str(out), "--directions", "all", "--db", str(db)]
    )
    assert r.exit_code == 2 and "--directions" in r.output + (r.stderr or "")


@pytest.mark.slow  # a verified design, a campaign, two reports and the findings: ~30 s
def test_run_report_and_findings_work_after_verify(db, tmp_path):
    # verify trials were once conditions outside the design; the next plain run
    # refused (a one-trial condition has no same-condition pair) and report crashed
    out = str(tmp_path / "out")
    ok("gait", "design", "--iterations", "1", "--verify", "--order", "1", "--out", out,
       "--db", str(db), "--json")  # fmt: skip
    levels = Store(db).query_df(
        "SELECT axis, level FROM experiment_levels WHERE added_by IS NOT NULL"
    )
    assert levels.values.tolist() == [["gait", "design-1-it1.toml"]]
    ok("run", "after", "--models", "phase-only,TLS", "--boots", "2", "--train-cycles", "3",
       "--db", str(db), "-q")  # fmt: skip
    out = tmp_path / "report"
    ok("report", "after", "--out", str(out), "--db", str(db))
    assert "design-1-it1.toml" in (out / "index.html").read_text()
    paper = Path(__file__).resolve().parents[1] / "suds_exp" / "experiment" / "paper.toml"
    ok(
        "report",
        "after",
        "--out",
        str(tmp_path / "r2"),
        "--experiment",
        str(paper),
        "--db",
        str(db),
    )
    ok("findings", "after", "--boot", "10", "--db", str(db))
