"""Snapshots of a whole database, to show that a step left it as it was.

A refused input must leave the DuckDB file exactly as it found it: take a `dump_db`
snapshot before the step and compare it with one taken after (`assert_same_db`), as
`numpy.testing.assert_array_equal` compares arrays.
"""

from __future__ import annotations

from pathlib import Path

import duckdb
import pandas as pd


def dump_db(path: Path) -> dict[str, pd.DataFrame]:
    """Every base table of the database at ``path``, keyed by table name.

    Each frame holds the table's rows ordered by all their columns, so two snapshots
    compare independently of storage order. A file that does not exist gives ``{}``.
    The database is opened read-only.
    """
    if not Path(path).exists():
        return {}
    con = duckdb.connect(str(path), read_only=True)
    try:
        names = [
            r[0]
            for r in con.execute(
                "SELECT table_name FROM information_schema.tables "
                "WHERE table_type = 'BASE TABLE' ORDER BY 1"
            ).fetchall()
        ]
        return {n: con.execute(f'SELECT * FROM "{n}" ORDER BY ALL').df() for n in names}
    finally:
        con.close()


def assert_same_db(before: dict[str, pd.DataFrame], after: dict[str, pd.DataFrame]) -> None:
    """Raise `AssertionError` unless two `dump_db` snapshots hold the same tables and rows.

    Values are compared as `pandas.testing.assert_frame_equal` does, dtypes aside (an
    empty table's column may come back with another dtype).
    """
    assert sorted(before) == sorted(after)
    for name in before:
        pd.testing.assert_frame_equal(before[name], after[name], check_dtype=False)
