"""SQLAlchemy reflection on a migrated database: the evidence behind the dialect and the
SQLAlchemy pins in pyproject.toml.

suds-exp itself writes plain SQL, but users query the database from their own code, and
pandas/SQLAlchemy tools reflect tables. duckdb-engine 0.17 (its last release) cannot
reflect columns with SQLAlchemy >= 2.0.45 (pg_catalog.pg_collation). The pins admit only
versions on which this test passes; run it in a venv with another SQLAlchemy or dialect
to check a new bound.
"""

from __future__ import annotations

import sqlalchemy as sa

from suds_exp.store import Store
from suds_exp.store.engine import make_engine


def catalog(db) -> tuple[dict[str, set[str]], set[str]]:
    """Columns of every base table (name -> column names) and the view names, as DuckDB's
    own information_schema lists them (no SQLAlchemy reflection involved)."""
    frame = Store(db).query_df(
        "SELECT t.table_name, t.table_type, c.column_name FROM information_schema.tables t "
        "JOIN information_schema.columns c USING (table_schema, table_name) "
        "WHERE t.table_schema = 'main'"
    )
    tables = frame[frame.table_type == "BASE TABLE"]
    columns = {name: set(rows.column_name) for name, rows in tables.groupby("table_name")}
    views = set(frame[frame.table_type == "VIEW"].table_name)
    return columns, views


def test_inspect_reflects_every_table_column_and_view(db):
    Store(db).upgrade()
    columns, views = catalog(db)
    assert len(columns) > 10 and len(views) > 3
    engine = make_engine(db, read_only=True)
    try:
        inspector = sa.inspect(engine)
        assert set(inspector.get_table_names()) == set(columns)
        assert set(inspector.get_view_names()) == views
        for table, names in columns.items():
            reflected = inspector.get_columns(table)
            assert {c["name"] for c in reflected} == names, table
            assert all(isinstance(c["type"], sa.types.TypeEngine) for c in reflected), table
        # the whole schema into a MetaData, as pandas and ORMs do it
        meta = sa.MetaData()
        meta.reflect(bind=engine, views=True)
        assert set(meta.tables) == set(columns) | views
    finally:
        engine.dispose()
