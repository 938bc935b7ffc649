"""`Store`: the one DuckDB file every step reads from and writes to."""

from __future__ import annotations

import itertools
import signal
import threading
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import duckdb

from suds_exp.display import Summary
from suds_exp.errors import StoreError
from suds_exp.store import migrate
from suds_exp.store.engine import default_db_path, make_engine, open_problem, retry_on_lock
from suds_exp.store.integrity import mark_written
from suds_exp.store.lock import WriteLock

if TYPE_CHECKING:  # loaded when a block opens the file: a Store is made without them
    import pandas as pd
    import sqlalchemy as sa

_frame_names = itertools.count()


class Store(Summary):
    """A DuckDB database file, opened only for the length of each block.

    ``with store.write() as conn`` gives a SQLAlchemy connection inside one transaction
    (committed when the block ends, rolled back if it raises) after applying pending
    migrations; ``with store.read() as conn`` gives a read-only one. Both wait briefly
    when another process holds the file. ``with store.locked(command, name):`` holds the
    database's write lock (`suds_exp.store.lock`) for a whole command; every write takes
    it too. A damaged file is refused before it is opened (`suds_exp.store.integrity`).

    Parameters
    ----------
    path : path-like, optional
        The database file; ``$SUDS_DB`` or ``./suds.duckdb`` when None.
    """

    def __init__(self, path: str | Path | None = None):
        self.path = Path(path) if path is not None else default_db_path()
        self._migrated = False

    def _summary(self):
        from suds_exp.store.rows import contents

        size = self.path.stat().st_size / 1e6 if self.path.exists() else 0.0
        return f"Store {self.path}", [("size", f"{size:.1f} MB"), ("holds", contents(self.path))]

    # -- connections ---------------------------------------------------------------
    def locked(self, command: str, name: str | None = None, wait_s: float | None = None):
        """The database's write lock for ``command`` (its ``name``: the campaign, stream,
        version or run), a context manager; another writer waits up to ``wait_s`` s
        (default `suds_exp.store.lock.WRITE_WAIT_S`) and is then refused in one line."""
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise open_problem(exc, self.path) from None
        return WriteLock(self.path, command, name, wait_s)

    def upgrade(self, target: int | None = None) -> list[str]:
        """Create the file if needed and apply pending migrations; return their names.

        Refuses (`StoreError`) before the file or its folder is touched when no migration
        files are installed."""
        migrations = migrate.available_migrations()
        with self.locked("init"), self._writable() as conn:
            applied = migrate.apply_on(conn, migrations, target)
        if target is None:
            self._migrated = True
        return applied

    @contextmanager
    def writer(self) -> Iterator[sa.Connection]:
        """A writable connection without a transaction; ``with conn.begin():`` per unit.

        For many small transactions in a row (one per ingested file): the file is held
        for the whole block, and DuckDB checkpoints once when it ends instead of after
        every transaction.
        """
        migrations = None if self._migrated else migrate.available_migrations()
        with self.locked("write"), self._writable() as conn:
            # pending migrations first, on the block's own connection: a second opening
            # of the file (~14 ms with its checkpoint) per command otherwise
            if migrations is not None:
                migrate.apply_on(conn, migrations)
                self._migrated = True
            yield conn

    @contextmanager
    def write(self) -> Iterator[sa.Connection]:
        """A connection in one transaction; the file is held only inside the block."""
        with self.writer() as conn, conn.begin():
            yield conn

    @contextmanager
    def read(self) -> Iterator[sa.Connection]:
        """A read-only connection; refuses a file that does not exist."""
        if not self.path.exists():
            raise StoreError(f"{self.path}: no database here; create one first", step="init")
        # an installation without its migrations is broken for reading too: refuse it in
        # one line here rather than let a later write fail far from the cause
        migrate.available_migrations()
        with self._connect(read_only=True) as conn:
            yield conn

    @contextmanager
    def _writable(self) -> Iterator[sa.Connection]:
        # a refused write in one line (`_write_problem`), and the file's integrity record
        # renewed whatever happened
        try:
            with self._connect(read_only=False) as conn:
                yield conn
        except Exception as exc:
            import sqlalchemy as sa  # loaded by now: the block's engine is SQLAlchemy's

            if isinstance(exc, duckdb.Error | sa.exc.DBAPIError):
                raise _write_problem(exc, self.path) from None
            raise
        finally:
            mark_written(self.path)

    @contextmanager
    def _connect(self, read_only: bool) -> Iterator[sa.Connection]:
        # one engine per block, disposed at its end, so the file is held only inside it
        engine = make_engine(self.path, read_only=read_only)
        try:
            conn = retry_on_lock(engine.connect, self.path)
            try:
                yield conn
            finally:
                with _sigint_deferred():
                    conn.close()
        finally:
            with _sigint_deferred():
                engine.dispose()

    # -- bulk data -------------------------------------------------------------------
    @staticmethod
    def insert_df(conn: sa.Connection, table: str, df: pd.DataFrame) -> int:
        """Insert ``df`` into ``table`` by column name through DuckDB's native path.

        Runs inside ``conn``'s transaction; returns the number of rows inserted.
        """
        if df.empty:
            return 0
        raw = conn.connection.driver_connection
        name = f"_suds_frame_{next(_frame_names)}"
        raw.register(name, df)
        try:
            conn.exec_driver_sql(f'INSERT INTO "{table}" BY NAME SELECT * FROM "{name}"')
        finally:
            raw.unregister(name)
        return len(df)

    @staticmethod
    def frame(
        conn: sa.Connection, query: Any, params: Sequence | Mapping | None = None
    ) -> pd.DataFrame:
        """Run ``query`` on ``conn`` and return a DataFrame through DuckDB's Arrow path.

        ``query`` is a SQLAlchemy Core statement (its bound parameters are used) or SQL
        text with DuckDB parameters (``?`` / ``$1`` / ``$name``) given in ``params``.
        """
        import sqlalchemy as sa

        raw = conn.connection.driver_connection
        if isinstance(query, sa.sql.ClauseElement):
            compiled = query.compile(dialect=conn.dialect)
            values = [compiled.params[k] for k in compiled.positiontup or []]
            return raw.execute(str(compiled), values).df()
        return raw.execute(query, params or []).df()

    def query_df(self, query: Any, params: Sequence | Mapping | None = None) -> pd.DataFrame:
        """Run ``query`` on a read-only connection and return a DataFrame."""
        with self.read() as conn:
            return self.frame(conn, query, params)


@contextmanager
def _sigint_deferred() -> Iterator[None]:
    """Serve a Ctrl-C that arrives inside the block after it: closing a connection half
    way makes SQLAlchemy log a multi-line "Exception closing connection"."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler if old is None else old)
    if caught:
        # delivered again to whoever handled it before (a campaign defers it itself)
        signal.raise_signal(signal.SIGINT)


def _write_problem(exc: BaseException, path: Path) -> Exception:
    """The one-line `StoreError` for a write DuckDB refused: a unique key another process
    already filled (the last defence against two writers), a file-system error, a
    damaged block; any other error is returned as it is, to surface unchanged."""
    orig = getattr(exc, "orig", exc)
    if isinstance(orig, duckdb.ConstraintException):
        first = str(orig).strip().splitlines()[0]
        return StoreError(
            f"{path}: refused a duplicate: {first}; another process stored these rows "
            "first; nothing of this transaction was written"
        )
    if isinstance(orig, duckdb.IOException):
        return open_problem(orig, path) or exc
    return exc
