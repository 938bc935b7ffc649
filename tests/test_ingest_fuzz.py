"""Random and mutated files fed to every reader: ingest, or raise IngestError, nothing else."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from suds_exp.errors import IngestError
from suds_exp.ingest import read_capture
from suds_exp.ingest.csv_reader import write_marker_csv
from suds_exp.testing.capture_files import write_c3d, write_motive, write_trc, write_vicon
from suds_exp.testing.synthetic_captures import qtm_text, random_track

FUZZ = settings(max_examples=120, deadline=None, suppress_health_check=list(HealthCheck))


def _seed_files() -> dict[str, bytes]:
    names, xyz = ["a", "b"], random_track(12, 2, seed=11)
    xyz[3, 0] = np.nan
    folder = Path(tempfile.mkdtemp())
    (folder / "s.tsv").write_text(qtm_text(names, xyz), newline="")
    capture, _ = read_capture(folder / "s.tsv")
    write_marker_csv(folder / "s.csv", capture)
    write_c3d(folder / "s.c3d", names, xyz)
    seeds = {ext: (folder / f"s{ext}").read_bytes() for ext in (".tsv", ".csv", ".c3d")}
    for name, write in (
        ("s.trc", write_trc),
        ("vicon.csv", write_vicon),
        ("motive.csv", write_motive),
    ):
        seeds[name] = write(folder / name, names, xyz).read_bytes()
    return seeds


SEEDS = _seed_files()

mutation = st.one_of(
    st.tuples(st.just("delete"), st.integers(0, 10_000), st.integers(1, 200)),
    st.tuples(st.just("insert"), st.integers(0, 10_000), st.binary(min_size=1, max_size=40)),
    st.tuples(st.just("replace"), st.integers(0, 10_000), st.binary(min_size=1, max_size=8)),
    st.tuples(st.just("truncate"), st.integers(0, 10_000), st.just(b"")),
    st.tuples(
        st.just("insert"),
        st.integers(0, 10_000),
        st.sampled_from([b"\t", b"\n", b"\r\n", b",", b"-", b"nan", b"1e400", b"0\t0\t0"]),
    ),
)


def _mutate(data: bytes, ops) -> bytes:
    for op, where, arg in ops:
        where = where % (len(data) + 1)
        if op == "delete":
            data = data[:where] + data[where + arg :]
        elif op == "insert":
            data = data[:where] + arg + data[where:]
        elif op == "replace":
            data = data[:where] + arg + data[where + len(arg) :]
        else:
            data = data[:where]
    return data


def _read_or_ingest_error(tmp: Path, ext: str, data: bytes) -> None:
    path = tmp / f"f{ext}"
    path.write_bytes(data)
    try:
        capture, digest = read_capture(path)
    except IngestError as exc:
        assert str(exc).startswith(str(path)), str(exc)
        assert "\n" not in str(exc)
        return
    assert capture.n_frames > 0 and len(digest) == 64
    assert capture.xyz.shape == (capture.n_frames, len(capture.marker_names), 3)


@FUZZ
@given(seed=st.sampled_from(sorted(SEEDS)), ops=st.lists(mutation, min_size=1, max_size=4))
def test_mutated_files_ingest_or_raise_ingest_error(tmp_path_factory, seed, ops):
    ext = Path(seed).suffix or seed
    _read_or_ingest_error(tmp_path_factory.mktemp("fuzz"), ext, _mutate(SEEDS[seed], ops))


@FUZZ
@given(ext=st.sampled_from([".tsv", ".csv", ".c3d", ".trc"]), data=st.binary(max_size=2000))
def test_random_bytes_ingest_or_raise_ingest_error(tmp_path_factory, ext, data):
    _read_or_ingest_error(tmp_path_factory.mktemp("rand"), ext, data)


@FUZZ
@given(ext=st.sampled_from([".tsv", ".csv", ".trc"]), text=st.text(max_size=600))
def test_random_text_ingest_or_raise_ingest_error(tmp_path_factory, ext, text):
    _read_or_ingest_error(
        tmp_path_factory.mktemp("text"), ext, text.encode("utf-8", "surrogatepass")
    )
