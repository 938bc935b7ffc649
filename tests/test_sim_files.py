"""Simulated capture files: QTM layout, determinism, and ingest round trip vs truth."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from suds_exp.ingest import ingest_paths, read_capture
from suds_exp.sim import (
    MARKER_NAMES,
    TRUTH_COLUMNS,
    SimConfig,
    simulate_dataset,
    truth_markers,
)
from suds_exp.store import Store

DESIGN = {"gaits": ("O", "D+"), "frequencies_hz": (1.0,), "repeats": 2, "cycles": (3, 5)}


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("sim")
    return simulate_dataset(out, seed=7, **DESIGN)


def test_writes_qtm_tsv_manifest_and_truth(dataset):
    assert len(dataset.tsv_paths) == 4
    lines = dataset.tsv_paths[0].read_bytes().split(b"\r\n")
    keys = [ln.split(b"\t")[0] for ln in lines[:12]]
    assert keys == [
        b"NO_OF_FRAMES",
        b"NO_OF_CAMERAS",
        b"NO_OF_MARKERS",
        b"FREQUENCY",
        b"NO_OF_ANALOG",
        b"ANALOG_FREQUENCY",
        b"DESCRIPTION",
        b"TIME_STAMP",
        b"DATA_INCLUDED",
        b"MARKER_NAMES",
        b"TRAJECTORY_TYPES",
        b"Frame",
    ]
    assert lines[9].decode().split("\t")[1:] == list(MARKER_NAMES)
    assert lines[12].startswith(b"1\t0.00000\t")
    manifest = pd.read_csv(dataset.manifest)
    assert list(manifest.columns) == ["file", "gait", "frequency_hz", "repeat", "notes"]
    assert sorted(manifest.gait.unique()) == ["D+", "O"]
    truth = pd.read_parquet(dataset.truth_paths[0])
    assert tuple(truth.columns) == TRUTH_COLUMNS
    n_frames = int(lines[0].split(b"\t")[1])
    assert len(truth) == n_frames


def test_same_seed_same_bytes_whatever_the_design(dataset, tmp_path):
    again = simulate_dataset(tmp_path / "a", seed=7, **DESIGN)
    for a, b in zip(
        dataset.tsv_paths + dataset.truth_paths, again.tsv_paths + again.truth_paths, strict=True
    ):
        assert a.read_bytes() == b.read_bytes()
    # one trial of the design alone: same files as inside the full design
    alone = simulate_dataset(
        tmp_path / "b", seed=7, gaits=("D+",), frequencies_hz=(1.0,), repeats=2, cycles=(3, 5)
    )
    by_name = {p.name: p for p in dataset.tsv_paths}
    for p in alone.tsv_paths:
        assert p.read_bytes() == by_name[p.name].read_bytes()
    other = simulate_dataset(tmp_path / "c", seed=8, **DESIGN)
    assert other.tsv_paths[0].read_bytes() != dataset.tsv_paths[0].read_bytes()


def test_ingested_markers_match_truth_up_to_noise(dataset, tmp_path):
    cfg = SimConfig()
    store = Store(tmp_path / "t.duckdb")
    results = ingest_paths(store, [], manifest=dataset.manifest, progress=False)
    assert len(results) == 4
    noise = cfg.measurement.noise_mm
    all_err = []
    truth_of = {p.name.removesuffix(".truth.parquet"): p for p in dataset.truth_paths}
    for res in results:
        truth_path = truth_of[res.path.stem]
        df = store.query_df(
            "select frame, marker, x, y, z, missing from markers where trial_id = ? "
            "order by frame, marker",
            [res.trial_id],
        )
        truth = pd.read_parquet(truth_path)
        expected = truth_markers(truth, cfg)  # (n, 11, 3)
        got = np.full_like(expected, np.nan)
        idx = {m: j for j, m in enumerate(MARKER_NAMES)}
        rows = df.frame.to_numpy() - df.frame.min()
        cols = df.marker.map(idx).to_numpy()
        got[rows, cols] = df[["x", "y", "z"]].to_numpy(dtype=float)
        err = np.linalg.norm(got - expected, axis=2)
        seen = ~np.isnan(err)
        assert seen.mean() > 0.97  # short dropouts only
        all_err.append(err[seen])
    err = np.concatenate(all_err)
    jumps = err > 9.0
    assert jumps.mean() < 1e-3  # rare jumps larger than 9 mm
    # 3-D Gaussian noise of sd `noise` per axis (+ 0.5 mm rounding of %.3f)
    assert np.sqrt(np.mean(err[~jumps] ** 2)) == pytest.approx(np.sqrt(3) * noise, rel=0.1)
    assert err[~jumps].max() < 8 * noise


def test_dropouts_are_written_as_zeros_and_read_as_missing(tmp_path):
    cfg = SimConfig()
    cfg.measurement.dropout_per_s = 0.5
    ds = simulate_dataset(
        tmp_path, cfg, gaits=("O",), frequencies_hz=(1.0,), repeats=1, cycles=(3, 3)
    )
    capture, _ = read_capture(ds.tsv_paths[0])
    assert capture.marker_names == list(MARKER_NAMES)
    assert capture.sample_rate_hz == 100
    missing = np.isnan(capture.xyz).all(axis=2)
    assert 0 < missing.mean() < 0.2
    assert b"\t0.000\t0.000\t0.000" in ds.tsv_paths[0].read_bytes()


def test_a_design_is_one_checked_value_that_simulates_as_its_keywords(tmp_path):
    from suds_exp.errors import ConfigError
    from suds_exp.sim import SimDesign
    from suds_exp.workflows.simulate import simulate_and_ingest

    design = SimDesign(["O", "D+"], [1], repeats=2, cycles=[3, 5], seed=7)
    assert design == SimDesign(("O", "D+"), (1.0,), 2, (3, 5), 7)
    assert design.frequencies_hz == (1.0,) and design.cycles == (3, 5)
    run = simulate_and_ingest(None, tmp_path / "a", design=design)
    again = simulate_dataset(tmp_path / "b", seed=7, **DESIGN)
    assert [p.read_bytes() for p in run.dataset.tsv_paths] == [
        p.read_bytes() for p in again.tsv_paths
    ]
    with pytest.raises(ConfigError, match=r"gaits \['O', 'X'\]: expected some of") as bad:
        SimDesign(("O", "X"))
    assert bad.value.param == "gaits"
    with pytest.raises(ConfigError, match=r"cycles \(5, 3\): expected 1 <= MIN <= MAX"):
        SimDesign(cycles=(5, 3))
