"""`preprocess --body`: the swimmer's description changes nothing; a chain gives shape
modes, phase and body velocity; a description naming an unknown marker is refused."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.ingest import ingest_paths
from suds_exp.preprocess import load_samples
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db
from suds_exp.testing.synthetic_captures import write_dataset

runner = CliRunner()


def cli(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_swimmer_description_gives_the_same_version_and_samples(tmp_path):
    manifest = write_dataset(tmp_path / "data", gaits=("O", "S+"), frequencies=(0.5,), n_cycles=3)
    plain, described = tmp_path / "a.duckdb", tmp_path / "b.duckdb"
    ingest_paths(Store(plain), [], manifest, progress=False)
    shutil.copyfile(plain, described)
    a = cli("preprocess", "--db", plain, "--json")
    b = cli("preprocess", "--db", described, "--body", "swimmer", "--json")
    assert a.exit_code == 0 and b.exit_code == 0, (a.output, b.output)
    assert json.loads(a.stdout)["params_hash"] == json.loads(b.stdout)["params_hash"]
    left, right = load_samples(Store(plain), 1), load_samples(Store(described), 1)
    assert len(left) > 0
    assert left.equals(right)


def _snake_csv(path: Path, f_hz=1.5, speed=300.0, rate=100.0, seconds=4.0, n=10) -> Path:
    """A serpenoid wave travelling head to tail along a body gliding at ``speed`` mm/s."""
    length, amp = 800.0, 0.6
    s = np.linspace(0.0, length, 200)
    t = np.arange(int(seconds * rate)) / rate
    theta = amp * np.sin(2 * np.pi * (s[None, :] / length - f_hz * t[:, None]))
    ds = s[1] - s[0]
    # body points from the head back: head at x = speed * t
    back = np.cumsum(np.stack([np.cos(theta), np.sin(theta)], axis=2) * ds, axis=1)
    back -= back[:, :1]
    head = np.column_stack([speed * t, np.zeros_like(t)])
    xy = head[:, None, :] - back
    pick = np.linspace(0, len(s) - 1, n).round().astype(int)
    pts = xy[:, pick]
    names = [f"m{i:02d}" for i in range(1, n + 1)]
    cols = ["frame", "t"] + [f"{m}_{a}" for m in names for a in "xyz"]
    rows = [
        [str(i + 1), f"{ti:.4f}"] + [f"{v:.3f}" for p in pts[i] for v in (p[0], p[1], 100.0)]
        for i, ti in enumerate(t)
    ]
    path.write_text("\n".join([",".join(cols)] + [",".join(r) for r in rows]) + "\n")
    return path


def _chain_toml(path: Path, names: list[str], modes: int = 4) -> Path:
    path.write_text(
        f'name = "test snake"\n[chain]\nmarkers = {json.dumps(names)}\nmodes = {modes}\n'
    )
    return path


def test_chain_gives_shape_modes_phase_rate_and_forward_velocity(tmp_path):
    db = tmp_path / "s.duckdb"
    assert cli("ingest", _snake_csv(tmp_path / "snake.csv"), "--db", db).exit_code == 0
    body = _chain_toml(tmp_path / "snake.toml", [f"m{i:02d}" for i in range(1, 11)])
    out = cli("preprocess", "--body", body, "--param", "jump_mm=30", "--db", db, "--json")
    assert out.exit_code == 0, out.output
    doc = json.loads(out.stdout)
    # a travelling wave is two standing waves a quarter period apart: two modes
    assert sum(doc["explained_variance_ratio"][:2]) > 0.9
    samples = load_samples(Store(db), doc["version_id"])
    inner = samples.iloc[50:-50]
    rate = abs(np.polyfit(inner.t, inner.phase, 1)[0]) / (2 * np.pi)
    assert rate == pytest.approx(1.5, rel=0.03)
    # the body glides forward (+x of the body frame) at about 300 mm/s
    assert inner.vx.mean() == pytest.approx(300.0, rel=0.15)
    assert abs(inner.vy.mean()) < 0.2 * inner.vx.mean()


def test_chain_naming_an_unknown_marker_is_refused(tmp_path):
    db = tmp_path / "s.duckdb"
    assert cli("ingest", _snake_csv(tmp_path / "snake.csv"), "--db", db).exit_code == 0
    before = dump_db(db)
    body = _chain_toml(tmp_path / "bad.toml", ["m01", "m02", "zz", "m04", "m05"], modes=3)
    out = cli("preprocess", "--body", body, "--db", db)
    assert out.exit_code == 2
    message = out.stderr.strip()
    assert len(message.splitlines()) == 1
    assert "bad.toml: marker 'zz' is unknown to trial 1" in message, message
    assert_same_db(before, dump_db(db))


def test_missing_body_file_is_one_line(tmp_path):
    out = cli("preprocess", "--body", tmp_path / "nope.toml", "--db", tmp_path / "x.duckdb")
    assert out.exit_code == 2 and "nope.toml: body description not found" in out.stderr


def test_chain_refuses_a_reduction_other_than_pca(tmp_path):
    # a chain's ra_1, ra_2 are its first two PCA modes (the travelling wave Phaser reads):
    # another reducer would silently not be used, so it is refused by name
    db = tmp_path / "s.duckdb"
    assert cli("ingest", _snake_csv(tmp_path / "snake.csv"), "--db", db).exit_code == 0
    before = dump_db(db)
    body = _chain_toml(tmp_path / "snake.toml", [f"m{i:02d}" for i in range(1, 11)])
    out = cli("preprocess", "--body", body, "--param", "reduction=autoencoder", "--db", db)
    assert out.exit_code == 2
    message = out.stderr.strip()
    assert len(message.splitlines()) == 1, message
    assert "snake.toml: reduction 'autoencoder'" in message and "pca" in message, message
    assert_same_db(before, dump_db(db))
