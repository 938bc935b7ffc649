"""Keypoint files of markerless trackers ingest through `movement`: files written by
movement's own writers (DeepLabCut CSV and H5, SLEAP analysis, Lightning Pose) and an
Anipose CSV give the right frames, keypoint names and missing counts (low confidence
counted as missing); 2-D tracks have no Z; bad input is one line, database unchanged."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.preprocess import load_samples
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db

load_poses = pytest.importorskip("movement.io.load_poses")
save_poses = pytest.importorskip("movement.io.save_poses")

runner = CliRunner()
KEYPOINTS = ["snout", "neck", "mid", "hip", "tail"]
N_FRAMES = 60


def cli(*args):
    return runner.invoke(app, [str(a) for a in args])


def _dataset(seed=0, n_low=7, n_lost=4, confidence=True, individuals=("mouse",)):
    """A pose dataset in pixels with ``n_low`` points of confidence 0.2 and ``n_lost``
    points the tracker did not place (NaN), in distinct places."""
    rng = np.random.default_rng(seed)
    n_ind = len(individuals)
    position = rng.uniform(50, 400, (N_FRAMES, 2, len(KEYPOINTS), n_ind))
    conf = rng.uniform(0.7, 1.0, (N_FRAMES, len(KEYPOINTS), n_ind))
    cells = rng.choice(N_FRAMES * len(KEYPOINTS), n_low + n_lost, replace=False)
    frames, kps = np.unravel_index(cells, (N_FRAMES, len(KEYPOINTS)))
    conf[frames[:n_low], kps[:n_low], 0] = 0.2
    position[frames[n_low:], :, kps[n_low:], 0] = np.nan
    conf[frames[n_low:], kps[n_low:], 0] = np.nan
    return load_poses.from_numpy(
        position,
        conf if confidence else None,
        individual_names=list(individuals),
        keypoint_names=KEYPOINTS,
        source_software="DeepLabCut",
    )


def _ingest(path, db, *args):
    out = cli("ingest", path, "--db", db, "--json", *args)
    assert out.exit_code == 0, out.output
    return json.loads(out.stdout)[0]["trial_id"]


def _trial(db, trial_id):
    store = Store(db)
    trial = store.query_df("SELECT * FROM trials WHERE id = ?", [trial_id]).iloc[0]
    counts = store.query_df(
        "SELECT count(*) AS rows, sum(missing::INT) AS missing, count(z) AS with_z, "
        "max(x) AS max_x FROM markers WHERE trial_id = ?",
        [trial_id],
    ).iloc[0]
    return trial, counts


def _written(tmp_path: Path, stem: str, suffix: str) -> Path:
    # movement's DeepLabCut writer names a single individual's file <stem>_<individual>
    (found,) = tmp_path.glob(f"{stem}*{suffix}")
    return found


@pytest.mark.parametrize("suffix", [".csv", ".h5"])
def test_deeplabcut_file_written_by_movement(tmp_path, suffix):
    save_poses.to_dlc_file(_dataset(), tmp_path / f"dlc{suffix}")
    path = _written(tmp_path, "dlc", suffix)
    db = tmp_path / "p.duckdb"
    tid = _ingest(path, db, "--fps", 30, "--mm-per-px", 0.1)
    trial, counts = _trial(db, tid)
    assert trial.format == "deeplabcut"
    assert trial.n_frames == N_FRAMES and list(trial.marker_names) == KEYPOINTS
    assert trial.sample_rate_hz == pytest.approx(30.0)
    assert counts["rows"] == N_FRAMES * len(KEYPOINTS)
    assert counts["missing"] == 7 + 4  # below the default confidence 0.6, and lost
    assert counts["with_z"] == 0  # 2-D: no Z stored
    assert counts["max_x"] <= 40.0  # 400 px at 0.1 mm/px


def test_sleap_analysis_file_written_by_movement(tmp_path):
    path = tmp_path / "sleap.analysis.h5"
    save_poses.to_sleap_analysis_file(_dataset(seed=1, n_low=5, n_lost=3), path)
    db = tmp_path / "p.duckdb"
    tid = _ingest(path, db, "--fps", 50, "--mm-per-px", 0.05)
    trial, counts = _trial(db, tid)
    assert trial.format == "sleap"
    assert trial.n_frames == N_FRAMES and list(trial.marker_names) == KEYPOINTS
    assert counts["missing"] == 5 + 3 and counts["with_z"] == 0


def test_confidence_threshold_is_a_parameter(tmp_path):
    save_poses.to_dlc_file(_dataset(), tmp_path / "dlc.csv")
    path = _written(tmp_path, "dlc", ".csv")
    db = tmp_path / "p.duckdb"
    # 0.1 keeps the points of confidence 0.2: only the lost ones are missing
    tid = _ingest(path, db, "--fps", 30, "--mm-per-px", 0.1, "--confidence-threshold", 0.1)
    assert _trial(db, tid)[1]["missing"] == 4


def test_lightning_pose_and_several_individuals(tmp_path):
    save_poses.to_lp_file(_dataset(seed=2), tmp_path / "lp.csv")
    path = _written(tmp_path, "lp", ".csv")
    db = tmp_path / "p.duckdb"
    tid = _ingest(path, db, "--software", "lightning-pose", "--fps", 25, "--mm-per-px", 1)
    trial, counts = _trial(db, tid)
    assert trial.format == "lightning-pose" and list(trial.marker_names) == KEYPOINTS
    assert counts["missing"] == 11
    two = tmp_path / "pair.h5"
    save_poses.to_sleap_analysis_file(_dataset(seed=3, individuals=("a", "b")), two)
    tid = _ingest(two, db, "--fps", 25, "--mm-per-px", 1)
    names = list(_trial(db, tid)[0].marker_names)
    assert names == [f"{i}/{k}" for i in ("a", "b") for k in KEYPOINTS]


def test_anipose_csv_is_three_dimensional(tmp_path):
    rng = np.random.default_rng(4)
    cols, data = ["fnum"], [np.arange(N_FRAMES)]
    for kp in KEYPOINTS[:3]:
        for suffix in ("x", "y", "z"):
            cols.append(f"{kp}_{suffix}")
            data.append(rng.uniform(-50, 50, N_FRAMES))
        cols += [f"{kp}_error", f"{kp}_score", f"{kp}_ncams"]
        data += [rng.uniform(0, 2, N_FRAMES), rng.uniform(0.7, 1, N_FRAMES), np.full(N_FRAMES, 2)]
    data[5][:6] = 0.1  # six low scores of the first keypoint
    for extra in ["center_0", "center_1", "center_2"] + [f"M_{i}{j}" for i in "012" for j in "012"]:
        cols.append(extra)
        data.append(np.zeros(N_FRAMES))
    path = tmp_path / "pose-3d.csv"
    lines = [",".join(cols)] + [",".join(f"{c[i]:g}" for c in data) for i in range(N_FRAMES)]
    path.write_text("\n".join(lines) + "\n")
    db = tmp_path / "p.duckdb"
    tid = _ingest(path, db, "--fps", 100)
    trial, counts = _trial(db, tid)
    # movement's Anipose loader orders the keypoints by name
    assert trial.format == "anipose" and list(trial.marker_names) == sorted(KEYPOINTS[:3])
    assert counts["missing"] == 6 and counts["with_z"] == N_FRAMES * 3 - 6


BAD = {
    "no confidence where one was asked for": (
        dict(confidence=False),
        ["--fps", 30, "--mm-per-px", 0.1, "--confidence-threshold", 0.5],
        "has no confidence values, so --confidence-threshold=0.5 cannot be applied",
    ),
    "no frame rate": (
        {},
        ["--mm-per-px", 0.1],
        "the file holds no frame rate; give --fps",
    ),
    "pixels with no scale": ({}, ["--fps", 30], "2-D keypoints are in pixels; give --mm-per-px"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_keypoint_input_is_one_line_and_leaves_the_database(tmp_path, case):
    kwargs, args, expected = BAD[case]
    db = tmp_path / "p.duckdb"
    assert cli("init", "--db", db).exit_code == 0
    save_poses.to_dlc_file(_dataset(**kwargs), tmp_path / "dlc.csv")
    path = _written(tmp_path, "dlc", ".csv")
    before = dump_db(db)
    out = cli("ingest", path, "--db", db, *args)
    assert out.exit_code == 2
    message = out.stderr.strip()
    assert len(message.splitlines()) == 1, message
    assert str(path) in message and expected in message, message
    assert_same_db(before, dump_db(db))


def test_two_dimensional_keypoints_along_a_body_preprocess_as_a_chain(tmp_path):
    # a travelling wave along 10 keypoints, in pixels, as a tracker would write it
    n, rate, f_hz, px = 10, 50.0, 1.0, 0.1
    t = np.arange(300) / rate
    s = np.linspace(0, 1, 200)
    theta = 0.7 * np.sin(2 * np.pi * (s[None] - f_hz * t[:, None]))
    back = np.cumsum(np.stack([np.cos(theta), np.sin(theta)], axis=2), axis=1) * (800 / 200)
    xy = np.column_stack([300 * t, np.zeros_like(t)])[:, None] - (back - back[:, :1])
    pick = np.linspace(0, 199, n).round().astype(int)
    position = (xy[:, pick] / px).transpose(0, 2, 1)[..., None]
    names = [f"k{i}" for i in range(n)]
    ds = load_poses.from_numpy(position, np.ones((len(t), n, 1)), ["eel"], names)
    save_poses.to_sleap_analysis_file(ds, tmp_path / "eel.h5")
    body = tmp_path / "eel.toml"
    body.write_text(f'name = "eel"\n[chain]\nmarkers = {json.dumps(names)}\nmodes = 4\n')
    db = tmp_path / "p.duckdb"
    _ingest(tmp_path / "eel.h5", db, "--fps", rate, "--mm-per-px", px)
    out = cli("preprocess", "--body", body, "--param", "jump_mm=40", "--db", db, "--json")
    assert out.exit_code == 0, out.output
    samples = load_samples(Store(db), json.loads(out.stdout)["version_id"]).iloc[40:-40]
    rate_hz = abs(np.polyfit(samples.t, samples.phase, 1)[0]) / (2 * np.pi)
    assert rate_hz == pytest.approx(f_hz, rel=0.03)
    assert samples.vx.mean() == pytest.approx(300.0, rel=0.15)
