"""Real exports from other labs ingest as they are (files in ../shared/refdata).

Expected counts are taken from the files' own headers and from a plain count of their
gap cells, not from the readers under test.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.testing.database import assert_same_db, dump_db

runner = CliRunner()


def cli(*args):
    return runner.invoke(app, [str(a) for a in args])


def _gap_points(path: Path, sep: str, first_data_line: int, missing: set[str]) -> int:
    """Marker positions whose three cells are all a gap token, counted from the raw text."""
    count = 0
    lines = path.read_text().splitlines()[first_data_line - 1 :]
    for line in lines:
        if not line.strip():
            break
        cells = line.rstrip(sep).split(sep)[2:] if sep == "\t" else line.split(sep)[2:]
        for j in range(0, len(cells), 3):
            if all(c.strip() in missing for c in cells[j : j + 3]):
                count += 1
    return count


def _trial(db: Path) -> dict:
    out = cli(
        "sql",
        "SELECT t.format, t.n_frames, t.sample_rate_hz, t.marker_names, "
        "(SELECT count(*) FROM markers m WHERE m.trial_id = t.id AND m.missing) AS n_missing, "
        "(SELECT min(frame) FROM markers m WHERE m.trial_id = t.id) AS first_frame "
        "FROM trials t ORDER BY t.id DESC LIMIT 1",
        "--db",
        db,
        "--json",
    )
    assert out.exit_code == 0, out.output
    return json.loads(out.stdout)[0]


SNAKE_QTM = [f"{i:02d}" for i in range(1, 15)]


@pytest.mark.parametrize("name", ["413_91.tsv", "413_91_filled.tsv"])
def test_flying_snake_qualisys_export_with_na_gaps(db, shared, name):
    path = shared / "refdata" / "flying_snake_qualisys" / name
    result = cli("ingest", path, "--db", db)
    assert result.exit_code == 0, result.output
    trial = _trial(db)
    assert trial["format"] == "qtm-tsv"
    assert trial["n_frames"] == 263
    assert trial["sample_rate_hz"] == 179.0
    assert trial["marker_names"] == SNAKE_QTM
    assert trial["first_frame"] == 3319
    expected = _gap_points(path, "\t", 12, {"NA", "0.000"})
    assert expected > 0
    assert trial["n_missing"] == expected


def test_the_filled_export_has_fewer_gaps(db, shared):
    folder = shared / "refdata" / "flying_snake_qualisys"
    assert cli("ingest", folder / "413_91.tsv", "--db", db).exit_code == 0
    raw = _trial(db)["n_missing"]
    assert cli("ingest", folder / "413_91_filled.tsv", "--db", db).exit_code == 0
    assert _trial(db)["n_missing"] < raw


def test_vicon_nexus_trajectories_export(db, shared):
    path = shared / "refdata" / "snake_gaps_vicon" / "275_Snake85_gap12_1.csv"
    result = cli("ingest", path, "--db", db)
    assert result.exit_code == 0, result.output
    trial = _trial(db)
    assert trial["format"] == "vicon-csv"
    assert trial["n_frames"] == 168  # frames 24257..24424
    assert trial["first_frame"] == 24257
    assert trial["sample_rate_hz"] == 150.0
    body = ["Head_M1"] + [f"M{i}" for i in range(2, 10)] + ["Vent_M10"]
    branch = ["OriginEnd", "TargetEnd", "OriginOther", "TargetOther"]
    assert trial["marker_names"] == body + branch
    assert trial["n_missing"] == _gap_points(path, ",", 6, {""})
    assert trial["n_missing"] > 0


@pytest.mark.parametrize(
    ("name", "n_markers"), [("qtm_measurement1.tsv", 15), ("qtm_measurement2.tsv", 16)]
)
def test_qtm_human_exports(db, shared, name, n_markers):
    path = shared / "refdata" / name
    assert cli("ingest", path, "--db", db).exit_code == 0
    trial = _trial(db)
    assert (trial["n_frames"], len(trial["marker_names"])) == (2000, n_markers)
    header = path.read_text().splitlines()[9].split("\t")
    assert header[0] == "MARKER_NAMES" and trial["marker_names"] == header[1:]
    assert trial["n_missing"] == _gap_points(path, "\t", 13, {"0.000", ""})


def test_folder_with_one_bad_file_stores_the_others(db, shared, tmp_path):
    folder = tmp_path / "captures"
    folder.mkdir()
    refdata = shared / "refdata"
    shutil.copy(refdata / "flying_snake_qualisys" / "413_91.tsv", folder)
    shutil.copy(refdata / "snake_gaps_vicon" / "275_Snake85_gap12_1.csv", folder)
    lines = (refdata / "qtm_measurement1.tsv").read_text().splitlines()
    lines[20] = lines[20].replace("\t", "\tx", 1)  # 'x0.01000' in the Time column
    (folder / "broken.tsv").write_text("\n".join(lines) + "\n")
    result = cli("ingest", folder, "--db", db, "-q")
    assert result.exit_code == 2, result.output
    errors = result.stderr.strip().splitlines()
    assert len(errors) == 2, errors
    assert "broken.tsv: line 21, column 'Time': expected a number" in errors[0]
    assert "1 of 3 files refused" in errors[1]
    stored = cli("sql", "SELECT format FROM trials ORDER BY id", "--db", db, "--json")
    assert sorted(r["format"] for r in json.loads(stored.stdout)) == ["qtm-tsv", "vicon-csv"]

    before = dump_db(db)
    again = cli("ingest", folder, "--db", db, "-q")
    assert again.exit_code == 2
    assert again.stdout.count("skipped") == 2
    assert_same_db(before, dump_db(db))
