"""The DuckDB store: engine, migrations, table declarations and read-only SQL.

`Store` (SQLAlchemy connections, pandas frames) and `suds_exp.store.rows` (plain rows
through DuckDB alone, for the small commands that start in a fraction of a second).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from suds_exp.lazy import exports

if TYPE_CHECKING:  # what the names are, for readers and static tools; loaded on first use
    from suds_exp.store.engine import default_db_path
    from suds_exp.store.sql import frame_to_json, run_readonly
    from suds_exp.store.store import Store

#: Where each public name lives. Loaded on first use (PEP 562), so that `suds-exp trials`
#: and `sql` can read through `suds_exp.store.rows` without pandas and SQLAlchemy.
_HOMES = {
    "Store": "suds_exp.store.store",
    "default_db_path": "suds_exp.store.engine",
    "frame_to_json": "suds_exp.store.sql",
    "run_readonly": "suds_exp.store.sql",
}


__all__ = ["Store", "default_db_path", "frame_to_json", "run_readonly"]

__getattr__, __dir__ = exports(__name__, _HOMES, __all__)
