"""Shared fixtures: temporary databases, capture-file builders, database dumps."""

from __future__ import annotations

import json
import os
from pathlib import Path

import duckdb
import numpy as np
import pandas as pd
import pytest

#: ../shared beside the repository, or where SUDS_SHARED points (a git worktree elsewhere)
SHARED = Path(os.environ.get("SUDS_SHARED") or Path(__file__).resolve().parents[2] / "shared")


# The default run's slowest files (`pytest --durations`, docs/results/speed.md session 16),
# slowest first. `make test` hands whole files to its 2 workers in collection order
# (`--dist loadfile`): starting these first keeps one of them from being the last thing a
# worker runs while the other waits.
SLOW_FILES = (
    "test_discrepancy_workflow.py",
    "test_reliability.py",
    "test_gait_design.py",
    "test_campaign_kill.py",
    "test_plan.py",
    "test_experiment_stored.py",
    "test_gait_bodies.py",
    "test_docs.py",
    "test_ingest_cli.py",
    "test_experiment_design.py",
    "test_preprocess_versions.py",
    "test_campaign_parallel.py",
    "test_analysis_report.py",
    "test_preprocess_reduction.py",
    "test_campaign_runner.py",
    "test_campaign_resume.py",
    "test_body_segments.py",
    "test_models_sklearn.py",
    "test_stream.py",
)


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


def qtm_text(names: list[str], xyz: np.ndarray, rate: float = 100.0, crlf: bool = True) -> str:
    """A QTM 3D TSV export of ``xyz`` (n_frames, n_markers, 3) mm; NaN -> 0 0 0."""
    n_frames = xyz.shape[0]
    head = [
        f"NO_OF_FRAMES\t{n_frames}",
        "NO_OF_CAMERAS\t4",
        f"NO_OF_MARKERS\t{len(names)}",
        f"FREQUENCY\t{rate:g}",
        "NO_OF_ANALOG\t0",
        "ANALOG_FREQUENCY\t0",
        "DESCRIPTION\t--",
        "TIME_STAMP\t2026-01-01, 10:00:00.000\t0.0",
        "DATA_INCLUDED\t3D",
        "MARKER_NAMES\t" + "\t".join(names),
        "TRAJECTORY_TYPES\t" + "\t".join(["Mixed"] * len(names)),
        "Frame\tTime\t" + "\t".join(f"{n} {a}" for n in names for a in "XYZ") + "\t",
    ]
    values = np.nan_to_num(xyz, nan=0.0).reshape(n_frames, -1)
    rows = [
        f"{i + 1}\t{i / rate:.5f}\t" + "\t".join(f"{v:.3f}" for v in row) + "\t"
        for i, row in enumerate(values)
    ]
    return ("\r\n" if crlf else "\n").join(head + rows) + ("\r\n" if crlf else "\n")


def random_track(n_frames: int, n_markers: int, seed: int = 0) -> np.ndarray:
    """Smooth random marker tracks, shape (n_frames, n_markers, 3), mm."""
    rng = np.random.default_rng(seed)
    base = rng.uniform(-300, 300, size=(1, n_markers, 3))
    drift = np.cumsum(rng.normal(0, 0.5, size=(n_frames, n_markers, 3)), axis=0)
    return np.round(base + drift, 3)


@pytest.fixture
def make_qtm(tmp_path: Path):
    """Write a QTM file; returns its path."""

    def write(name: str, names=None, n_frames: int = 50, seed: int = 0, **kw) -> Path:
        names = names or ["m1", "m2", "m3"]
        path = tmp_path / name
        path.write_text(qtm_text(names, random_track(n_frames, len(names), seed), **kw), newline="")
        return path

    return write


def dump_db(path: Path) -> dict[str, pd.DataFrame]:
    """Every table's rows, ordered, keyed by table name (for before/after comparisons)."""
    if not path.exists():
        return {}
    con = duckdb.connect(str(path), read_only=True)
    try:
        names = [
            r[0]
            for r in con.execute(
                "SELECT table_name FROM information_schema.tables "
                "WHERE table_type = 'BASE TABLE' ORDER BY 1"
            ).fetchall()
        ]
        return {n: con.execute(f'SELECT * FROM "{n}" ORDER BY ALL').df() for n in names}
    finally:
        con.close()


def assert_same_db(before: dict[str, pd.DataFrame], after: dict[str, pd.DataFrame]) -> None:
    assert sorted(before) == sorted(after)
    for name in before:
        pd.testing.assert_frame_equal(before[name], after[name], check_dtype=False)


# A sweep small enough for the default suite: 2 gaits x 2 frequencies x 3 repeats.
SMALL_SWEEP = dict(gaits=("S+", "D+"), frequencies_hz=(0.5, 1.0), repeats=3, cycles=(3, 4))


def inertia_store(work: Path, tau_s: float, seed: int) -> Path:
    """Database of `SMALL_SWEEP` simulated with body inertia ``tau_s`` (s), an effect the
    nominal model lacks; returns its path."""
    from suds_exp.sim.config import SimConfig
    from suds_exp.testing.hidden_effects import simulate_measured

    truth = SimConfig()
    truth.effects.body_inertia.tau_s = tau_s
    simulate_measured(work, truth, seed=seed, **SMALL_SWEEP)
    return work / "suds.duckdb"


def discrepancy_json(db: Path, out: Path, *args: str) -> tuple[dict, Path]:
    """``suds-exp discrepancy --db db --out out *args --json`` through the CLI: the
    printed document and the report folder; fails the test on a non-zero exit."""
    from typer.testing import CliRunner

    from cli import app

    argv = ["discrepancy", "--db", str(db), "--out", str(out), *args, "--json"]
    res = CliRunner().invoke(app, argv)
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout), out
