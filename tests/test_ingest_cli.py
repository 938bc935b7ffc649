"""Ingest through the CLI: good captures, every bad-input case, database left unchanged."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.testing.database import assert_same_db, dump_db
from suds_exp.testing.synthetic_captures import qtm_text, random_track

runner = CliRunner()


def cli(*args: str):
    return runner.invoke(app, [str(a) for a in args])


def test_real_qualisys_exports_ingest_as_they_are(db, shared):
    refdata = shared / "refdata"
    result = cli(
        "ingest",
        refdata / "qtm_measurement1.tsv",
        refdata / "qtm_measurement2.tsv",
        "--db",
        db,
        "--json",
    )
    assert result.exit_code == 0, result.output
    rows = json.loads(result.stdout)
    assert [r["status"] for r in rows] == ["ingested", "ingested"]
    out = cli(
        "sql",
        "SELECT n_frames, len(marker_names) AS n, sample_rate_hz FROM trials ORDER BY id",
        "--db",
        db,
        "--json",
    )
    assert json.loads(out.stdout) == [
        {"n_frames": 2000, "n": 15, "sample_rate_hz": 100.0},
        {"n_frames": 2000, "n": 16, "sample_rate_hz": 100.0},
    ]
    counts = cli("sql", "SELECT count(*) AS n FROM markers", "--db", db, "--json")
    assert json.loads(counts.stdout) == [{"n": 2000 * 31}]


def test_reingesting_the_same_content_does_nothing_and_says_so(db, make_qtm):
    path = make_qtm("a.tsv")
    assert cli("ingest", path, "--db", db).exit_code == 0
    before = dump_db(db)
    again = cli("ingest", path, "--db", db)
    assert again.exit_code == 0
    assert "already ingested as trial 1" in again.stdout
    assert_same_db(before, dump_db(db))


def test_zero_triplets_and_empty_cells_are_stored_as_missing(db, tmp_path):
    xyz = random_track(6, 2)
    xyz[2, 0] = np.nan  # written as 0 0 0
    text = qtm_text(["a", "b"], xyz)
    lines = text.split("\r\n")
    cells = lines[12 + 4].split("\t")  # frame 5: leave marker b's cells empty
    cells[5:8] = ["", "", ""]
    lines[12 + 4] = "\t".join(cells)
    path = tmp_path / "gaps.tsv"
    path.write_text("\r\n".join(lines), newline="")
    assert cli("ingest", path, "--db", db).exit_code == 0
    out = cli(
        "sql",
        "SELECT frame, marker FROM markers WHERE missing ORDER BY frame",
        "--db",
        db,
        "--json",
    )
    assert json.loads(out.stdout) == [{"frame": 3, "marker": "a"}, {"frame": 5, "marker": "b"}]
    nulls = cli(
        "sql",
        "SELECT count(*) AS n FROM markers WHERE missing AND x IS NOT NULL",
        "--db",
        db,
        "--json",
    )
    assert json.loads(nulls.stdout) == [{"n": 0}]


def test_manifest_assigns_conditions_and_unlisted_files_have_none(db, make_qtm, tmp_path):
    a, b = make_qtm("a.tsv", seed=1), make_qtm("b.tsv", seed=2)
    manifest = tmp_path / "manifest.csv"
    manifest.write_text("file,gait,frequency_hz,repeat,notes\na.tsv,D+,1/3,2,first\n")
    assert cli("ingest", a, b, "--manifest", manifest, "--db", db).exit_code == 0
    out = cli("trials", "--db", db, "--json")
    rows = {Path(r["source_file"]).name: r for r in json.loads(out.stdout)}
    assert rows["a.tsv"]["gait"] == "D+" and rows["a.tsv"]["repeat"] == 2
    assert rows["a.tsv"]["frequency_hz"] == pytest.approx(1 / 3)
    assert rows["a.tsv"]["notes"] == "first"
    assert rows["b.tsv"]["gait"] is None


def test_folder_and_manifest_only_ingest(db, make_qtm, tmp_path):
    make_qtm("a.tsv", seed=1)
    make_qtm("b.tsv", seed=2)
    manifest = tmp_path / "manifest.csv"
    manifest.write_text("file,gait,frequency_hz,repeat,notes\na.tsv,O,1,1,\nb.tsv,O,1,2,\n")
    result = cli("ingest", "--manifest", manifest, "--db", db, "--json")
    assert result.exit_code == 0, result.output
    assert len(json.loads(result.stdout)) == 2
    # the folder holds the manifest too; it is not mistaken for a capture
    again = cli("ingest", tmp_path, "--manifest", manifest, "--db", db, "--json")
    assert again.exit_code == 0, again.output
    assert {r["status"] for r in json.loads(again.stdout)} == {"skipped"}


def _bad_qtm(tmp_path: Path, name: str, mutate) -> Path:
    lines = qtm_text(["m1", "m2"], random_track(8, 2, seed=3)).split("\r\n")
    lines = mutate(lines)
    path = tmp_path / name
    path.write_text("\r\n".join(lines), newline="")
    return path


def _write(folder: Path, name: str, content: str | bytes) -> Path:
    path = folder / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return path


def _set(lines, i, value):
    lines[i] = value
    return lines


BAD_FILES = {
    "empty": (lambda tp: _write(tp, "empty.tsv", ""), "is empty"),
    "truncated": (
        lambda tp: _bad_qtm(tp, "trunc.tsv", lambda ls: ls[:15]),
        "NO_OF_FRAMES says 8 but the file has 3 data lines",
    ),
    "no table": (
        lambda tp: _bad_qtm(tp, "head.tsv", lambda ls: ls[:9]),
        "header lacks MARKER_NAMES",
    ),
    "marker count": (
        lambda tp: _bad_qtm(tp, "count.tsv", lambda ls: _set(ls, 2, "NO_OF_MARKERS\t3")),
        "NO_OF_MARKERS says 3 but MARKER_NAMES lists 2",
    ),
    "short row": (
        lambda tp: _bad_qtm(tp, "short.tsv", lambda ls: _set(ls, 14, ls[14].rsplit("\t", 3)[0])),
        "line 15: expected 8 tab-separated values",
    ),
    "non-numeric": (
        lambda tp: _bad_qtm(
            tp,
            "text.tsv",
            lambda ls: _set(
                ls,
                13,
                ls[13]
                .replace("\t", "\tabc\t", 1)
                .replace("\tabc\t", "\t", 1)
                .replace(ls[13].split("\t")[3], "1.2.3", 1),
            ),
        ),
        "line 14, column 'm1 Y': expected a number, got '1.2.3'",
    ),
    "duplicated frame": (
        lambda tp: _bad_qtm(tp, "dup.tsv", lambda ls: _set(ls, 14, "1" + ls[14][1:])),
        "line 15: frame values must increase strictly",
    ),
    "time backwards": (
        lambda tp: _bad_qtm(
            tp,
            "time.tsv",
            lambda ls: _set(
                ls, 15, "\t".join([ls[15].split("\t")[0], "0.00000"] + ls[15].split("\t")[2:])
            ),
        ),
        "line 16: time values must increase strictly",
    ),
    "zero rate": (
        lambda tp: _bad_qtm(tp, "rate.tsv", lambda ls: _set(ls, 3, "FREQUENCY\t0")),
        "FREQUENCY: expected a positive number of Hz",
    ),
    "unknown format": (lambda tp: _write(tp, "x.xyz", "abc"), "unknown format '.xyz'"),
    "not a trc": (lambda tp: _write(tp, "x.trc", "abc"), "line 1: not a TRC file"),
    "trc truncated": (
        lambda tp: _write(
            tp,
            "t.trc",
            "PathFileType\t4\t(X/Y/Z)\tt.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\t"
            "Units\nx\t100\t3\t1\tmm\nFrame#\tTime\ta\n\t\tX1\tY1\tZ1\n1\t0\t1\t2\t3\n",
        ),
        "line 3, DataRate: expected a positive number of Hz, got 'x'",
    ),
    "vicon without trajectories": (
        lambda tp: _write(tp, "v.csv", "Devices\n1000\n,,Plate\nFrame,Sub Frame,Fx\n,,N\n1,0,2\n"),
        "without a 'Trajectories' block (blocks found: Devices)",
    ),
    "vicon unit": (
        lambda tp: _write(
            tp,
            "u.csv",
            "Trajectories\n100\n,,S:a,,\nFrame,Sub Frame,X,Y,Z\n,,in,in,in\n1,0,1,2,3\n",
        ),
        "line 5: length unit 'in'; expected mm, cm or m",
    ),
    "vicon gap token": (
        lambda tp: _write(
            tp,
            "g.csv",
            "Trajectories\n100\n,,S:a,,\nFrame,Sub Frame,X,Y,Z\n,,mm,mm,mm\n1,0,1,2,3\n2,0,1,?,3\n",
        ),
        "line 7, column 'S:a Y': expected a number, got '?'",
    ),
    "motive without markers": (
        lambda tp: _write(
            tp,
            "o.csv",
            "Format Version,1.23,Export Frame Rate,100,Length Units,Meters\n\n"
            ",Type,Rigid Body,Rigid Body,Rigid Body\n,Name,RB,RB,RB\n,ID,1,1,1\n"
            ",,Position,Position,Position\nFrame,Time (Seconds),X,Y,Z\n0,0,1,2,3\n",
        ),
        "holds no marker positions",
    ),
    "missing file": (lambda tp: tp / "nope.tsv", "no such file"),
    "bad c3d": (
        lambda tp: _write(tp, "x.c3d", b"\x02P" + b"\x00" * 700),
        "not a readable C3D file",
    ),
    "bad csv header": (
        lambda tp: _write(tp, "x.csv", "frame,time,a_x\n1,0,2\n"),
        "line 1: expected columns frame,t",
    ),
    "csv uneven rate": (
        lambda tp: _write(
            tp,
            "r.csv",
            "frame,t,a_x,a_y,a_z\n1,0,1,2,3\n2,0.01,1,2,3\n3,0.05,1,2,3\n4,0.06,1,2,3\n",
        ),
        "expected a constant sample rate",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_FILES))
def test_bad_capture_is_refused_in_one_line_and_db_is_unchanged(case, db, make_qtm, tmp_path):
    assert cli("ingest", make_qtm("good.tsv"), "--db", db).exit_code == 0
    before = dump_db(db)
    build, expected = BAD_FILES[case]
    path = build(tmp_path)
    result = cli("ingest", path, "--db", db)
    assert result.exit_code == 2, result.output
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1, message
    assert str(path.name) in message and expected in message, message
    assert_same_db(before, dump_db(db))


def _manifest(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "manifest.csv"
    path.write_text("file,gait,frequency_hz,repeat,notes\n" + body)
    return path


BAD_MANIFESTS = {
    "file does not exist": ("ghost.tsv,O,1,1,\n", "line 2: file 'ghost.tsv' does not exist"),
    "unknown gait": ("good.tsv,Z,1,1,\n", "line 2: unknown gait 'Z'"),
    "zero frequency": ("good.tsv,O,0,1,\n", "line 2: frequency_hz '0': expected a positive number"),
    "negative frequency": ("good.tsv,O,-1,1,\n", "frequency_hz '-1'"),
    "bad repeat": ("good.tsv,O,1,x,\n", "repeat 'x': expected a whole number"),
}


@pytest.mark.parametrize("case", sorted(BAD_MANIFESTS))
def test_bad_manifest_is_refused_before_anything_is_written(case, db, make_qtm, tmp_path):
    good = make_qtm("good.tsv")
    other = make_qtm("other.tsv", seed=5)
    assert cli("ingest", other, "--db", db).exit_code == 0
    before = dump_db(db)
    body, expected = BAD_MANIFESTS[case]
    result = cli("ingest", good, "--manifest", _manifest(tmp_path, body), "--db", db)
    assert result.exit_code == 2, result.output
    assert "manifest.csv" in result.stderr and expected in result.stderr, result.stderr
    assert_same_db(before, dump_db(db))


def test_same_condition_with_different_content_is_refused(db, make_qtm, tmp_path):
    a, b = make_qtm("a.tsv", seed=1), make_qtm("b.tsv", seed=2)
    assert (
        cli(
            "ingest", a, "--manifest", _manifest(tmp_path, "a.tsv,O,0.5,1,\n"), "--db", db
        ).exit_code
        == 0
    )
    before = dump_db(db)
    result = cli("ingest", b, "--manifest", _manifest(tmp_path, "b.tsv,O,1/2,1,\n"), "--db", db)
    assert result.exit_code == 2
    assert "b.tsv" in result.stderr and "already trial 1" in result.stderr, result.stderr
    assert_same_db(before, dump_db(db))


def test_layout_naming_a_marker_the_trial_lacks_is_refused(db, make_qtm, tmp_path):
    from suds_exp.ingest import ROLES

    names = [f"M{i}" for i in range(11)]
    capture = make_qtm("robot.tsv", names=names)
    layout = tmp_path / "layout.csv"
    rows = [f"{role},{name}" for role, name in zip(ROLES, names, strict=True)]
    layout.write_text("role,marker\n" + "\n".join(rows) + "\n")
    ok = cli("ingest", capture, "--layout", layout, "--db", db)
    assert ok.exit_code == 0, ok.output
    stored = cli("sql", "SELECT layout FROM trials", "--db", db, "--json")
    assert json.loads(json.loads(stored.stdout)[0]["layout"])["flipper_4"] == "M10"

    before = dump_db(db)
    other = make_qtm("other.tsv", names=names[:-1] + ["X"], seed=4)
    result = cli("ingest", other, "--layout", layout, "--db", db)
    assert result.exit_code == 2
    assert "layout.csv" in result.stderr and "'M10' (role flipper_4)" in result.stderr
    assert "other.tsv" in result.stderr
    assert_same_db(before, dump_db(db))


def test_manifest_without_a_required_column_is_refused(db, make_qtm, tmp_path):
    good = make_qtm("good.tsv")
    manifest = tmp_path / "manifest.csv"
    manifest.write_text("file,gait,repeat\ngood.tsv,O,1\n")
    result = cli("ingest", good, "--manifest", manifest, "--db", db)
    assert result.exit_code == 2
    assert "manifest.csv: line 1: manifest lacks column(s) frequency_hz" in result.stderr
    assert dump_db(db) == {}


def test_layout_lacking_a_role_is_refused(db, make_qtm, tmp_path):
    layout = tmp_path / "layout.csv"
    layout.write_text("role,marker\nhead_top_1,M0\n")
    result = cli("ingest", make_qtm("a.tsv"), "--layout", layout, "--db", db)
    assert result.exit_code == 2
    assert "layout.csv: layout lacks role(s) head_top_2" in result.stderr
    assert dump_db(db) == {}
