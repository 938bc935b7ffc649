"""Reading the small CSV files users write by hand (manifest, marker layout)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from suds_exp.errors import IngestError


def read_text_table(path: Path, what: str, columns: tuple[str, ...]) -> pd.DataFrame:
    """The CSV at ``path`` as text cells (empty cells as ""), header names stripped.

    Raises `IngestError` naming ``what`` (e.g. "manifest") when the file is missing, is
    not a CSV, or lacks one of ``columns``.
    """
    path = Path(path)
    if not path.is_file():
        raise IngestError(f"{path}: {what} file not found")
    try:
        table = pd.read_csv(path, dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError):
        raise IngestError(f"{path}: expected a CSV with columns {','.join(columns)}") from None
    table.columns = [c.strip() for c in table.columns]
    lacking = [c for c in columns if c not in table.columns]
    if lacking:
        raise IngestError(f"{path}: line 1: {what} lacks column(s) {', '.join(lacking)}")
    return table
