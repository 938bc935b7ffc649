"""Read-only SQL for users: `suds-exp sql` and notebooks."""

from __future__ import annotations

import json

import duckdb
import pandas as pd
import sqlalchemy as sa

from suds_exp.store.rows import plain as _plain
from suds_exp.store.rows import query_problem
from suds_exp.store.store import Store


def run_readonly(store: Store, query: str) -> pd.DataFrame:
    """Run ``query`` on a read-only connection; a statement that would write is refused."""
    try:
        return store.query_df(query)
    except (duckdb.Error, sa.exc.DBAPIError) as exc:
        raise query_problem(exc) from None


def frame_to_json(frame: pd.DataFrame) -> str:
    """A DataFrame as a JSON list of row objects (NaN -> null, timestamps ISO 8601)."""
    rows = [{k: _plain(v) for k, v in row.items()} for row in frame.to_dict(orient="records")]
    return json.dumps(rows, default=str)
