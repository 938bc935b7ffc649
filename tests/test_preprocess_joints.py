"""Segment origins (the motor axes) from trials that do not pin them down.

One gait whose shape loop is a circle (O: phi1 = cos, phi2 = sin) leaves the constant-
distance fit of the motor axes nearly free along one direction, and marker noise then
biases it (errors in variables): about 3 mm too far apart on the simulated robot, which
shrinks every joint angle by about 1.5 %. The run must say so, and a known distance
between the motor axes must remove the bias.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.commands.simulate import simulate_command
from suds_exp.errors import ConfigError
from suds_exp.preprocess import preprocess
from suds_exp.preprocess.truth import truth_errors
from suds_exp.sim.dataset import SimDesign
from suds_exp.store import Store

#: the simulated robot's distance between its motor axes (SimConfig.geometry), mm
MIDDLE_MM = 100.0


def simulated(folder: Path, gaits) -> Store:
    store = Store(folder / "sim.duckdb")
    simulate_command(
        folder / "data", store=store, design=SimDesign(gaits, repeats=1, cycles=(4, 4))
    )
    return store


@pytest.fixture(scope="module")
def one_loop(tmp_path_factory) -> Store:
    return simulated(tmp_path_factory.mktemp("joints-o"), ("O",))


def test_one_circular_gait_warns_and_a_known_distance_fixes_the_angles(one_loop):
    fitted = preprocess(one_loop, name="fitted", progress=False)
    (warning,) = fitted.warnings
    assert "segment origins" in warning and "joint_distance_mm" in warning
    err_fitted = truth_errors(one_loop, fitted.version_id).set_index("trial_id").loc[-1]
    assert err_fitted.err_ra > 0.01  # rad: the bias the warning is about

    known = preprocess(
        one_loop, name="known", params={"joint_distance_mm": MIDDLE_MM}, progress=False
    )
    assert known.warnings == []
    err_known = truth_errors(one_loop, known.version_id).set_index("trial_id").loc[-1]
    assert err_known.err_ra < 0.005
    assert err_known.err_vx < err_fitted.err_vx
    state = one_loop.query_df(
        "SELECT f.state FROM prep_fits f JOIN prep_versions v ON v.id = f.version_id "
        "WHERE v.name = 'known' AND f.kind = 'joints'"
    ).state.iloc[0]
    assert json.loads(state)["length_mm"] == MIDDLE_MM


def test_gaits_that_pin_the_axes_down_give_no_warning(tmp_path):
    store = simulated(tmp_path, ("O", "D+"))
    result = preprocess(store, progress=False)
    assert result.warnings == []
    assert truth_errors(store, result.version_id).set_index("trial_id").loc[-1].err_ra < 0.005


def test_the_command_prints_the_warning_and_takes_the_distance(one_loop, tmp_path):
    db = tmp_path / "copy.duckdb"
    store = Store(db)
    simulate_command(
        tmp_path / "data", store=store, design=SimDesign(("O",), repeats=1, cycles=(4, 4))
    )
    runner = CliRunner()
    out = runner.invoke(app, ["preprocess", "--db", str(db)])
    assert out.exit_code == 0, out.output
    assert "warning: segment origins" in out.stderr
    out = runner.invoke(
        app, ["preprocess", "--db", str(db), "--param", f"joint_distance_mm={MIDDLE_MM}"]
    )
    assert out.exit_code == 0, out.output
    assert "warning" not in out.stderr


@pytest.mark.parametrize("value", ["-5", "far"])
def test_a_distance_that_is_not_positive_is_refused_and_nothing_is_written(one_loop, value):
    before = one_loop.query_df("SELECT count(*) AS n FROM prep_versions").n.iloc[0]
    with pytest.raises(ConfigError, match="joint_distance_mm"):
        preprocess(one_loop, params={"joint_distance_mm": value}, progress=False)
    assert one_loop.query_df("SELECT count(*) AS n FROM prep_versions").n.iloc[0] == before


def _swimmer_description(folder: Path, length: str = "") -> Path:
    """The built-in swimmer description, its middle segment's length given or not."""
    from importlib import resources

    text = resources.files("suds_exp.body").joinpath("swimmer.toml").read_text()
    text = text.replace("from_joints = true\n", f"from_joints = true\n{length}", 1)
    path = folder / "swimmer.toml"
    path.write_text(text)
    return path


def test_a_body_description_warns_too_and_takes_the_middle_segments_length(one_loop, tmp_path):
    from suds_exp.body import SegmentModel, load_body, preprocess_body

    # the generic segment model (the swimmer's description through it)
    generic = {"tail_fit": "rigid", "body_fit": "segments"}
    fitted = preprocess(
        one_loop,
        name="generic",
        params=generic,
        body=SegmentModel(load_body(_swimmer_description(tmp_path))),
        progress=False,
    )
    (warning,) = fitted.warnings
    assert "segments.middle" in warning and "length_mm" in warning
    known = load_body(_swimmer_description(tmp_path, f"length_mm = {MIDDLE_MM}\n"))
    given = preprocess(
        one_loop, name="generic-known", params=generic, body=SegmentModel(known), progress=False
    )
    assert given.warnings == []
    errors = truth_errors(one_loop, given.version_id).set_index("trial_id").loc[-1]
    assert errors.err_ra < 0.005
    # the swimmer's description goes to the standard pipeline, with the length as its
    # joint_distance_mm
    standard = preprocess_body(one_loop, known, name="body-known", progress=False)
    assert standard.params["joint_distance_mm"] == MIDDLE_MM
    assert standard.warnings == []


@pytest.mark.parametrize("line", ["length_mm = -3\n", "length_mm = 'long'\n", "length_mm = true\n"])
def test_a_bad_segment_length_is_one_line(tmp_path, line):
    from suds_exp.body import load_body
    from suds_exp.body.description import BodyError

    with pytest.raises(BodyError, match=r"segments\.middle\.length_mm"):
        load_body(_swimmer_description(tmp_path, line))
