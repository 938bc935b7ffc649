"""The experiment stays with the data and reports degrade instead of
vanishing: the description given at ingest is stored, and run, report, findings
and status read it without ``--experiment``; trials a loop adds become levels of the
stored design; a report section that cannot be computed says why on the page."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

import cli
from suds_exp.errors import IngestError
from suds_exp.experiment import PAPER_DESIGN, load_design
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db

runner = CliRunner()

#: Three gaits of the user's own (none of the paper's), each run as a simulated gait.
OWN_GAITS = {"O": "glide", "D+": "crawl", "S-": "turn"}
#: The user's design: an unordered gait axis and the frequency.
OWN_EXPERIMENT = """
[[axis]]
name = "gait"
kind = "unordered"
levels = ["glide", "crawl", "turn"]

[[axis]]
name = "frequency_hz"
kind = "numeric"
"""

#: A campaign small enough for a test: two fast learners, two draws of two cycles.
SMALL_RUN = ("--models", "phase-only,TLS", "--boots", 2, "--train-cycles", 2)


def ok(*args: str) -> str:
    got = runner.invoke(cli.app, [str(a) for a in args])
    assert got.exit_code == 0, got.output + repr(got.exception)
    return got.stdout


def refused(*args: str) -> str:
    got = runner.invoke(cli.app, [str(a) for a in args])
    assert got.exit_code == 2, got.output + repr(got.exception)
    lines = got.stderr.strip().splitlines()
    assert len(lines) == 1, got.stderr
    return lines[0]


def own_manifest(folder: Path) -> Path:
    """The simulator's manifest with the user's gait names."""
    with open(folder / "manifest.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    out = folder / "own_manifest.csv"
    with open(out, "w", newline="") as fh:
        writer = csv.DictWriter(fh, ["file", "gait", "frequency_hz", "repeat", "notes"])
        writer.writeheader()
        for row in rows:
            writer.writerow({**row, "gait": OWN_GAITS[row["gait"]]})
    return out


@pytest.fixture(scope="module")
def own(tmp_path_factory) -> tuple[Path, Path]:
    """3 own gaits x 1/2 Hz x 2 repeats of 5 cycles, ingested with the user's design
    through the CLI, preprocessed and run (phase-only and TLS, 2 boots, 2 cycles):
    (database, folder)."""
    from suds_exp.sim import simulate_dataset

    work = tmp_path_factory.mktemp("own")
    simulate_dataset(work, gaits=tuple(OWN_GAITS), frequencies_hz=(0.5,), repeats=2, cycles=(5, 5))
    (work / "experiment.toml").write_text(OWN_EXPERIMENT)
    db = work / "own.duckdb"
    manifest = own_manifest(work)
    ok("ingest", "--manifest", manifest, "--experiment", work / "experiment.toml", "--db", db, "-q")
    ok("preprocess", "--db", db, "-q")
    ok("run", "own", *SMALL_RUN, "--db", db)
    return db, work


@pytest.fixture
def own_db(own, tmp_path) -> Path:
    copy = tmp_path / "own.duckdb"
    shutil.copy(own[0], copy)
    return copy


def test_ingest_stores_the_description_with_the_data(own):
    from suds_exp.ingest import stored_design

    db, work = own
    store = Store(db)
    row = store.query_df("SELECT id, source FROM experiment_description")
    assert row.id.tolist() == [1] and row.source[0] == str(work / "experiment.toml")
    design = stored_design(store)
    assert design.axes == load_design(work / "experiment.toml").axes
    assert design.source == str(work / "experiment.toml")


def test_a_paper_database_stores_no_description_and_reads_the_papers(tmp_path):
    from suds_exp.ingest import stored_design

    store = Store(tmp_path / "paper.duckdb")
    store.upgrade()
    assert stored_design(store) is PAPER_DESIGN
    assert store.query_df("SELECT count(*) AS n FROM experiment_description").n[0] == 0


def test_ingesting_again_with_the_same_description_duplicates_nothing(own_db, own):
    _, work = own
    store = Store(own_db)
    tables = ("experiment_description", "experiment_axes", "experiment_levels")
    before = {t: store.query_df(f"SELECT * FROM {t} ORDER BY ALL") for t in tables}
    # the same files again: every file is refused as already stored, the design is kept
    runner.invoke(
        cli.app,
        [
            "ingest",
            "--manifest",
            str(own_manifest(work)),
            "--experiment",
            str(work / "experiment.toml"),
            "--db",
            str(own_db),
            "-q",
        ],
    )
    for t in tables:
        after = store.query_df(f"SELECT * FROM {t} ORDER BY ALL")
        assert after.drop(columns=["created_at"], errors="ignore").equals(
            before[t].drop(columns=["created_at"], errors="ignore")
        ), t


def test_another_description_is_refused_and_leaves_the_database_as_it_was(own_db, own):
    _, work = own
    (work / "other.toml").write_text(
        '[[axis]]\nname = "gait"\nkind = "ordered"\nlevels = ["glide", "crawl", "turn"]\n'
    )
    before = dump_db(own_db)
    line = refused(
        "ingest",
        "--manifest",
        own_manifest(work),
        "--experiment",
        work / "other.toml",
        "--db",
        own_db,
        "-q",
    )
    assert "other.toml" in line and "'gait'" in line
    assert_same_db(before, dump_db(own_db))


def test_report_without_experiment_reads_the_stored_design(own, tmp_path):
    # a design not given again once printed a traceback (KeyError ... 'gait_sim')
    db, _ = own
    out = tmp_path / "report"
    ok("report", "own", "--out", out, "--db", db)
    page = (out / "index.html").read_text()
    assert "gait (unordered)" in page and "frequency_hz (numeric)" in page
    assert (out / "boxplot_gait.png").stat().st_size > 1000
    glm = (out / "glm.csv").read_text()
    assert "gait=same" in glm


def test_report_experiment_overrides_the_stored_design(own, tmp_path):
    db, work = own
    (work / "ordered.toml").write_text(
        '[[axis]]\nname = "gait"\nkind = "ordered"\nlevels = ["glide", "crawl", "turn"]\n'
        '[[axis]]\nname = "frequency_hz"\nkind = "numeric"\n'
    )
    out = tmp_path / "over"
    ok("report", "own", "--out", out, "--experiment", work / "ordered.toml", "--db", db)
    page = (out / "index.html").read_text()
    assert "gait (ordered)" in page and "gait (unordered)" not in page


def test_status_and_findings_read_the_stored_design(own):
    db, work = own
    text = ok("status", "own", "--db", db)
    assert "experiment.toml" in text and "gait (unordered)" in text
    doc = json.loads(ok("status", "own", "--db", db, "--json"))
    assert [a["name"] for a in doc["experiment"]["axes"]] == ["gait", "frequency_hz"]
    text = ok("findings", "own", "--boot", 20, "--db", db)
    assert "assume the paper's design" in text
    assert "no stored samples" not in text
    doc = json.loads(ok("findings", "own", "--boot", 20, "--db", db, "--json"))
    assert doc["design"] == str(work / "experiment.toml") and doc["caveat"]
    assert all(s["verdict"] != "not measurable" for s in doc["statistics"])
    assert doc["left_out"], "the findings the design cannot measure are named"


# -- an unknown gait without a description ------------------------------------------------


def test_an_unknown_gait_names_experiment_and_the_how_to(own):
    _, work = own
    line = refused("ingest", "--manifest", own_manifest(work), "--db", work / "paper.duckdb", "-q")
    assert "unknown gait 'glide'" in line
    assert "--experiment" in line and "docs/how-to/own-experiment.md" in line


# -- trials a loop adds -------------------------------------------------------------------


def test_add_trial_levels_makes_new_trials_levels_of_the_stored_design(own_db, own):
    from suds_exp.ingest import add_trial_levels, stored_design

    _, work = own
    store = Store(own_db)
    trial = int(store.query_df("SELECT min(id) AS id FROM trials").id[0])
    # a trial stored outside the design, as `gait design --verify` stored them before
    with store.write() as conn:
        conn.exec_driver_sql("UPDATE trials SET gait = 'loop-1.toml' WHERE id = ?", (trial,))
        conn.exec_driver_sql("DELETE FROM trial_conditions WHERE trial_id = ?", (trial,))
    design = add_trial_levels(store, {trial: "loop-1.toml"}, added_by="a test loop")
    assert design.axis("gait").added == ("loop-1.toml",)
    assert stored_design(store).axis("gait").added == ("loop-1.toml",)
    got = store.query_df(
        "SELECT axis, value FROM trial_conditions WHERE trial_id = ? ORDER BY axis", [trial]
    )
    assert got.value.tolist() == ["0.5", "loop-1.toml"]
    level = store.query_df("SELECT added_by FROM experiment_levels WHERE level = 'loop-1.toml'")
    assert level.added_by.tolist() == ["a test loop"]
    # again: nothing is duplicated
    add_trial_levels(store, {trial: "loop-1.toml"}, added_by="a test loop")
    assert (
        store.query_df("SELECT count(*) AS n FROM trial_conditions WHERE trial_id = ?", [trial]).n[
            0
        ]
        == 2
    )
    # a level name the design cannot hold is refused, the database unchanged
    before = dump_db(own_db)
    with pytest.raises(IngestError, match=r"level 'a;b'"):
        add_trial_levels(store, {trial: "a;b"}, added_by="a test loop")
    assert_same_db(before, dump_db(own_db))


def verify(db: Path, out: Path) -> None:
    """One verified design iteration (first order): one trial of a designed gait added."""
    ok(
        "gait",
        "design",
        "--iterations",
        1,
        "--verify",
        "--order",
        1,
        "--out",
        out,
        "--db",
        db,
        "--json",
    )


@pytest.mark.slow  # a verified design, a campaign, two reports and the findings: ~10-35 s
def test_run_report_and_findings_after_verify_on_the_users_design(own_db, tmp_path):
    verify(own_db, tmp_path / "design")
    store = Store(own_db)
    level = store.query_df(
        "SELECT level, added_by FROM experiment_levels WHERE added_by IS NOT NULL"
    )
    assert level.level.tolist() == ["design-1-it1.toml"]
    assert "design 1" in level.added_by[0]
    ok("run", "after", *SMALL_RUN, "--db", own_db)
    out = tmp_path / "report"
    ok("report", "after", "--out", out, "--db", own_db)
    # its one trial cannot give same-condition pairs: the cells left out are on the page
    assert "design-1-it1.toml@0.5 x 2 cycles" in (out / "index.html").read_text()
    # the user's file names only the declared levels: the added ones are kept from the store
    ok(
        "report",
        "after",
        "--out",
        tmp_path / "r2",
        "--experiment",
        _own_toml(tmp_path),
        "--db",
        own_db,
    )
    ok("findings", "after", "--boot", 10, "--db", own_db)


def _own_toml(folder: Path) -> Path:
    path = folder / "own.toml"
    path.write_text(OWN_EXPERIMENT)
    return path


# -- reports degrade ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def tiny(tmp_path_factory, simulated_db) -> Path:
    """The README tour's small campaign: one gait, 2 draws, 2 cycles (paper design)."""
    db = simulated_db(tmp_path_factory.mktemp("tiny"), "O", "1/2", repeats=2, cycles=6)
    ok(
        "run",
        "tiny",
        "--models",
        "phase-only,TLS,TLS+SUDS",
        "--boots",
        2,
        "--train-cycles",
        2,
        "--db",
        db,
        "-q",
    )
    return db


def test_the_tiny_campaigns_report_is_written_and_says_why_the_glm_is_missing(tiny, tmp_path):
    # once: "GLM: only 4 learner results at 2 cycles; need 10+" and an empty folder
    out = tmp_path / "tiny"
    ok("report", "tiny", "--out", out, "--db", tiny)
    page = (out / "index.html").read_text()
    assert "Not computed" in page and "only 4 learner results at 2 cycles; need 10+" in page
    assert (out / "glm.md").read_text().startswith("Not computed: GLM: only 4 learner")
    assert (out / "findings.csv").is_file() and (out / "categories.csv").is_file()
    assert (out / "boxplot_gait.png").stat().st_size > 1000


def test_a_design_without_same_condition_pairs_reports_the_rest(own, tmp_path):
    db, _ = own
    ok(
        "run",
        "cross",
        *SMALL_RUN,
        "--train-conditions",
        "glide",
        "--test-conditions",
        "crawl,turn",
        "--db",
        db,
    )
    out = tmp_path / "cross"
    ok("report", "cross", "--out", out, "--db", db)
    page = (out / "index.html").read_text()
    assert "no same-condition results" in page
    assert (out / "iqr.md").read_text().startswith("Not computed: no same-condition results")
    # the rest is written: box plots and their numbers; the GLM (4 TLS results) says why
    assert (out / "categories.csv").is_file() and (out / "boxplot_gait.png").is_file()
    assert (out / "glm.md").read_text().startswith("Not computed: GLM: only 4 learner results")


# -- the migration -------------------------------------------------------------------------


def test_a_database_with_stored_axes_upgrades_to_a_stored_description(tmp_path):
    from suds_exp.ingest import stored_design
    from suds_exp.store.engine import make_engine

    db = tmp_path / "old.duckdb"
    store = Store(db)
    store.upgrade(target=20)
    engine = make_engine(db)
    with engine.begin() as conn:
        conn.exec_driver_sql(
            "INSERT INTO experiment_axes VALUES ('gait', 0, 'unordered', '[\"a\", \"b\"]'), "
            "('frequency_hz', 1, 'numeric', NULL)"
        )
        conn.exec_driver_sql(
            "INSERT INTO experiment_levels VALUES ('gait', 'a', 0), ('gait', 'b', 1)"
        )
    engine.dispose()
    # read before the upgrade (a read-only command on an old file): the axes are the design
    assert [a.name for a in stored_design(Store(db)).axes] == ["gait", "frequency_hz"]
    Store(db).upgrade()
    rows = Store(db).query_df("SELECT id, source FROM experiment_description")
    assert rows.id.tolist() == [1] and "before migration 021" in rows.source[0]
    design = stored_design(Store(db))
    assert design.axis("gait").levels == ("a", "b") and design.axis("gait").added == ()
    levels = Store(db).query_df("SELECT level, added_by FROM experiment_levels ORDER BY level")
    assert levels.level.tolist() == ["a", "b"] and levels.added_by.isna().all()


def test_a_design_with_several_condition_axes_takes_no_added_trials(own_db):
    from suds_exp.experiment import Axis, ExperimentDesign
    from suds_exp.ingest import add_trial_levels, trial_level_axis

    two = ExperimentDesign(
        (Axis("gait", "unordered", ("a", "b")), Axis("surface", "unordered", ("sand", "mud"))),
        "two.toml",
    )
    with pytest.raises(IngestError, match=r"^two\.toml: the design has 2 condition axes"):
        trial_level_axis(two)
    assert trial_level_axis(PAPER_DESIGN).name == "gait"
    before = dump_db(own_db)
    with pytest.raises(
        IngestError, match=r"^trial 1 is stored as '(glide|crawl|turn)', not 'x.toml'"
    ):
        add_trial_levels(Store(own_db), {1: "x.toml"}, added_by="a test loop")
    with pytest.raises(IngestError, match=r"no trial 999"):
        add_trial_levels(Store(own_db), {999: "x.toml"}, added_by="a test loop")
    with pytest.raises(IngestError, match=r"axis 'frequency_hz': expected the design's one"):
        add_trial_levels(Store(own_db), {1: "x.toml"}, added_by="t", axis="frequency_hz")
    assert_same_db(before, dump_db(own_db))
