"""The SQL vocabulary table ``learners``, written from the learner registry.

Migration 019 created the table (and 019/023 filled it by hand); since then its rows are
`suds_exp.vocabulary.REGISTRY`'s, written each time the store brings a database up to
date, so a learner added to the registry is labelled in ``results_labelled`` with no
migration. A new tag in `suds_exp.vocabulary.TAGS` is a new column: that one needs a
migration.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from suds_exp import vocabulary

if TYPE_CHECKING:
    import sqlalchemy as sa

#: The table's columns, in its order: name, family, suds, then one flag per tag.
COLUMNS = ("name", "family", "suds", *vocabulary.TAGS)


def learner_rows() -> list[tuple]:
    """One row per registered learner (`COLUMNS`), sorted by name."""
    return sorted(
        (i.name, i.family, i.suds, *(t in i.tags for t in vocabulary.TAGS))
        for i in vocabulary.REGISTRY
    )


def sync_learners(conn: sa.Connection) -> bool:
    """Make the ``learners`` table hold exactly the registry's rows, in one transaction
    on ``conn`` (outside one); False (nothing done) when the table does not exist yet (a
    database migrated to before 019) or already holds them."""
    duck = conn.connection.driver_connection
    with conn.begin():
        found = duck.execute(
            "SELECT count(*) FROM information_schema.tables WHERE table_name = 'learners'"
        ).fetchone()[0]
        if not found:
            return False
        have = duck.execute(f"SELECT {', '.join(COLUMNS)} FROM learners ORDER BY name").fetchall()
        want = learner_rows()
        if sorted(map(tuple, have)) == want:
            return False
        duck.execute("DELETE FROM learners")
        duck.executemany(
            f"INSERT INTO learners ({', '.join(COLUMNS)}) "
            f"VALUES ({', '.join('?' for _ in COLUMNS)})",
            want,
        )
    return True
