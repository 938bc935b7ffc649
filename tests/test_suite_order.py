"""`make test` starts the slowest test files first (tests/conftest.py): every file named
there must exist, or a renamed file silently falls back to the end of the run."""

from __future__ import annotations

from pathlib import Path


def test_every_slow_file_named_for_the_schedule_exists(slow_files):
    here = Path(__file__).parent
    assert len(set(slow_files)) == len(slow_files)
    missing = [name for name in slow_files if not (here / name).is_file()]
    assert not missing, f"tests/conftest.py SLOW_FILES names no such file: {missing}"


def test_the_slow_files_are_collected_first(request, slow_files):
    files = []
    for item in request.session.items:
        if item.path.name not in files:
            files.append(item.path.name)
    present = [name for name in slow_files if name in files]
    assert files[: len(present)] == present
