"""The tables and views the migration files create, read from their SQL text in order, so
independently of the migration runner (`suds_exp.store.migrate`), whose result it checks:
tests/test_packaging.py in a checkout, .ci/wheel_check.sh against an installed wheel."""

import re
from pathlib import Path

# CREATE TABLE/VIEW, DROP TABLE/VIEW and ALTER TABLE ... RENAME TO, in file order: a
# migration may rebuild a table under a temporary name and rename it (016 does).
STATEMENT = re.compile(
    r"CREATE\s+(?:OR\s+REPLACE\s+)?(?P<create>TABLE|VIEW)\s+(?:IF\s+NOT\s+EXISTS\s+)?(?P<new>\w+)"
    r"|DROP\s+(?P<drop>TABLE|VIEW)\s+(?:IF\s+EXISTS\s+)?(?P<old>\w+)"
    r"|ALTER\s+TABLE\s+(?P<src>\w+)\s+RENAME\s+TO\s+(?P<dst>\w+)",
    re.I,
)
COMMENT = re.compile(r"--[^\n]*")


def created_by_migrations(folder: Path) -> tuple[set[str], set[str]]:
    """Names of the tables and views left after applying every ``*.sql`` in ``folder``."""
    tables, views = {"schema_migrations"}, set()
    for path in sorted(Path(folder).glob("*.sql")):
        text = COMMENT.sub("", path.read_text(encoding="utf-8"))
        for m in STATEMENT.finditer(text):
            if m["create"]:
                (tables if m["create"].upper() == "TABLE" else views).add(m["new"])
            elif m["drop"]:
                (tables if m["drop"].upper() == "TABLE" else views).discard(m["old"])
            else:
                tables.discard(m["src"])
                tables.add(m["dst"])
    return tables, views
