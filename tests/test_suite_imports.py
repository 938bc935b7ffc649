"""Each test module stands alone: it imports no other test module, nothing of
`conftest.py` (its fixtures arrive as arguments) and nothing of `benchmarks/` (a test runs
a benchmark as a process). What tests share is public (`suds_exp.testing`) or a fixture."""

from __future__ import annotations

import ast
from pathlib import Path

HERE = Path(__file__).parent


def imported_modules(path: Path) -> set[str]:
    """Every module ``path`` imports (``from tests import x`` counts as ``tests.x``)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
    return found


def test_no_test_module_imports_another_conftest_or_the_benchmarks():
    bad = {}
    for path in sorted(HERE.glob("*.py")):
        if path.name == "conftest.py":
            continue
        wrong = sorted(
            m
            for m in imported_modules(path)
            if m.split(".")[0] in ("conftest", "benchmarks", "tests")
        )
        if wrong:
            bad[path.name] = wrong
    assert not bad, bad
