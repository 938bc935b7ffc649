"""The store: migrations, read-only SQL, other processes opening the file."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.errors import StoreError
from suds_exp.store import Store, migrate
from suds_exp.store.engine import make_engine

runner = CliRunner()


def test_help_lists_the_commands():
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    # the stable command names
    names = "init ingest trials sql simulate connection effects preprocess run status report"
    for name in (names + " discrepancy demo").split():
        assert f" {name} " in result.stdout, name


def test_init_creates_then_reports_up_to_date(db):
    first = runner.invoke(app, ["init", "--db", str(db)])
    assert first.exit_code == 0 and "applied 001_trials_markers" in first.stdout
    second = runner.invoke(app, ["init", "--db", str(db)])
    assert second.exit_code == 0 and "up to date" in second.stdout


def test_db_from_environment_variable(tmp_path, monkeypatch):
    monkeypatch.setenv("SUDS_DB", str(tmp_path / "env.duckdb"))
    assert runner.invoke(app, ["init"]).exit_code == 0
    assert (tmp_path / "env.duckdb").exists()


def test_database_at_migration_1_upgrades_with_data_intact(db, make_qtm):
    store = Store(db)
    assert store.upgrade(target=1) == ["001_trials_markers"]
    engine = make_engine(db)
    with engine.begin() as conn:
        conn.exec_driver_sql(
            "INSERT INTO trials (source_file, content_hash, format, sample_rate_hz, "
            "n_frames, marker_names) "
            "VALUES ('old.tsv', 'abc', 'qtm-tsv', 100, 1, ['m'])"
        )
        conn.exec_driver_sql("INSERT INTO markers VALUES (1, 1, 0.0, 'm', 1.0, 2.0, 3.0, false)")
    engine.dispose()
    applied = Store(db).upgrade()
    names = [m.name for m in migrate.available_migrations()]
    assert applied == names[1:]
    rows = Store(db).query_df("SELECT source_file, n_frames FROM trials")
    assert rows.to_dict("records") == [{"source_file": "old.tsv", "n_frames": 1}]
    marks = Store(db).query_df("SELECT x, y, z FROM markers")
    assert marks.to_dict("records") == [{"x": 1.0, "y": 2.0, "z": 3.0}]
    versions = Store(db).query_df("SELECT version FROM schema_migrations ORDER BY 1")
    assert list(versions.version) == [m.version for m in migrate.available_migrations()]
    # a new trial after the upgrade takes the next id from the sequence
    assert runner.invoke(app, ["ingest", str(make_qtm("new.tsv")), "--db", str(db)]).exit_code == 0
    assert list(Store(db).query_df("SELECT id FROM trials ORDER BY id").id) == [1, 2]


def test_edited_migration_is_refused(db, tmp_path):
    folder = tmp_path / "migrations"
    shutil.copytree(Path(str(migrate.migrations_dir())), folder)
    engine = make_engine(db)
    try:
        migrate.upgrade(engine, directory=folder)
        first = sorted(folder.glob("*.sql"))[0]
        first.write_text(first.read_text() + "\n-- edited\n")
        with pytest.raises(StoreError, match="was edited after it was applied"):
            migrate.upgrade(engine, directory=folder)
    finally:
        engine.dispose()


def test_failed_migration_leaves_no_trace(db, tmp_path):
    folder = tmp_path / "migrations"
    folder.mkdir()
    (folder / "001_ok.sql").write_text("CREATE TABLE a (x INTEGER);")
    (folder / "002_broken.sql").write_text(
        "CREATE TABLE b (x INTEGER); INSERT INTO nowhere VALUES (1);"
    )
    engine = make_engine(db)
    try:
        with pytest.raises(StoreError, match="002_broken.sql failed and was not applied"):
            migrate.upgrade(engine, directory=folder)
        with engine.connect() as conn:
            tables = {
                r[0]
                for r in conn.exec_driver_sql("SELECT table_name FROM information_schema.tables")
            }
            versions = conn.exec_driver_sql("SELECT version FROM schema_migrations").fetchall()
    finally:
        engine.dispose()
    assert "a" in tables and "b" not in tables
    assert versions == [(1,)]


def test_a_new_database_is_opened_once_for_all_its_migrations(db, monkeypatch):
    """Each migration is its own transaction, but on one connection: opening the file
    (and checkpointing it on close) per migration made every new database cost ~0.3 s."""
    import duckdb

    opened = []
    connect = duckdb.connect

    def counting(*args, **kwargs):
        # the file's openings only (the driver probes its settings on ":memory:" once)
        target = str(args[0] if args else kwargs.get("database"))
        if target.endswith(".duckdb"):
            opened.append(target)
        return connect(*args, **kwargs)

    monkeypatch.setattr(duckdb, "connect", counting)
    applied = Store(db).upgrade()
    assert applied == [m.name for m in migrate.available_migrations()]
    assert len(opened) == 1, opened
    # a write block migrates on its own connection: a new file is opened once, too
    opened.clear()
    other = db.with_name("other.duckdb")
    with Store(other).write() as conn:
        conn.exec_driver_sql("SELECT 1")
    assert len(opened) == 1, opened
    versions = Store(other).query_df("SELECT count(*) AS n FROM schema_migrations").n[0]
    assert versions == len(applied)


def test_sql_refuses_writes_and_answers_reads(db, make_qtm):
    assert runner.invoke(app, ["ingest", str(make_qtm("a.tsv")), "--db", str(db)]).exit_code == 0
    refused = runner.invoke(app, ["sql", "DELETE FROM trials", "--db", str(db)])
    assert refused.exit_code == 2
    assert "read-only" in refused.stderr
    assert Store(db).query_df("SELECT count(*) AS n FROM trials").n[0] == 1
    counted = runner.invoke(
        app, ["sql", "SELECT count(*) AS n FROM trials", "--db", str(db), "--json"]
    )
    assert counted.exit_code == 0 and json.loads(counted.stdout) == [{"n": 1}]
    table = runner.invoke(app, ["sql", "SELECT count(*) AS n FROM trials", "--db", str(db)])
    assert table.exit_code == 0 and "1" in table.stdout


def test_sql_on_missing_database_says_so(tmp_path):
    result = runner.invoke(app, ["sql", "SELECT 1", "--db", str(tmp_path / "none.duckdb")])
    assert result.exit_code == 2 and "suds-exp init" in result.stderr


def test_file_opens_read_only_in_a_separate_duckdb_process(db, make_qtm):
    assert runner.invoke(app, ["ingest", str(make_qtm("a.tsv")), "--db", str(db)]).exit_code == 0
    code = (
        "import duckdb, sys; con = duckdb.connect(sys.argv[1], read_only=True); "
        "print(con.execute('SELECT count(*) FROM markers').fetchone()[0])"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, str(db)], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) == 150


def test_stock_duckdb_cli_opens_the_file_read_only(db, make_qtm):
    cli_path = shutil.which("duckdb") or str(Path(sys.executable).parent / "duckdb")
    if not Path(cli_path).exists():
        pytest.skip("the duckdb CLI (pip package duckdb-cli) is not installed")
    assert runner.invoke(app, ["ingest", str(make_qtm("a.tsv")), "--db", str(db)]).exit_code == 0
    done = subprocess.run(
        [cli_path, "-readonly", "-csv", str(db), "-c", "SELECT count(*) AS n FROM markers"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["n", "150"]


def test_trials_command_shows_conditions(db, make_qtm, tmp_path):
    make_qtm("a.tsv")
    manifest = tmp_path / "m.csv"
    manifest.write_text("file,gait,frequency_hz,repeat,notes\na.tsv,S-,0.5,3,\n")
    assert (
        runner.invoke(app, ["ingest", "--manifest", str(manifest), "--db", str(db)]).exit_code == 0
    )
    shown = runner.invoke(app, ["trials", "--db", str(db)])
    assert shown.exit_code == 0 and "S-" in shown.stdout and "a.tsv" in shown.stdout
