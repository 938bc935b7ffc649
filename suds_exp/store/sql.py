"""Read-only SQL for users: `suds-exp sql` and notebooks."""

from __future__ import annotations

import json
import math
from typing import Any

import duckdb
import pandas as pd
import sqlalchemy as sa

from suds_exp.errors import StoreError
from suds_exp.store.store import Store


def run_readonly(store: Store, query: str) -> pd.DataFrame:
    """Run ``query`` on a read-only connection; a statement that would write is refused."""
    try:
        return store.query_df(query)
    except (duckdb.Error, sa.exc.DBAPIError) as exc:
        text = str(exc).strip().splitlines()[0]
        if "read-only" in text or "read only" in text:
            raise StoreError(
                "refused: this statement would change the database; queries here are read-only"
            ) from None
        raise StoreError(f"query failed: {text}") from None


def _plain(value: Any) -> Any:
    if isinstance(value, float) and math.isnan(value):
        return None
    if hasattr(value, "tolist"):
        return value.tolist()
    if hasattr(value, "isoformat"):
        return value.isoformat()
    return value


def frame_to_json(frame: pd.DataFrame) -> str:
    """A DataFrame as a JSON list of row objects (NaN -> null, timestamps ISO 8601)."""
    rows = [{k: _plain(v) for k, v in row.items()} for row in frame.to_dict(orient="records")]
    return json.dumps(rows, default=str)
