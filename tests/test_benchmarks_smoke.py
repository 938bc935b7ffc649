"""The benchmarks package: every script runs as a module with ``--quick``.

The smoke run of each script (`test_quick_run`, slow) runs ``python -m benchmarks.<box>.<name>
--quick`` from the repository root in its own process, as a user would; the figures it
prints mean nothing, only that the script still runs against the library as it is now.
The structural checks beside it are fast.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"
SCRIPTS = sorted(
    f"benchmarks.{p.parent.name}.{p.stem}"
    for box in ("speed", "studies")
    for p in (BENCHMARKS / box).glob("*.py")
    if p.stem != "__init__"
)
#: Scripts that read ../shared (the reference data beside the repository).
NEEDS_SHARED = {"benchmarks.studies.discrepancy_hatton"}


def test_every_script_sits_in_a_box_and_takes_quick():
    loose = sorted(p.name for p in BENCHMARKS.glob("*.py") if not p.name.startswith("_"))
    assert not loose, f"scripts outside speed/ and studies/: {loose}"
    assert len(SCRIPTS) > 20
    for module in SCRIPTS:
        text = (ROOT / (module.replace(".", "/") + ".py")).read_text()
        # the harness's parsers declare --quick for the scripts that use them
        assert re.search(r'"--quick"|\b(script|comparison)_parser\(', text), (
            f"{module} has no --quick"
        )
        assert re.search(rf"python3? -m {re.escape(module)}\b", text), (
            f"{module}'s docstring does not say how to run it"
        )


def test_no_script_edits_the_import_path():
    for path in BENCHMARKS.rglob("*.py"):
        assert not re.search(r"sys\.path\.(insert|append)", path.read_text()), path


@pytest.mark.slow
@pytest.mark.parametrize("module", SCRIPTS)
def test_quick_run(module, request):
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    if module in NEEDS_SHARED:
        env["SUDS_SHARED"] = str(request.getfixturevalue("shared"))  # skips when absent
    res = subprocess.run(
        [sys.executable, "-m", module, "--quick"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert res.returncode == 0, f"{module} --quick: exit {res.returncode}\n{res.stderr[-3000:]}"
    assert res.stdout.strip(), f"{module} --quick printed nothing"
