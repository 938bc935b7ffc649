"""The DuckDB store: engine, migrations, table declarations and read-only SQL."""

from suds_exp.store.engine import default_db_path
from suds_exp.store.sql import frame_to_json, run_readonly
from suds_exp.store.store import Store

__all__ = ["Store", "default_db_path", "frame_to_json", "run_readonly"]
