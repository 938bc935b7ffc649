"""Gait files (CSV / Fourier TOML), the SE(2) integral, and bad input through the CLI."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.errors import ConfigError
from suds_exp.gait.motion import cycle_motion, integrate_twists, relative
from suds_exp.gait.shape import FourierGait, ellipse, read_gait_file
from suds_exp.testing.database import assert_same_db, dump_db

runner = CliRunner()


def write_csv(path: Path, theta, phi1, phi2) -> Path:
    rows = ["phase_rad,phi1_rad,phi2_rad"] + [
        f"{t:.6f},{a:.6f},{b:.6f}" for t, a, b in zip(theta, phi1, phi2, strict=True)
    ]
    path.write_text("\n".join(rows) + "\n")
    return path


def circle_csv(path: Path, n=64, radius=1.0, **kw) -> Path:
    theta = 2 * np.pi * np.arange(n) / n
    return write_csv(path, theta, radius * np.cos(theta), radius * np.sin(theta), **kw)


def test_csv_and_toml_give_the_same_ellipse(tmp_path):
    theta = 2 * np.pi * np.arange(90) / 90
    csv = write_csv(tmp_path / "e.csv", theta, 1.2 * np.cos(theta), 1.2 * np.sin(theta + 0.5))
    toml = tmp_path / "e.toml"
    toml.write_text(ellipse(1.2, 1.2, 0.5, name="e").to_toml())
    a, b = read_gait_file(csv), read_gait_file(toml)
    probe = np.linspace(0, 2 * np.pi, 37)
    assert a.name == "e.csv" and b.name == "e.toml"
    np.testing.assert_allclose(a.shape(probe), b.shape(probe), atol=2e-4)
    np.testing.assert_allclose(a.rate(probe), b.rate(probe), atol=5e-3)
    # the Fourier file round-trips exactly
    assert isinstance(b, FourierGait)
    np.testing.assert_allclose(b.shape(probe)[:, 1], 1.2 * np.sin(probe + 0.5), atol=1e-9)


@pytest.mark.parametrize(
    "make, words",
    [
        (
            lambda p: write_csv(
                p,
                *(lambda t: (t, np.cos(t), np.sin(t)))(
                    np.r_[np.linspace(0, 2.0, 20, endpoint=False), np.linspace(4.0, 6.2, 20)]
                ),
            ),
            "gap of",
        ),
        (
            lambda p: write_csv(
                p, *(lambda t: (t, t / 3, np.sin(t)))(2 * np.pi * np.arange(60) / 60)
            ),
            "ends do not meet",
        ),
        (lambda p: circle_csv(p, radius=2.2), "beyond the bound 2 rad"),
        (
            lambda p: write_csv(
                p, *(lambda t: (t[::-1], np.cos(t), np.sin(t)))(2 * np.pi * np.arange(30) / 30)
            ),
            "phase order",
        ),
    ],
    ids=["gap", "not-periodic", "beyond-bound", "out-of-order"],
)
def test_bad_gait_files_are_one_line_and_leave_the_db_unchanged(tmp_path, db, make, words):
    bad = make(tmp_path / "bad.csv")
    with pytest.raises(ConfigError, match=words):
        read_gait_file(bad)
    assert runner.invoke(app, ["init", "--db", str(db)]).exit_code == 0
    before = dump_db(db)
    for args in (
        ["gait", "predict", "--gait-file", str(bad)],
        ["simulate", "--out", str(tmp_path / "o"), "--gait-file", str(bad), "--ingest"],
    ):
        r = runner.invoke(app, [*args, "--db", str(db)])
        assert r.exit_code == 2, r.output
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and "bad.csv" in lines[0]
        assert words in lines[0]
    assert_same_db(before, dump_db(db))


def test_the_bound_is_a_parameter(tmp_path):
    p = circle_csv(tmp_path / "c.csv", radius=1.5)
    assert read_gait_file(p).max_abs() == pytest.approx(1.5, abs=1e-3)
    with pytest.raises(
        ConfigError, match="c.csv: an angle reaches 1.500 rad, beyond the bound 1.3"
    ):
        read_gait_file(p, bound=1.3)


def test_toml_errors_name_the_file(tmp_path):
    p = tmp_path / "g.toml"
    # one table a joint: a file of [phi1] alone is a one-joint gait; a loose
    # value where a joint's table belongs is refused
    p.write_text("phi1 = 1.0\n[phi2]\nsin = [1.0]\n")
    with pytest.raises(ConfigError, match=r"g.toml: entry 'phi1' is not a table; expected one"):
        read_gait_file(p)
    p.write_text('name = "x"\n')
    with pytest.raises(ConfigError, match=r"g.toml: no joint; expected one table a joint"):
        read_gait_file(p)
    p.write_text("[phi1]\ncos = [1.0]\n")
    assert read_gait_file(p).joints == ("phi1",)
    p.write_text("[phi1]\ncos = ['a']\n[phi2]\nsin = [1.0]\n")
    with pytest.raises(ConfigError, match="lists of numbers"):
        read_gait_file(p)


def test_se2_integral_of_a_constant_twist_is_a_circle_arc():
    # vx = 10 mm/s, wz = pi/10 rad/s for 10 s: half a circle of radius 10/(pi/10)
    dt, n = 0.01, 1001
    poses = integrate_twists(np.tile([10.0, 0.0, math.pi / 10], (n, 1)), dt)
    r = 10 / (math.pi / 10)
    np.testing.assert_allclose(poses[-1], [0.0, 2 * r, math.pi], atol=1e-6)
    # relative motion is frame-independent
    np.testing.assert_allclose(relative(poses[0], poses[-1]), poses[-1], atol=1e-9)


def test_cycle_motion_is_in_the_frame_at_the_cycle_start():
    # straight 5 mm per cycle along a body turned by 90 degrees in the world
    t = np.arange(0, 301)
    poses = np.c_[np.zeros_like(t, float), 5.0 * t / 100, np.full(len(t), math.pi / 2)]
    m = cycle_motion(poses, 100, (0, 1, 2))
    assert m.forward_mm == pytest.approx(5.0)
    assert m.lateral_mm == pytest.approx(0.0, abs=1e-9)
