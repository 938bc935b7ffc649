"""`suds-exp report`: what it prints for a written report."""

from __future__ import annotations

from pathlib import Path


def report_document(index: Path) -> dict:
    """The report's ``index`` page and the names of the files beside it (sorted)."""
    files = sorted(p.name for p in index.parent.iterdir() if p.is_file())
    return {"index": str(index), "files": files}
