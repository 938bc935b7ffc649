"""The tables.py declarations, written through store.declare, mirror the migrated schema."""

import pytest
import sqlalchemy as sa

from suds_exp.campaign import tables as campaign_tables
from suds_exp.discrepancy import tables as discrepancy_tables
from suds_exp.preprocess import tables as preprocess_tables
from suds_exp.store import Store
from suds_exp.store import tables as store_tables
from suds_exp.store.declare import columns, declare_table

DECLARED = [
    table
    for module in (store_tables, preprocess_tables, campaign_tables, discrepancy_tables)
    for table in module.metadata.sorted_tables
]


def test_a_column_line_sets_type_and_flags():
    key, name, loadings, note = columns(
        """
        id        Integer  key
        name      String   required unique
        loadings  Float[]  required
        note      String
        """
    )
    assert (key.name, key.primary_key, key.nullable) == ("id", True, False)
    assert isinstance(name.type, sa.String) and name.unique and not name.nullable
    assert isinstance(loadings.type, sa.ARRAY) and isinstance(loadings.type.item_type, sa.Float)
    assert note.nullable and not note.primary_key and note.unique is None


@pytest.mark.parametrize("line", ["x Text required", "x Float requred", "x"])
def test_a_line_it_cannot_read_is_refused(line):
    with pytest.raises(ValueError):
        declare_table("t", sa.MetaData(), line)


def test_declarations_match_the_migrated_database(db):
    store = Store(db)
    store.upgrade()
    with store.read() as conn:
        inspector = sa.inspect(conn)
        for table in DECLARED:
            migrated = {c["name"]: c for c in inspector.get_columns(table.name)}
            assert list(migrated) == [c.name for c in table.columns], table.name
            for column in table.columns:
                if not column.primary_key:
                    assert migrated[column.name]["nullable"] == column.nullable, (
                        f"{table.name}.{column.name}"
                    )
