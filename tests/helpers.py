"""Helpers shared by the test modules: capture-file writers, database dumps, synthetic
samples and results, a campaign in a child process, small CLI shortcuts.

Fixtures live in `conftest.py`; plain functions and constants that several test modules
call live here, so no test module imports another (or `conftest.py`).
"""

from __future__ import annotations

import io
import json
import subprocess
import sys
import warnings
from pathlib import Path

import duckdb
import numpy as np
import pandas as pd

from suds_exp.campaign import KEY_COLUMNS, TIMING_COLUMNS
from suds_exp.robot import GAIT_K
from suds_exp.store import Store
from suds_exp.testing.synthetic_captures import qtm_text, random_track  # noqa: F401 (the tests' name)

REPO = Path(__file__).resolve().parents[1]

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
    """Fail unless two `dump_db` snapshots hold the same tables and rows."""
    assert sorted(before) == sorted(after)
    for name in before:
        pd.testing.assert_frame_equal(before[name], after[name], check_dtype=False)


def cli(*args):
    """Run ``suds-exp ARGS`` through typer's CliRunner (arguments made strings)."""
    from typer.testing import CliRunner

    from cli import app

    return CliRunner().invoke(app, [str(a) for a in args])


def sql(db, query):
    """The rows of ``query`` on database ``db`` as ``suds-exp sql --json`` prints them."""
    out = cli("sql", query, "--db", db, "--json")
    assert out.exit_code == 0, out.output
    return json.loads(out.stdout)


# -- capture files ----------------------------------------------------------------------
def write_c3d(path, names, xyz, rate=100.0, units="mm  ", scale=1.0):
    """A C3D file of ``xyz`` (n_frames, n_markers, 3), NaN as an invalid point."""
    import c3d

    writer = c3d.Writer(point_rate=rate, point_units=units)
    writer.set_point_labels(names)
    frames = []
    for frame in xyz:
        points = np.zeros((len(names), 5), np.float32)
        points[:, :3] = np.nan_to_num(frame / scale)
        points[:, 3] = np.where(np.isnan(frame).any(axis=1), -1.0, 0.0)
        frames.append((points, np.zeros((0, 0), np.float32)))
    writer.add_frames(frames)
    buffer = io.BytesIO()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        writer.write(buffer)
    path.write_bytes(buffer.getvalue())
    return path


def _cells(frame, scale=1.0):
    return ["" if np.isnan(v) else f"{v / scale:.6f}" for v in frame.reshape(-1)]


def write_trc(path, names, xyz, rate=100.0, units="mm", scale=1.0, first=1):
    """A TRC file laid out as OpenSim documents it (a blank line before the frames)."""
    n = len(names)
    head = [
        f"PathFileType\t4\t(X/Y/Z)\t{path.name}",
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
        "OrigDataStartFrame\tOrigNumFrames",
        f"{rate:g}\t{rate:g}\t{len(xyz)}\t{n}\t{units}\t{rate:g}\t{first}\t{len(xyz)}",
        "Frame#\tTime\t" + "\t\t\t".join(names),
        "\t\t" + "\t".join(f"{a}{i}" for i in range(1, n + 1) for a in "XYZ"),
        "",
    ]
    rows = [
        "\t".join([str(first + i), f"{i / rate:.5f}"] + _cells(frame, scale))
        for i, frame in enumerate(xyz)
    ]
    path.write_text("\n".join(head + rows) + "\n")
    return path


def write_vicon(path, names, xyz, rate=100.0, units="mm", scale=1.0, first=5):
    """A Nexus CSV: a Devices block, then Trajectories with subject-prefixed names."""
    n = len(names)
    devices = ["Devices", f"{rate * 10:g}", ",,Plate", "Frame,Sub Frame,Fx", ",,N", "5,0,1.5", ""]
    head = [
        "Trajectories",
        f"{rate:g}",
        ",," + ",".join(f"Robot:{m},," for m in names),
        "Frame,Sub Frame," + ",".join(["X,Y,Z"] * n),
        ",," + ",".join([units] * 3 * n),
    ]
    rows = [",".join([str(first + i), "0"] + _cells(f, scale)) for i, f in enumerate(xyz)]
    path.write_text("\r\n".join(devices + head + rows) + "\r\n\r\n")
    return path


def write_motive(path, names, xyz, rate=100.0):
    """A Motive 1.23 CSV in metres with a rigid body's columns before the markers."""
    n = len(names)
    head = [
        f"Format Version,1.23,Take Name,t,Capture Frame Rate,{rate:f},Export Frame Rate,"
        f"{rate:f},Total Exported Frames,{len(xyz)},Rotation Type,Quaternion,"
        "Length Units,Meters,Coordinate Space,Global",
        "",
        ",Type," + ",".join(["Rigid Body"] * 7 + ["Marker"] * 3 * n),
        ",Name," + ",".join(["RB"] * 7 + [f"Sub:{m}" for m in names for _ in "XYZ"]),
        ",ID," + ",".join(["1"] * 7 + [f'"{j}"' for j in range(n) for _ in "XYZ"]),
        ",," + ",".join(["Rotation"] * 4 + ["Position"] * (3 + 3 * n)),
        "Frame,Time (Seconds)," + ",".join(["X,Y,Z,W", "X,Y,Z"] + ["X,Y,Z"] * n),
    ]
    rows = [
        ",".join([str(i), f"{i / rate:.6f}"] + ["0", "0", "0", "1", "1", "2", "3"])
        + ","
        + ",".join(_cells(f, 1000.0))
        for i, f in enumerate(xyz)
    ]
    path.write_text("\n".join(head + rows) + "\n")
    return path


# -- samples, campaigns and discrepancy runs --------------------------------------------
def synthetic_samples(
    conditions=(("O", 0.5), ("O", 1.0), ("D+", 0.5), ("D+", 1.0)),
    trials_per_condition: int = 4,
    cycles=(8, 14),
    rate_hz: float = 20.0,
    seed: int = 0,
) -> pd.DataFrame:
    """A samples frame like `load_samples` returns: several trials per condition.

    r_a follows the contract gaits with a per-trial amplitude and phase offset; r_p lags
    r_a; v_b is a quadratic map of (r_a, dr_a/dt) plus noise; captured at ``rate_hz``.
    """
    rng = np.random.default_rng(seed)
    frames, tid = [], 1
    for gait, f in conditions:
        k = GAIT_K[gait]
        s = 0.0 if np.isinf(k) else 1.0 / k
        for _ in range(trials_per_condition):
            n_cyc = rng.uniform(*cycles)
            t = np.arange(int(n_cyc * rate_hz / f)) / rate_hz
            th0 = rng.uniform(0, 2 * np.pi)
            th = 2 * np.pi * f * t + th0
            w = 2 * np.pi * f
            amp = 1 + 0.1 * rng.standard_normal()
            ra = amp * np.stack(
                [np.cos(th) + s * np.cos(3 * th), np.sin(th) - s * np.sin(3 * th)], 1
            )
            dra = (
                amp
                * w
                * np.stack(
                    [-np.sin(th) - 3 * s * np.sin(3 * th), np.cos(th) - 3 * s * np.cos(3 * th)], 1
                )
            )
            rp = 0.5 * np.stack([np.cos(th - 0.4), np.sin(th - 0.4)], 1)
            drp = 0.5 * w * np.stack([-np.sin(th - 0.4), np.cos(th - 0.4)], 1)
            vx = 12 * (ra[:, 0] * dra[:, 1] - ra[:, 1] * dra[:, 0]) + 3 * rp[:, 0] * dra[:, 0]
            vy = 5 * dra[:, 0] - 2 * dra[:, 1]
            wz = 0.3 * dra[:, 0] * ra[:, 1]
            n = len(t)
            phase = th - th0 + th0 % (2 * np.pi)
            frames.append(
                pd.DataFrame(
                    {
                        "trial_id": tid,
                        "frame": np.arange(n),
                        "t": t,
                        "phase": phase,
                        "cycle": np.floor(phase / (2 * np.pi)).astype(int),
                        "ra_1": ra[:, 0],
                        "ra_2": ra[:, 1],
                        "dra_1": dra[:, 0],
                        "dra_2": dra[:, 1],
                        "rp_1": rp[:, 0],
                        "rp_2": rp[:, 1],
                        "drp_1": drp[:, 0],
                        "drp_2": drp[:, 1],
                        "vx": vx + rng.normal(0, 1.0, n),
                        "vy": vy + rng.normal(0, 1.0, n),
                        "wz": wz + rng.normal(0, 0.02, n),
                        "gait": gait,
                        "frequency_hz": f,
                    }
                )
            )
            tid += 1
    return pd.concat(frames, ignore_index=True)


def campaign_rows(store: Store, campaign: str = "c") -> pd.DataFrame:
    """The results rows of ``campaign``, timing columns dropped, in key order (for
    comparing runs)."""
    frame = store.query_df("SELECT * FROM results WHERE campaign = ? ORDER BY ALL", [campaign])
    return frame.drop(columns=list(TIMING_COLUMNS)).sort_values(
        list(KEY_COLUMNS), ignore_index=True
    )


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


def start_campaign(
    samples_file: Path, db: Path, options: dict, batch_rows: int
) -> subprocess.Popen:
    """Run campaign "c" on the samples in ``samples_file`` (parquet) in a child process that
    prints a line per stored batch (`wait_batches`)."""
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


def wait_batches(child: subprocess.Popen, n: int) -> None:
    """Block until the child of `start_campaign` has stored ``n`` more batches."""
    for _ in range(n):
        line = child.stdout.readline()
        assert line.startswith("batch"), f"child ended early: {line!r}"


# A sweep small enough for the default suite: 2 gaits x 2 frequencies x 3 repeats.
SMALL_SWEEP = dict(gaits=("S+", "D+"), frequencies_hz=(0.5, 1.0), repeats=3, cycles=(3, 4))


def inertia_store(work: Path, tau_s: float, seed: int) -> Path:
    """Database of `SMALL_SWEEP` simulated with body inertia ``tau_s`` (s), an effect the
    nominal model lacks; returns its path."""
    from suds_exp.sim.config import SimConfig
    from suds_exp.workflows.hidden_effects import simulate_measured

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
