"""The first simulation after an install says that the simulator compiles once, and for
about how long; a cached one says nothing."""

from __future__ import annotations

import os
import subprocess
import sys

from typer.testing import CliRunner

import suds_exp.sim.precompile as precompile
from cli import app

PROBE = "from suds_exp.sim.precompile import kernels_cached; print(kernels_cached())"


def test_an_empty_numba_cache_is_told_from_a_filled_one(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    out = subprocess.run(
        [sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "False"


def test_simulate_says_it_compiles_only_when_it_will(tmp_path, monkeypatch):
    args = ["simulate", "--gaits", "O", "--freqs", "1", "--repeats", "1", "--cycles", "2"]
    monkeypatch.setattr(precompile, "kernels_cached", lambda: False)
    cold = CliRunner().invoke(app, [*args, "--out", str(tmp_path / "a")])
    assert cold.exit_code == 0, cold.output
    assert "compiling the simulator once (numba): about 15 s" in cold.stderr
    monkeypatch.setattr(precompile, "kernels_cached", lambda: True)
    warm = CliRunner().invoke(app, [*args, "--out", str(tmp_path / "b")])
    assert warm.exit_code == 0 and "compiling" not in warm.stderr
    # --json (and --quiet) print no progress, nor this
    monkeypatch.setattr(precompile, "kernels_cached", lambda: False)
    quiet = CliRunner().invoke(app, [*args, "--out", str(tmp_path / "c"), "--json"])
    assert quiet.exit_code == 0 and "compiling" not in quiet.stderr
