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
