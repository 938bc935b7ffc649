"""Gait tools on bodies other than the swimmer: described serial
bodies of 2, 3 and 5 links (1, 2 and 4 actuated joints) moved by the kinematic generator,
ingested and preprocessed through the CLI; gait files named by the body's joints;
predict, connection and design work or refuse in one line; the support flag; estimates
and their intervals; outputs under reports/."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.errors import ConfigError
from suds_exp.gait.predict import MIN_BOOT, percentile_interval
from suds_exp.gait.shape import FourierGait, read_gait_file
from suds_exp.testing.database import assert_same_db, dump_db
from suds_exp.testing.kinematic_body import serial_body, write_body_trial

runner = CliRunner()

#: One design iteration of one harmonic a joint within 0.8 rad.
DESIGN_ONE = ("gait", "design", "--iterations", "1", "--order", "1", "--bound", "0.8")
#: The generator's travelling wave (`kinematic_body.travelling_wave` defaults): actuated
#: joint i at AMPLITUDE sin(theta - i LAG).
AMPLITUDE, LAG = 0.5, 0.9


def cli(*args):
    return runner.invoke(app, [str(a) for a in args])


def ok(*args) -> str:
    r = cli(*args)
    assert r.exit_code == 0, r.output + (r.stderr or "")
    return r.stdout


def refused(db: Path, *args) -> str:
    """Run a command that must be refused in one line leaving the database as it was;
    that line."""
    before = dump_db(db)
    r = cli(*args, "--db", db)
    assert r.exit_code == 2, r.output
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert_same_db(before, dump_db(db))
    return lines[0]


def _body_db(work: Path, n_segments: int, rename: dict[str, str]) -> Path:
    planar = serial_body(n_segments, fin=True)
    toml = planar.toml
    for old, new in rename.items():
        toml = toml.replace(f'name = "{old}"', f'name = "{new}"')
    (work / "body.toml").write_text(toml)
    db = work / "body.duckdb"
    for seed in (0, 1):
        path, _ = write_body_trial(planar, work / f"trial{seed}.csv", seed=seed)
        ok("ingest", path, "--db", db)
    ok("preprocess", "--body", work / "body.toml", "--db", db, "-q")
    return db


@pytest.fixture(scope="module")
def bodies(tmp_path_factory) -> dict[int, Path]:
    """Databases of the 2-link body (its joint named phi1, as a one-motor swimmer's
    would be), the 3-link (q1, q2) and the 5-link (q1..q4), each 2 trials of 6 s."""
    out = {}
    for n, rename in ((2, {"q1": "phi1"}), (3, {}), (5, {})):
        out[n - 1] = _body_db(tmp_path_factory.mktemp(f"body{n}"), n, rename)
    return out


@pytest.fixture
def body_db(bodies, tmp_path, request) -> Path:
    copy = tmp_path / "db.duckdb"
    shutil.copy(bodies[request.param], copy)
    return copy


def joints_of(m: int) -> list[str]:
    return ["phi1"] if m == 1 else [f"q{i}" for i in range(1, m + 1)]


def wave_toml(path: Path, joints, amplitude=AMPLITUDE, extra: dict | None = None) -> Path:
    """The generator's wave over ``joints`` (sin(theta - i LAG) = cos LAG sin - sin LAG cos)
    and ``extra`` joints (name -> amplitude of a cosine) as a Fourier gait file."""
    lines = []
    for i, j in enumerate(joints):
        c, s = -amplitude * math.sin(i * LAG), amplitude * math.cos(i * LAG)
        lines += [f"[{j}]", f"cos = [{c:.9g}]", f"sin = [{s:.9g}]", ""]
    for j, a in (extra or {}).items():
        lines += [f"[{j}]", f"cos = [{a:g}]", ""]
    path.write_text("\n".join(lines))
    return path


def test_gait_files_carry_one_column_per_joint_named_as_the_body(tmp_path):
    toml = wave_toml(tmp_path / "w.toml", ["q1", "q2", "q3"])
    g = read_gait_file(toml)
    assert g.joints == ("q1", "q2", "q3")
    theta = np.linspace(0, 2 * np.pi, 9)
    np.testing.assert_allclose(g.shape(theta)[:, 2], AMPLITUDE * np.sin(theta - 2 * LAG))
    csv = tmp_path / "w.csv"
    rows = ["phase_rad,q1_rad,q2_rad,q3_rad"] + [
        f"{t:.6f}," + ",".join(f"{v:.6f}" for v in g.shape(t))
        for t in 2 * np.pi * np.arange(64) / 64
    ]
    csv.write_text("\n".join(rows) + "\n")
    s = read_gait_file(csv)
    assert s.joints == ("q1", "q2", "q3")
    np.testing.assert_allclose(s.shape(theta), g.shape(theta), atol=1e-4)
    # the swimmer's files are unchanged, and the TOML the designer writes reads back
    assert isinstance(g, FourierGait)
    (tmp_path / "back.toml").write_text(g.to_toml())
    np.testing.assert_allclose(read_gait_file(tmp_path / "back.toml").shape(theta), g.shape(theta))
    bad = tmp_path / "bad.csv"
    bad.write_text("phase_rad,q1,q2_rad\n0,0,0\n")
    with pytest.raises(ConfigError, match=r"bad.csv: column 'q1'.*JOINT_rad"):
        read_gait_file(bad)


@pytest.mark.parametrize("body_db", [1], indirect=True)
def test_the_silent_phi2_is_refused_naming_the_column_and_the_body_s_joints(body_db, tmp_path):
    # once, on a body with one actuated joint the gait's phi2 was ignored (the same
    # prediction whether phi2 was an ellipse or zero)
    gait = wave_toml(tmp_path / "two.toml", ["phi1"], extra={"phi2": 1.0})
    line = refused(body_db, "gait", "predict", "--gait-file", gait, "--boots", "0")
    assert "two.toml" in line and "'phi2'" in line and "phi1" in line, line
    assert "no joint" in line, line
    # the gait of the joint the body has is predicted
    one = wave_toml(tmp_path / "one.toml", ["phi1"])
    doc = json.loads(
        ok("gait", "predict", "--gait-file", one, "--boots", "0", "--db", body_db, "--json")
    )
    assert doc["joints"] == ["phi1"] and math.isfinite(doc["forward_mm"])


@pytest.mark.parametrize("body_db", [4], indirect=True)
def test_a_gait_missing_one_of_the_body_s_joints_is_refused(body_db, tmp_path):
    gait = wave_toml(tmp_path / "three.toml", ["q1", "q2", "q3"])
    line = refused(body_db, "gait", "predict", "--gait-file", gait, "--boots", "0")
    assert "three.toml" in line and "'q4'" in line, line


@pytest.mark.parametrize("body_db", [1, 2, 4], indirect=True, ids=["1-joint", "2-joint", "4-joint"])
def test_predict_flags_a_gait_outside_the_data_s_support(body_db, tmp_path, request):
    joints = joints_of(request.node.callspec.params["body_db"])
    inside = wave_toml(tmp_path / "inside.toml", joints)
    outside = wave_toml(tmp_path / "outside.toml", joints, amplitude=1.4)
    docs = {}
    for g in (inside, outside):
        docs[g.stem] = json.loads(
            ok("gait", "predict", "--gait-file", g, "--boots", "0", "--db", body_db, "--json")
        )
        assert docs[g.stem]["joints"] == joints
        for key in ("forward_mm", "lateral_mm", "turn_rad", "mean_vx_mm_s"):
            assert math.isfinite(docs[g.stem][key])
    assert docs["inside"]["support"]["inside"] is True, docs["inside"]["support"]
    assert docs["outside"]["support"]["inside"] is False, docs["outside"]["support"]
    assert docs["outside"]["support"]["distance_rad"] > docs["outside"]["support"]["radius_rad"]
    text = ok("gait", "predict", "--gait-file", outside, "--boots", "0", "--db", body_db)
    assert "outside the data's support" in text, text
    text = ok("gait", "predict", "--gait-file", inside, "--boots", "0", "--db", body_db)
    assert "outside" not in text, text


@pytest.mark.parametrize("body_db", [2], indirect=True)
def test_the_estimate_outside_its_interval_is_refused_or_explained(body_db, tmp_path):
    # once, `--boot 3` gave lateral_mm 12.97 against its interval [10.106, 12.703]:
    # 3 refits cannot estimate 2.5 and 97.5 percentiles
    gait = wave_toml(tmp_path / "w.toml", ["q1", "q2"])
    line = refused(body_db, "gait", "predict", "--gait-file", gait, "--boots", "3")
    assert "--boots 3" in line and str(MIN_BOOT) in line, line


def test_an_interval_that_misses_its_estimate_says_why():
    rng = np.random.default_rng(0)
    boots = rng.normal(10.0, 1.0, MIN_BOOT)
    inside = percentile_interval(10.2, boots)
    assert inside.low <= 10.2 <= inside.high and inside.note == ""
    shifted = percentile_interval(14.0, boots)
    assert not shifted.low <= 14.0 <= shifted.high
    assert "outside its interval" in shifted.note and "bias" in shifted.note
    with pytest.raises(ConfigError, match=f"at least {MIN_BOOT}"):
        percentile_interval(10.0, boots[:3])


@pytest.mark.parametrize("body_db", [1, 4], indirect=True, ids=["1-joint", "4-joint"])
def test_connection_refuses_bodies_without_two_joints_in_one_line(body_db, tmp_path):
    line = refused(body_db, "gait", "connection", "--out", tmp_path / "c.csv")
    assert "two actuated joints" in line, line
    assert not (tmp_path / "c.csv").exists()


@pytest.mark.parametrize("body_db", [2], indirect=True)
def test_connection_of_a_two_joint_body_goes_under_reports(body_db, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ("gait", "connection", "--grid", "9", "--range", "0.6", "--db", body_db)
    doc = json.loads(ok(*args, "--json"))
    assert Path(doc["csv"]).resolve().is_relative_to((tmp_path / "reports").resolve())
    assert Path(doc["csv"]).is_file() and Path(doc["figure"]).is_file()
    assert doc["joints"] == ["q1", "q2"] and doc["n_inside"] > 0
    line = refused(body_db, *args[:-2], "--compare")
    assert "--compare" in line and "swimmer" in line, line
    # a grid with no shape near the data (5 points over +-2 rad; the data swing 0.5 rad)
    line = refused(body_db, "gait", "connection", "--grid", "5")
    assert "--grid 5, --range 2: no shape of the grid lies within 0.1 rad" in line, line


@pytest.mark.parametrize("body_db", [1, 4], indirect=True, ids=["1-joint", "4-joint"])
def test_design_works_on_any_body_and_writes_under_reports(body_db, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    doc = json.loads(ok(*DESIGN_ONE, "--db", body_db, "--json"))
    report = Path(doc["report"])
    assert report.is_file() and report.resolve().is_relative_to((tmp_path / "reports").resolve())
    assert not (tmp_path / "gait-design").exists()
    it = doc["iterations"][0]
    m = len(doc["joints"])
    assert m in (1, 4) and all(f"{j}_rad" in it for j in doc["joints"])
    for j in doc["joints"]:
        assert np.abs(it[f"{j}_rad"]).max() <= 0.8 + 1e-9
    assert len(it["coefficients"]) == 3 * m  # a0, cos and sin of one harmonic a joint
    assert isinstance(it["support"]["inside"], bool)
    # the designed gait's file reads back as a gait of the body's joints
    saved = Path(doc["gaits"][0])
    assert read_gait_file(saved).joints == tuple(doc["joints"])
    # the same design printed: its line flags a gait outside the data's support
    text = ok(
        "gait", "design", "--iterations", "1", "--order", "1", "--bound", "0.8", "--db", body_db
    )
    assert ("outside the data's support" in text) is (not it["support"]["inside"]), text
    line = refused(body_db, "gait", "design", "--iterations", "1", "--verify")
    assert "--verify" in line and "swimmer" in line, line


@pytest.mark.parametrize("body_db", [2], indirect=True)
def test_every_estimate_lies_inside_its_interval_or_says_why(body_db, tmp_path):
    # the reproduction's gait (a circle of 1 rad on the 3-link body) with the fewest refits
    # allowed: each interval holds its estimate, or the JSON and the text say why not
    gait = tmp_path / "circle.toml"
    gait.write_text("[q1]\ncos = [1.0]\n\n[q2]\nsin = [1.0]\n")
    args = ("gait", "predict", "--gait-file", gait, "--boots", str(MIN_BOOT), "--db", body_db)
    doc = json.loads(ok(*args, "--json"))
    assert doc["n_boot"] == MIN_BOOT
    for key in ("forward_mm", "lateral_mm", "turn_rad", "mean_vx_mm_s"):
        lo, hi = doc["interval"][key]
        assert lo <= doc[key] <= hi or "outside its interval" in doc["interval_notes"][key]
    text = ok(*args)
    for key in doc["interval_notes"]:
        assert f"note: {key}: estimate" in text, text


def test_the_simulator_refuses_a_gait_of_other_joints_in_one_line(tmp_path, db):
    # the simulator moves the swimmer: a gait file of other joints is refused before any
    # file is written
    assert cli("init", "--db", db).exit_code == 0
    gait = wave_toml(tmp_path / "q.toml", ["q1", "q2"])
    out = tmp_path / "sim"
    line = refused(db, "simulate", "--out", out, "--gait-file", gait, "--ingest")
    assert "q.toml" in line and "'q1', 'q2'" in line and "phi1, phi2" in line, line
    assert not out.exists()


@pytest.mark.slow
def test_predict_and_design_on_eight_actuated_joints(tmp_path, monkeypatch):
    # the most a version holds (ra_1 .. ra_8): a 9-link body (24 s measured in all)
    db = _body_db(tmp_path, 9, {})
    joints = joints_of(8)
    doc = json.loads(
        ok(
            "gait",
            "predict",
            "--gait-file",
            wave_toml(tmp_path / "w.toml", joints),
            "--boot",
            "0",
            "--db",
            db,
            "--json",
        )
    )
    assert doc["joints"] == joints and doc["support"]["inside"] is True
    monkeypatch.chdir(tmp_path)
    design = json.loads(ok(*DESIGN_ONE, "--db", db, "--json"))
    assert design["joints"] == joints
    assert read_gait_file(design["gaits"][0]).joints == tuple(joints)
    # the designer's circles are far from these data in 16 dimensions; the design still
    # keeps to its trust region
    it = design["iterations"][0]
    assert it["support_distance"] <= it["trust_radius"] + 1e-9, it
