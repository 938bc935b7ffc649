"""Shared fixtures and the suite's order.

Test modules import nothing from here or from each other: what they share is either a
public helper of `suds_exp.testing` (database snapshots, capture files, synthetic data)
or a fixture below, received as an argument. A fixture that hands back a function (`cli`,
`campaign_rows`, `start_campaign`, ...) is session-scoped, so fixtures of any scope can
use it too."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from suds_exp.testing.synthetic_captures import qtm_text, random_track

REPO = Path(__file__).resolve().parents[1]

#: ../shared beside the repository, or where SUDS_SHARED points (a git worktree elsewhere)
SHARED = Path(os.environ.get("SUDS_SHARED") or Path(__file__).resolve().parents[2] / "shared")

# The default run's slowest files (`pytest --durations`, docs/results/speed.md), slowest
# first. `make test` hands whole files to its 2 workers in collection order
# (`--dist loadfile`): starting these first keeps one of them from being the last thing a
# worker runs while the other waits.
SLOW_FILES = (
    "test_benchmarks_smoke.py",
    "test_discrepancy_workflow.py",
    "test_reliability.py",
    "test_gait_design.py",
    "test_campaign_kill.py",
    "test_plan.py",
    "test_experiment_stored.py",
    "test_gait_bodies.py",
    "test_docs.py",
    "test_cli_help.py",
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
    "test_models_momentum.py",
    "test_momentum_information.py",
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


@pytest.fixture(scope="session")
def slow_files() -> tuple[str, ...]:
    """The file names `SLOW_FILES` schedules first, slowest first."""
    return SLOW_FILES


# -- the command line -------------------------------------------------------------------
def _cli(*args):
    from typer.testing import CliRunner

    from cli import app

    return CliRunner().invoke(app, [str(a) for a in args])


@pytest.fixture(scope="session")
def cli():
    """``cli(*args)`` runs ``suds-exp ARGS`` through typer's CliRunner (arguments made
    strings) and returns its `Result`."""
    return _cli


@pytest.fixture(scope="session")
def sql():
    """``sql(db, query)``: the rows of ``query`` on database ``db`` as ``suds-exp sql
    --json`` prints them (a list of dicts); fails the test on a non-zero exit."""

    def rows(db, query):
        out = _cli("sql", query, "--db", db, "--json")
        assert out.exit_code == 0, out.output
        return json.loads(out.stdout)

    return rows


@pytest.fixture(scope="session")
def simulated_db():
    """``simulated_db(work, gaits, freqs="1/2", repeats=2, cycles=6)``: the path of a database
    in folder ``work`` made as a user would (``suds-exp simulate --ingest``, then
    ``preprocess``: version v1) of ``gaits`` (e.g. "O,D+") at ``freqs`` Hz, ``repeats``
    trials of ``cycles`` cycles each."""

    def make(work: Path, gaits: str, freqs: str = "1/2", repeats: int = 2, cycles: int = 6):
        db = work / "simulated.duckdb"
        simulate = ["simulate", "--out", work / "d", "--gaits", gaits, "--freqs", freqs,
                    "--repeats", repeats, "--cycles", cycles, "--ingest"]  # fmt: skip
        for args in (simulate, ["preprocess"]):
            out = _cli(*args, "--db", db, "-q")
            assert out.exit_code == 0, out.output
        return db

    return make


# -- campaigns --------------------------------------------------------------------------
@pytest.fixture(scope="session")
def campaign_rows():
    """``campaign_rows(store, campaign="c")``: the results rows of ``campaign``, timing
    columns dropped, in key order (to compare two runs row for row)."""
    from suds_exp.campaign import KEY_COLUMNS, TIMING_COLUMNS

    def rows(store, campaign: str = "c"):
        frame = store.query_df("SELECT * FROM results WHERE campaign = ? ORDER BY ALL", [campaign])
        return frame.drop(columns=list(TIMING_COLUMNS)).sort_values(
            list(KEY_COLUMNS), ignore_index=True
        )

    return rows


CHILD = """
import sys, json, pandas as pd
from suds_exp.campaign import CampaignOptions, run_campaign
from suds_exp.store import Store
samples = pd.read_parquet(sys.argv[1])
options = CampaignOptions(**json.loads(sys.argv[3]))
report = lambda n: print("batch", n, flush=True)
run_campaign(Store(sys.argv[2]), "c", options, samples=samples, progress=False,
             batch_rows=int(sys.argv[4]), flush_seconds=0.2, on_batch=report)
print("done", flush=True)
"""


@pytest.fixture(scope="session")
def start_campaign():
    """``start_campaign(samples_file, db, options, batch_rows)`` runs campaign "c" on the
    samples in ``samples_file`` (parquet) with `CampaignOptions(**options)` in a child
    process that prints a line per stored batch (see `wait_batches`); returns the Popen."""

    def start(samples_file: Path, db: Path, options: dict, batch_rows: int):
        return subprocess.Popen(
            [
                sys.executable,
                "-c",
                CHILD,
                str(samples_file),
                str(db),
                json.dumps(options),
                str(batch_rows),
            ],
            cwd=REPO,
            stdout=subprocess.PIPE,
            text=True,
        )

    return start


@pytest.fixture(scope="session")
def wait_batches():
    """``wait_batches(child, n)`` blocks until the child of `start_campaign` has stored
    ``n`` more batches; fails the test if it ends first."""

    def wait(child: subprocess.Popen, n: int) -> None:
        for _ in range(n):
            line = child.stdout.readline()
            assert line.startswith("batch"), f"child ended early: {line!r}"

    return wait


# -- hidden effects and the discrepancy command -----------------------------------------
#: A sweep small enough for the default suite: 2 gaits x 2 frequencies x 3 repeats.
SMALL_SWEEP = dict(gaits=("S+", "D+"), frequencies_hz=(0.5, 1.0), repeats=3, cycles=(3, 4))


@pytest.fixture(scope="session")
def small_sweep() -> dict:
    """Keyword arguments of a simulated sweep small enough for the default suite
    (2 gaits x 2 frequencies x 3 repeats of 3-4 cycles)."""
    return dict(SMALL_SWEEP)


@pytest.fixture(scope="session")
def inertia_store():
    """``inertia_store(work, tau_s, seed)``: a database (its path) of the small sweep
    simulated into folder ``work`` with body inertia ``tau_s`` (s), an effect the nominal
    model lacks."""
    from suds_exp.sim.config import SimConfig
    from suds_exp.sim.dataset import SimDesign
    from suds_exp.workflows.hidden_effects import simulate_measured

    def make(work: Path, tau_s: float, seed: int) -> Path:
        truth = SimConfig()
        truth.effects.body_inertia.tau_s = tau_s
        simulate_measured(work, truth, SimDesign(seed=seed, **SMALL_SWEEP))
        return work / "suds.duckdb"

    return make


@pytest.fixture(scope="session")
def discrepancy_json():
    """``discrepancy_json(db, out, *args)`` runs ``suds-exp discrepancy --db db --out out
    *args --json`` through the CLI and returns (the printed document, ``out``); fails the
    test on a non-zero exit."""

    def run(db: Path, out: Path, *args: str) -> tuple[dict, Path]:
        res = _cli("discrepancy", "--db", db, "--out", out, *args, "--json")
        assert res.exit_code == 0, res.output
        return json.loads(res.stdout), out

    return run
