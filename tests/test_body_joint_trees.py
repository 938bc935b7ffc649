"""Joint angles are defined by the joint, not by the file: any valid tree of rigid segments
(any root, any body frame segment, joints listed in any order, passive joints and passive
markers) gives each joint's bend and the body velocity of the documented body frame; a
rigid segment takes its pose from whichever of its markers are visible."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from cli import app
from suds_exp.body import SegmentModel, preprocess_body
from suds_exp.body.description import BodyError, parse_body
from suds_exp.ingest import ingest_paths
from suds_exp.ingest.readers import read_capture
from suds_exp.preprocess import load_samples
from suds_exp.preprocess.clean import clean_tracks
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db
from suds_exp.testing.kinematic_body import (
    random_tree_body,
    serial_body,
    sine,
    write_body_trial,
)

runner = CliRunner()

ANGLE_RMS_RAD = 0.01
VELOCITY_RMS_FRACTION = 0.05


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def _wrapped(x):
    return np.angle(np.exp(1j * np.asarray(x)))


def _signals(planar):
    """A known smooth motion keyed by joint name (not by listing order)."""
    out = {}
    for i, j in enumerate(sorted(planar.body.joints, key=lambda j: j.name)):
        if j.kind == "actuated":
            out[j.name] = sine(0.5, 1.0, -0.9 * i)
        else:
            out[j.name] = sine(0.25, 1.0, -0.9 * i - np.pi / 2, 0.05)
    return out


def _through_model(planar, path):
    """(joint angles by name, kinematics) from the file through the public model."""
    model = SegmentModel(planar.body)
    capture, _ = read_capture(path)
    clean = clean_tracks(capture.xyz, 9.0, 25, capture.marker_names)
    measured = model.measure(clean.xyz, {}, filled=clean.filled)
    joints = model.fit_joints([measured])
    kin = model.kinematics(measured, joints, {}, capture.sample_rate_hz, 1.0)
    return model.joint_angles(measured, joints), kin, measured


def _velocity_error(truth, samples) -> float:
    speed = _rms(np.hypot(truth.vx, truth.vy))
    error = np.hypot(samples.vx.to_numpy() - truth.vx, samples.vy.to_numpy() - truth.vy)
    return _rms(error) / speed


def _check_tree(tmp_path, seed, n_segments):
    tmp_path = Path(tempfile.mkdtemp(dir=tmp_path))  # hypothesis reuses the fixture
    planar = random_tree_body(seed, n_segments)
    signals = _signals(planar)
    path, truth = write_body_trial(planar, tmp_path / "tree.csv", seed=seed, joint_signals=signals)
    angles, kin, _ = _through_model(planar, path)
    for j in planar.body.joints:
        error = _rms(_wrapped(angles[j.name] - truth[j.name].to_numpy()))
        assert error < ANGLE_RMS_RAD, (planar.toml, j.name, error)

    store = Store(tmp_path / "tree.duckdb")
    ingest_paths(store, [path], None, progress=False)
    result = preprocess_body(store, planar.body, progress=False)
    samples = load_samples(store, result.version_id)
    at = truth.iloc[samples.frame.to_numpy() - 1]
    actuated = [j.name for j in planar.body.joints if j.kind == "actuated"]
    for i, name in enumerate(actuated):
        error = _rms(_wrapped(samples[f"ra_{i + 1}"].to_numpy() - at[name].to_numpy()))
        assert error < ANGLE_RMS_RAD, (planar.toml, name, error)
    assert _velocity_error(at, samples) < VELOCITY_RMS_FRACTION, planar.toml

    # another listing of the same tree: the same angles by name, the same body motion
    order = [j.name for j in planar.body.joints][::-1]
    other = planar.relisted(order)
    other_angles, other_kin, _ = _through_model(other, path)
    for name, value in angles.items():
        np.testing.assert_allclose(other_angles[name], value, atol=1e-9)
    np.testing.assert_allclose(other_kin.xy, kin.xy, atol=1e-9)
    np.testing.assert_allclose(other_kin.heading, kin.heading, atol=1e-9)
    np.testing.assert_allclose(other_kin.passive, kin.passive, atol=1e-9)


@settings(
    max_examples=12,
    deadline=None,
    derandomize=True,
    phases=[Phase.explicit, Phase.generate],  # a failing tree is printed, not shrunk
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(seed=st.integers(0, 10_000), n_segments=st.integers(2, 6))
def test_any_valid_tree_gives_each_joints_bend_and_the_body_velocity(tmp_path, seed, n_segments):
    _check_tree(tmp_path, seed, n_segments)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(60))
def test_sixty_random_trees(tmp_path, seed):
    _check_tree(tmp_path, seed, 2 + seed % 5)


PURCELL_FROM_MIDDLE = """
name = "purcell"
body_frame = "middle"
[segments.tail]
markers = { tail_a = "top", tail_b = "top", tail_c = "top" }
[segments.middle]
markers = { middle_a = "top", middle_b = "top", middle_c = "top" }
[segments.head]
markers = { head_a = "top", head_b = "top", head_c = "top" }
[passive_markers]
fin = "head"
"""
JOINT = '[[joints]]\nname = "{}"\nparent = "middle"\nchild = "{}"\nkind = "actuated"\n'


@pytest.mark.parametrize("first", ["head", "tail"])
def test_a_segment_parent_of_two_joints_gives_no_pi_offset(tmp_path, first):
    """The Purcell swimmer described from its middle: both joints' bends are right and
    straight is zero, whichever joint the file lists first (once off by pi)."""
    # the middle link from its tail joint (0, 0) to its head joint (60, 0); the tail link
    # hangs from its far end (60, 0), the head link from its near end (0, 0)
    serial = serial_body(3, fin=True)
    markers = {
        m.replace("s1", "tail").replace("s2", "middle").replace("s3", "head"): xyz
        for m, xyz in serial.markers.items()
    }
    joints = {"to_head": ((60.0, 0.0), (0.0, 0.0)), "to_tail": ((0.0, 0.0), (60.0, 0.0))}
    listing = ["to_head", "to_tail"] if first == "head" else ["to_tail", "to_head"]
    text = PURCELL_FROM_MIDDLE + "".join(
        JOINT.format(name, name.removeprefix("to_")) for name in listing
    )
    planar = type(serial)(parse_body(text, "purcell.toml"), markers, serial.hinges, joints, text)
    assert planar.bend_offsets() == {"to_head": 0.0, "to_tail": 0.0}  # straight is zero
    signals = {"to_head": sine(0.6, 1.0), "to_tail": sine(0.6, 1.0, -1.2)}
    path, truth = write_body_trial(planar, tmp_path / f"p-{first}.csv", joint_signals=signals)
    angles, _, _ = _through_model(planar, path)
    for name in joints:
        # the child of a middle-rooted joint bends away from the middle: the tail's bend
        # is its own (its sign is opposite to the tail-to-head swimmer's phi2)
        assert _rms(angles[name] - truth[name].to_numpy()) < ANGLE_RMS_RAD, name


def _fastest_segment(planar, signals):
    t = np.arange(600) / 100.0
    from suds_exp.testing.kinematic_body import wavy_path

    xyz, _ = planar.move(t, signals, wavy_path(), {m: sine(0.4, 1.0) for m in planar.hinges})
    speed = np.linalg.norm(np.diff(xyz, axis=0), axis=2).mean(axis=0)
    by_segment = {
        s.name: np.mean([speed[planar.body.markers.index(m)] for m in s.markers])
        for s in planar.body.segments
    }
    return max(by_segment, key=by_segment.get)


@pytest.mark.parametrize("n_segments", [3, 5])
def test_a_marker_gap_on_the_fastest_segment_keeps_its_pose_from_the_other_two(
    tmp_path, n_segments
):
    planar = serial_body(n_segments, fin=True)
    # a fast gait (2 Hz, 0.8 rad), over which interpolating a lost marker bends the link
    # (on 5 links: 0.087 rad at worst, 0.034 RMS over the gap, before)
    signals = {j.name: sine(0.8, 2.0, -0.9 * i) for i, j in enumerate(planar.body.joints)}
    fastest = _fastest_segment(planar, signals)
    marker = f"{fastest}_a"
    path, truth = write_body_trial(
        planar, tmp_path / "gap.csv", n_gaps=0, joint_signals=signals, gaps={marker: (300, 10)}
    )
    angles, _, measured = _through_model(planar, path)
    for j in planar.body.joints:
        gap = slice(300, 310)
        error = _rms(angles[j.name][gap] - truth[j.name].to_numpy()[gap])
        assert error < ANGLE_RMS_RAD, (j.name, error)
        assert _rms(angles[j.name] - truth[j.name].to_numpy()) < ANGLE_RMS_RAD
    # two of its three markers fix the segment in every frame: no pose was interpolated
    assert measured.interpolated_frames == {s.name: 0 for s in planar.body.segments}


def test_a_segment_pose_is_interpolated_only_where_too_few_markers_are_seen(tmp_path):
    planar = serial_body(3, fin=True)
    gaps = {"s3_a": (300, 6), "s3_b": (302, 6)}  # both unseen on frames 302-305
    path, _ = write_body_trial(planar, tmp_path / "gap2.csv", n_gaps=0, gaps=gaps)
    _, _, measured = _through_model(planar, path)
    assert measured.interpolated_frames == {"s1": 0, "s2": 0, "s3": 4}
    store = Store(tmp_path / "g.duckdb")
    ingest_paths(store, [path], None, progress=False)
    result = preprocess_body(store, planar.body, progress=False)
    assert result.interpolated_pose_frames == 4


def test_a_segment_joined_to_nothing_is_refused_in_one_line(tmp_path):
    loose = '[segments.loose]\nmarkers = { l1 = "top", l2 = "top" }\n[passive_markers]'
    text = serial_body(3, fin=True).toml.replace("[passive_markers]", loose)
    with pytest.raises(BodyError) as err:
        parse_body(text, "three.toml")
    assert str(err.value) == (
        "three.toml: segments.loose: joined to no other segment; every segment must be "
        "connected to the body by joints (add a [[joints]] entry or remove the segment)"
    )
    # through the command line: one line, the database unchanged
    planar = serial_body(3, fin=True)
    path, _ = write_body_trial(planar, tmp_path / "three.csv")
    db = tmp_path / "c.duckdb"
    assert runner.invoke(app, ["ingest", str(path), "--db", str(db)]).exit_code == 0
    toml = tmp_path / "three.toml"
    toml.write_text(text)
    before = dump_db(db)
    out = runner.invoke(app, ["preprocess", "--body", str(toml), "--db", str(db)])
    assert out.exit_code == 2, out.output
    assert len(out.stderr.strip().splitlines()) == 1, out.stderr
    assert "segments.loose: joined to no other segment" in out.stderr
    assert_same_db(before, dump_db(db))
