"""Plain rows read through DuckDB alone: what the small commands print.

`suds-exp trials`, `sql` and the like read a few rows and print them; a `Store` would load
SQLAlchemy and pandas (about a second) to do the same. Here a read-only DuckDB connection
gives column names and tuples (`Rows`); `Rows.to_frame` makes the DataFrame a notebook
wants, loading pandas then.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import TYPE_CHECKING, Any

import duckdb

from suds_exp.errors import StoreError
from suds_exp.store import migrate
from suds_exp.store.engine import retry_on_lock

if TYPE_CHECKING:
    import pandas as pd

#: the trials as users see them: one row per trial, its condition, rate (Hz) and size
TRIALS_SQL = """
SELECT id, source_file, format, gait, frequency_hz, repeat, sample_rate_hz, n_frames,
       len(marker_names) AS n_markers, ingested_at, notes
FROM trials ORDER BY id
"""


@dataclass(frozen=True)
class Rows:
    """A query's result: ``columns`` (names) and ``rows`` (tuples of Python values)."""

    columns: tuple[str, ...]
    rows: list[tuple]

    def __len__(self) -> int:
        return len(self.rows)

    def records(self) -> list[dict[str, Any]]:
        """One dict a row; NaN becomes None, dates and times ISO 8601 text."""
        return [{c: plain(v) for c, v in zip(self.columns, row, strict=True)} for row in self.rows]

    def column(self, name: str) -> list:
        i = self.columns.index(name)
        return [row[i] for row in self.rows]

    def to_frame(self) -> pd.DataFrame:
        import pandas as pd

        return pd.DataFrame.from_records(self.rows, columns=list(self.columns))


def plain(value: Any) -> Any:
    """A value as JSON has it: NaN -> None, arrays -> lists, dates and times ISO 8601,
    DECIMAL numbers (DuckDB's type of a literal such as 1.5) -> float."""
    if isinstance(value, Decimal):
        return float(value)
    if isinstance(value, float) and math.isnan(value):
        return None
    if hasattr(value, "tolist"):
        return value.tolist()
    if hasattr(value, "isoformat"):
        return value.isoformat()
    return value


@contextmanager
def read_connection(path: Path) -> Iterator[duckdb.DuckDBPyConnection]:
    """A read-only DuckDB connection to the database file ``path`` for the block; waits
    out a writer as `Store.read` does, and refuses a file that is not there."""
    path = Path(path)
    if not path.exists():
        raise StoreError(f"{path}: no database here; create one first", step="init")
    migrate.available_migrations()  # a broken installation is refused here too
    conn = retry_on_lock(lambda: duckdb.connect(str(path), read_only=True), path)
    try:
        yield conn
    finally:
        conn.close()


def text_literal(value: str) -> str:
    """``value`` as a SQL string literal (quotes doubled), for queries of the small
    commands: DuckDB loads pandas (about a second) on the first bound parameter, to check
    whether it is a pandas value."""
    return "'" + str(value).replace("'", "''") + "'"


def read_rows(path: Path, query: str, params: Sequence | Mapping | None = None) -> Rows:
    """Run ``query`` (DuckDB SQL, parameters ``?``/``$name`` in ``params``) on a read-only
    connection to the database file ``path``; waits out a writer as `Store.read` does."""
    with read_connection(path) as conn:
        cursor = conn.execute(query, params or [])
        columns = tuple(d[0] for d in cursor.description or ())
        return Rows(columns, cursor.fetchall())


def query_rows(path: Path, query: str) -> Rows:
    """A user's SQL on a read-only connection; a statement that would write, or one that
    fails, is refused in one line (`StoreError`)."""
    try:
        return read_rows(path, query)
    except duckdb.Error as exc:
        raise query_problem(exc) from None


def query_problem(exc: BaseException) -> StoreError:
    """The one line for a user's query DuckDB refused."""
    text = str(exc).strip().splitlines()[0]
    if "read-only" in text or "read only" in text:
        return StoreError(
            "refused: this statement would change the database; queries here are read-only"
        )
    return StoreError(f"query failed: {text}")


def trial_rows(path: Path) -> Rows:
    """One row per trial: id, file, format, condition, rate (Hz), frames, markers."""
    return read_rows(path, TRIALS_SQL)


#: what a database holds, as a `Store` shows it: table -> what its rows are called (the
#: preprocessing versions are preprocess's to read: a `Version` shows itself)
CONTENTS = {"trials": "trials", "campaigns": "campaigns", "results": "results"}


def contents(path: Path) -> dict[str, int] | str:
    """How many trials, campaigns and results the file ``path`` holds, read in
    one try (no waiting: a notebook's display must not hang); else why not, in words."""
    path = Path(path)
    if not path.exists():
        return "no file yet"
    try:
        conn = duckdb.connect(str(path), read_only=True)
    except duckdb.Error as exc:
        return "busy (held by another process)" if "lock" in str(exc) else "unreadable"
    try:
        have = {r[0] for r in conn.execute("SELECT table_name FROM duckdb_tables()").fetchall()}
        return {
            word: conn.execute(f'SELECT count(*) FROM "{table}"').fetchone()[0]
            for table, word in CONTENTS.items()
            if table in have
        }
    finally:
        conn.close()
