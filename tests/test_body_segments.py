"""Any body of rigid segments preprocesses like the swimmer: the swimmer written as a
description gives the built-in pipeline's samples exactly; bodies of 2 to 6 links moved by
the kinematic generator (known joint angles and body path, noisy gappy markers) are
recovered; bad descriptions are one-line errors that leave the database as it was."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.body import SegmentModel, load_body, preprocess_body
from suds_exp.ingest import ingest_paths
from suds_exp.ingest.readers import read_capture
from suds_exp.preprocess import load_samples, preprocess
from suds_exp.preprocess.clean import clean_tracks
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db
from suds_exp.testing.kinematic_body import serial_body, write_body_trial
from suds_exp.testing.synthetic_captures import write_dataset

runner = CliRunner()

#: Tolerances a body description must meet against the simulator's joint angles.
ANGLE_RMS_RAD = 0.01
VELOCITY_RMS_FRACTION = 0.05


def test_swimmer_as_a_generic_description_gives_the_builtin_samples_exactly(tmp_path):
    manifest = write_dataset(tmp_path / "data", gaits=("O", "S+"), frequencies=(0.5,), n_cycles=3)
    store = Store(tmp_path / "s.duckdb")
    ingest_paths(store, [], manifest, progress=False)
    # the built-in pipeline with its segment-frame settings, and the same numbers from
    # the swimmer's description through the generic segment model
    settings = {"tail_fit": "rigid", "body_fit": "segments"}
    builtin = preprocess(store, params=settings, progress=False)
    generic = preprocess(
        store, params=settings, progress=False, body=SegmentModel(load_body("swimmer"))
    )
    assert generic.version_id != builtin.version_id  # the description is in its parameters
    left = load_samples(store, builtin.version_id)
    right = load_samples(store, generic.version_id)
    assert len(left) == 1200
    assert left.equals(right)


def _recover(tmp_path, n_segments, passive, seed=0):
    planar = serial_body(n_segments, passive, fin=not passive)
    path, truth = write_body_trial(planar, tmp_path / f"body{n_segments}.csv", seed=seed)
    store = Store(tmp_path / f"b{n_segments}.duckdb")
    ingest_paths(store, [path], None, progress=False)
    result = preprocess_body(store, planar.body, progress=False)
    samples = load_samples(store, result.version_id)
    return planar, path, truth.iloc[samples.frame.to_numpy() - 1], samples, result


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def _check_recovery(planar, truth, samples):
    actuated = [j.name for j in planar.body.joints if j.kind == "actuated"]
    for i, name in enumerate(actuated):
        error = samples[f"ra_{i + 1}"].to_numpy() - truth[name].to_numpy()
        assert _rms(error) < ANGLE_RMS_RAD, (name, _rms(error))
    speed = _rms(np.hypot(truth.vx, truth.vy))
    error = np.hypot(samples.vx.to_numpy() - truth.vx, samples.vy.to_numpy() - truth.vy)
    assert _rms(error) < VELOCITY_RMS_FRACTION * speed, _rms(error) / speed


def test_four_links_with_a_passive_joint_are_recovered_from_noisy_gappy_markers(tmp_path):
    planar, path, truth, samples, result = _recover(tmp_path, 4, passive=(2,))
    assert [j.kind for j in planar.body.joints] == ["actuated", "passive", "actuated"]
    assert result.params["k"] == 2  # the passive joint: the far link's origin, x and y
    _check_recovery(planar, truth, samples)
    # the passive joint's angle, from the same noisy markers through the public model
    model = SegmentModel(planar.body)
    capture, _ = read_capture(path)
    assert np.isnan(capture.xyz).any()  # the generator's gaps
    clean = clean_tracks(capture.xyz, 9.0, 25, capture.marker_names)
    measured = model.measure(clean.xyz, {})
    angles = model.joint_angles(measured, model.fit_joints([measured]))
    for name in ("q1", "q2", "q3"):
        error = angles[name] - truth[name].to_numpy()
        assert _rms(error) < ANGLE_RMS_RAD, (name, _rms(error))


@pytest.mark.parametrize(
    ("n_segments", "passive"), [(2, ()), (3, (1,)), (5, (3,)), (6, (2, 4)), (6, ())]
)
def test_bodies_of_two_to_six_links_are_recovered(tmp_path, n_segments, passive):
    planar, _, truth, samples, _ = _recover(tmp_path, n_segments, passive, seed=n_segments)
    _check_recovery(planar, truth, samples)
    n_actuated = sum(j.kind == "actuated" for j in planar.body.joints)
    assert [c for c in samples.columns if c.startswith("ra_")] == [
        f"ra_{i}" for i in range(1, n_actuated + 1)
    ]


def test_segment_body_through_the_cli_resumes(tmp_path):
    planar = serial_body(4, (2,))
    path, _ = write_body_trial(planar, tmp_path / "four.csv")
    toml = tmp_path / "four.toml"
    toml.write_text(planar.toml)
    db = tmp_path / "c.duckdb"
    assert runner.invoke(app, ["ingest", str(path), "--db", str(db)]).exit_code == 0
    args = ["preprocess", "--body", str(toml), "--db", str(db), "--json"]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    again = runner.invoke(app, args)
    assert json.loads(again.stdout)["skipped"] == [1]
    assert json.loads(again.stdout)["version_id"] == json.loads(first.stdout)["version_id"]


BAD_BODIES = {
    "a segment with one marker": (
        lambda t: t.replace('s2_a = "top", s2_b = "top", s2_c = "top"', 's2_a = "top"'),
        "segments.s2: 1 marker(s); a rigid segment needs at least 2",
    ),
    "a joint tree with a cycle": (
        lambda t: t + '[[joints]]\nname = "loop"\nparent = "s4"\nchild = "s1"\nkind = "passive"\n',
        "joints[3] 'loop': joins 's4' and 's1', which are already connected (a cycle)",
    ),
    "a segment with two parents": (
        lambda t: t.replace('parent = "s3"\nchild = "s4"', 'parent = "s4"\nchild = "s3"'),
        "joints[2] 'q3': 's3' is already the child of joint 'q2'",
    ),
    "a marker the trial lacks": (
        lambda t: t.replace("s3_c", "s3_zz"),
        "four.toml: marker(s) s3_zz unknown to trial 1",
    ),
    "a swimmer-only parameter": (None, "four.toml: params body_fit='chain' is the built-in"),
}


@pytest.mark.parametrize("case", sorted(BAD_BODIES))
def test_bad_segment_body_is_one_line_and_leaves_the_database(tmp_path, case):
    edit, expected = BAD_BODIES[case]
    planar = serial_body(4, (2,))
    path, _ = write_body_trial(planar, tmp_path / "four.csv")
    db = tmp_path / "c.duckdb"
    assert runner.invoke(app, ["ingest", str(path), "--db", str(db)]).exit_code == 0
    toml = tmp_path / "four.toml"
    toml.write_text(edit(planar.toml) if edit else planar.toml)
    before = dump_db(db)
    extra = ["--param", "body_fit=chain"] if edit is None else []
    out = runner.invoke(app, ["preprocess", "--body", str(toml), "--db", str(db), *extra])
    assert out.exit_code == 2, out.output
    message = out.stderr.strip()
    assert len(message.splitlines()) == 1, message
    assert expected in message, message
    assert_same_db(before, dump_db(db))
