"""`make test` starts the slowest test files first (tests/conftest.py): every file named
there must exist, or a renamed file silently falls back to the end of the run."""

from __future__ import annotations

from pathlib import Path

from tests.helpers import SLOW_FILES


def test_every_slow_file_named_for_the_schedule_exists():
    here = Path(__file__).parent
    assert len(set(SLOW_FILES)) == len(SLOW_FILES)
    missing = [name for name in SLOW_FILES if not (here / name).is_file()]
    assert not missing, f"tests/conftest.py SLOW_FILES names no such file: {missing}"


def test_the_slow_files_are_collected_first(request):
    files = []
    for item in request.session.items:
        if item.path.name not in files:
            files.append(item.path.name)
    present = [name for name in SLOW_FILES if name in files]
    assert files[: len(present)] == present
