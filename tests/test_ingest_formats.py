"""C3D and CSV captures ingest to the same rows as the QTM export of the same data."""

from __future__ import annotations

import io
import warnings

import c3d
import numpy as np
import pytest

from suds_exp.ingest import read_capture
from suds_exp.ingest.csv_reader import write_marker_csv
from tests.conftest import qtm_text, random_track


def write_c3d(path, names, xyz, rate=100.0, units="mm  ", scale=1.0):
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


@pytest.fixture
def data():
    xyz = random_track(40, 3, seed=7)
    xyz[5, 1] = np.nan
    return ["a", "b", "c"], xyz


def test_c3d_matches_qtm(tmp_path, data):
    names, xyz = data
    (tmp_path / "q.tsv").write_text(qtm_text(names, xyz), newline="")
    qtm, _ = read_capture(tmp_path / "q.tsv")
    c3d_capture, _ = read_capture(write_c3d(tmp_path / "q.c3d", names, xyz))
    assert c3d_capture.marker_names == names
    assert c3d_capture.sample_rate_hz == pytest.approx(100.0)
    np.testing.assert_allclose(c3d_capture.xyz, qtm.xyz, atol=1e-3, equal_nan=True)
    np.testing.assert_allclose(c3d_capture.t, qtm.t, atol=1e-9)


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
