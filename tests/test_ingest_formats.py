"""C3D and CSV captures ingest to the same rows as the QTM export of the same data."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.ingest import read_capture
from suds_exp.ingest.csv_reader import write_marker_csv
from suds_exp.testing.capture_files import write_c3d, write_motive, write_trc, write_vicon
from suds_exp.testing.synthetic_captures import qtm_text, random_track


@pytest.fixture
def data():
    xyz = random_track(40, 3, seed=7)
    xyz[5, 1] = np.nan
    return ["a", "b", "c"], xyz


def test_c3d_in_metres_is_converted_to_mm(tmp_path, data):
    names, xyz = data
    capture, _ = read_capture(write_c3d(tmp_path / "m.c3d", names, xyz, units="m   ", scale=1000.0))
    np.testing.assert_allclose(capture.xyz, xyz, atol=1e-2, equal_nan=True)


def test_csv_round_trip(tmp_path, data):
    names, xyz = data
    (tmp_path / "q.tsv").write_text(qtm_text(names, xyz), newline="")
    qtm, _ = read_capture(tmp_path / "q.tsv")
    write_marker_csv(tmp_path / "q.csv", qtm)
    csv_capture, _ = read_capture(tmp_path / "q.csv")
    assert csv_capture.sample_rate_hz == pytest.approx(100.0)
    assert csv_capture.marker_names == names
    np.testing.assert_allclose(csv_capture.xyz, qtm.xyz, atol=1e-3, equal_nan=True)


@pytest.mark.parametrize(
    ("fmt", "write", "t_atol"),
    [
        ("c3d", lambda p, n, x: write_c3d(p / "q.c3d", n, x), 1e-9),
        ("trc", lambda p, n, x: write_trc(p / "a.trc", n, x), 1e-5),
        (
            "trc",
            lambda p, n, x: write_trc(p / "m.trc", n, x, units="m", scale=1000.0, first=7),
            1e-5,
        ),
        ("vicon-csv", lambda p, n, x: write_vicon(p / "v.csv", n, x), 1e-5),
        (
            "vicon-csv",
            lambda p, n, x: write_vicon(p / "w.csv", n, x, units="m", scale=1000.0),
            1e-5,
        ),
        ("motive-csv", lambda p, n, x: write_motive(p / "o.csv", n, x), 1e-5),
    ],
)
def test_every_format_matches_qtm(tmp_path, data, fmt, write, t_atol):
    names, xyz = data
    (tmp_path / "q.tsv").write_text(qtm_text(names, xyz), newline="")
    qtm, _ = read_capture(tmp_path / "q.tsv")
    capture, _ = read_capture(write(tmp_path, names, xyz))
    assert capture.format == fmt
    assert capture.marker_names == names
    assert capture.sample_rate_hz == pytest.approx(100.0)
    np.testing.assert_allclose(capture.xyz, qtm.xyz, atol=1e-3, equal_nan=True)
    np.testing.assert_allclose(capture.t, qtm.t, atol=t_atol)


def test_skipped_parts_are_named_in_a_note(tmp_path, data):
    names, xyz = data
    vicon, _ = read_capture(write_vicon(tmp_path / "v.csv", names, xyz))
    assert vicon.meta["notes"] == ["skipped block(s) Devices"]
    motive, _ = read_capture(write_motive(tmp_path / "o.csv", names, xyz))
    assert motive.meta["notes"] == ["skipped column type(s) Rigid Body"]


def test_prefixes_stay_when_short_names_would_clash(tmp_path, data):
    _, xyz = data
    path = write_vicon(tmp_path / "v.csv", ["a", "b", "c"], xyz)
    text = path.read_text().replace("Robot:c", "Other:a")
    path.write_text(text)
    capture, _ = read_capture(path)
    assert capture.marker_names == ["Robot:a", "Robot:b", "Other:a"]
