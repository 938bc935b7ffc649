"""Shared fixtures (temporary databases, capture files, an ingested synthetic dataset) and
the suite's order; the plain helpers they use are in `tests/helpers.py`."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from tests.helpers import SLOW_FILES, qtm_text, random_track

#: ../shared beside the repository, or where SUDS_SHARED points (a git worktree elsewhere)
SHARED = Path(os.environ.get("SUDS_SHARED") or Path(__file__).resolve().parents[2] / "shared")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Run the `SLOW_FILES` first, in that order; every other file after them in its usual
    order, and each file's tests in theirs."""
    rank = {name: i for i, name in enumerate(SLOW_FILES)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


@pytest.fixture
def shared() -> Path:
    """The project's ../shared folder; skips the test when it is absent."""
    if not SHARED.is_dir():
        pytest.skip("../shared is not present beside the repository")
    return SHARED


@pytest.fixture
def db(tmp_path: Path) -> Path:
    """Path of a fresh (not yet created) database file."""
    return tmp_path / "test.duckdb"


@pytest.fixture
def make_qtm(tmp_path: Path):
    """Write a QTM file; returns its path."""

    def write(name: str, names=None, n_frames: int = 50, seed: int = 0, **kw) -> Path:
        names = names or ["m1", "m2", "m3"]
        path = tmp_path / name
        path.write_text(qtm_text(names, random_track(n_frames, len(names), seed), **kw), newline="")
        return path

    return write


@pytest.fixture(scope="module")
def ingested(tmp_path_factory) -> Path:
    """Five synthetic trials (one per gait, 0.5 Hz, 4 cycles) ingested into a database."""
    from suds_exp.ingest import ingest_paths
    from suds_exp.store import Store
    from suds_exp.testing.synthetic_captures import write_dataset

    folder = tmp_path_factory.mktemp("prep")
    manifest = write_dataset(
        folder / "data", frequencies=(0.5,), n_cycles=4, n_jumps=3, n_dropouts=3
    )
    db = folder / "template.duckdb"
    ingest_paths(Store(db), [], manifest, progress=False)
    return db


@pytest.fixture
def dataset(ingested: Path, tmp_path: Path) -> Path:
    """A fresh copy of the ingested database for one test."""
    db = tmp_path / "db.duckdb"
    shutil.copyfile(ingested, db)
    return db
