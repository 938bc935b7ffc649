"""Numbered plain-SQL migrations, applied in order, each in one transaction.

Files in ``migrations/`` are named ``NNN_description.sql``. The runner records each
applied file's version, name and SHA-256 in ``schema_migrations``; a file whose text
changed after it was applied is refused, because the database it describes no longer
matches the code.
"""

from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

import duckdb
import sqlalchemy as sa

from suds_exp.errors import StoreError

MIGRATIONS_DIR = Path(
    os.environ.get("SUDS_MIGRATIONS") or Path(__file__).resolve().parents[2] / "migrations"
)
_NAME = re.compile(r"^(\d{3})_([a-z0-9_]+)\.sql$")

_BOOKKEEPING = """
CREATE TABLE IF NOT EXISTS schema_migrations (
    version INTEGER PRIMARY KEY,
    name VARCHAR NOT NULL,
    checksum VARCHAR NOT NULL,
    applied_at TIMESTAMP NOT NULL DEFAULT current_timestamp
)
"""


@dataclass(frozen=True)
class Migration:
    """One migration file: its version number, name, SQL text and checksum."""

    version: int
    name: str
    sql: str
    checksum: str


def available_migrations(directory: Path = MIGRATIONS_DIR) -> list[Migration]:
    """The migration files in ``directory``, ordered by version."""
    found = []
    for path in sorted(directory.glob("*.sql")):
        m = _NAME.match(path.name)
        if not m:
            raise StoreError(f"{path}: migration files must be named NNN_name.sql")
        text = path.read_text(encoding="utf-8")
        found.append(
            Migration(int(m.group(1)), path.stem, text, hashlib.sha256(text.encode()).hexdigest())
        )
    versions = [m.version for m in found]
    if len(set(versions)) != len(versions):
        raise StoreError(f"{directory}: two migration files share a version number")
    return found


def applied_versions(conn: sa.Connection) -> dict[int, str]:
    """Version -> checksum of every migration recorded in the database."""
    conn.exec_driver_sql(_BOOKKEEPING)
    rows = conn.exec_driver_sql("SELECT version, checksum FROM schema_migrations").fetchall()
    return {int(v): c for v, c in rows}


def pending(conn: sa.Connection, migrations: list[Migration]) -> list[Migration]:
    """Migrations not yet applied; refuses edited or unknown applied ones."""
    done = applied_versions(conn)
    known = {m.version: m for m in migrations}
    for version, checksum in done.items():
        if version not in known:
            raise StoreError(
                f"database has migration {version:03d}, which this code does not know; "
                "upgrade suds-exp"
            )
        if known[version].checksum != checksum:
            raise StoreError(
                f"migration {known[version].name}.sql was edited after it was applied to "
                "this database; restore it and add a new migration instead"
            )
    return [m for m in migrations if m.version not in done]


def upgrade(
    engine: sa.Engine, target: int | None = None, directory: Path = MIGRATIONS_DIR
) -> list[str]:
    """Apply pending migrations up to ``target`` (all when None); return their names."""
    migrations = [
        m for m in available_migrations(directory) if target is None or m.version <= target
    ]
    with engine.begin() as conn:
        todo = pending(conn, migrations)
    applied = []
    for m in todo:
        with engine.begin() as conn:
            # DuckDB executes a multi-statement script in the open transaction.
            try:
                conn.connection.driver_connection.execute(m.sql)
            except duckdb.Error as exc:
                reason = str(exc).strip().splitlines()[0]
                raise StoreError(
                    f"migration {m.name}.sql failed and was not applied: {reason}"
                ) from None
            conn.execute(
                sa.text(
                    "INSERT INTO schema_migrations (version, name, checksum) VALUES (:v, :n, :c)"
                ),
                {"v": m.version, "n": m.name, "c": m.checksum},
            )
        applied.append(m.name)
    return applied
