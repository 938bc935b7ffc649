"""Capture files in the exporters' own layouts, written from marker arrays.

Each writer takes marker names and tracks ``xyz`` (n_frames, n_markers, 3) in mm, NaN
where a marker was not seen, and writes the file a motion-capture system would export:
C3D, OpenSim TRC, Vicon Nexus CSV, OptiTrack Motive CSV (QTM TSV text is
`synthetic_captures.qtm_text`). Use them with `synthetic_captures.random_track` or a
`SyntheticTrial`'s ``xyz`` to test a reader against a known truth.
"""

from __future__ import annotations

import io
import warnings

import numpy as np


def write_c3d(path, names, xyz, rate=100.0, units="mm  ", scale=1.0):
    """Write a C3D file of marker tracks; returns ``path``.

    ``xyz`` is (n_frames, n_markers, 3) in mm divided by ``scale`` on writing (NaN = an
    invalid point, residual -1); ``names`` the n_markers labels; ``rate`` in Hz; ``units``
    the POINT:UNITS string (4 characters, as Vicon pads it).
    """
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
    """One frame's coordinates as text cells, an empty cell for NaN."""
    return ["" if np.isnan(v) else f"{v / scale:.6f}" for v in frame.reshape(-1)]


def write_trc(path, names, xyz, rate=100.0, units="mm", scale=1.0, first=1):
    """Write a TRC file laid out as OpenSim documents it (a blank line before the frames).

    ``xyz`` (n_frames, n_markers, 3) mm, divided by ``scale`` and written in ``units``;
    ``rate`` Hz; frames numbered from ``first``. Returns ``path``.
    """
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
    """Write a Vicon Nexus CSV: a Devices block, then Trajectories with subject-prefixed
    names (``Robot:m``), CRLF line ends.

    ``xyz`` (n_frames, n_markers, 3) mm, divided by ``scale`` and labelled ``units``;
    ``rate`` Hz; frames numbered from ``first``. Returns ``path``.
    """
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
    """Write an OptiTrack Motive 1.23 CSV in metres, a rigid body's columns before the
    markers (``Sub:m``).

    ``xyz`` (n_frames, n_markers, 3) mm; ``rate`` Hz. Returns ``path``.
    """
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
