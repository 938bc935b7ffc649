"""The robot's vocabulary (`suds_exp.robot`) and the one way into a preprocessing version
(`get_version`), through the library and the CLI."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp import robot
from suds_exp.discrepancy import DiscrepancyOptions, run_discrepancy
from suds_exp.discrepancy.replay import make_windows
from suds_exp.errors import ConfigError
from suds_exp.ingest import ingest_paths
from suds_exp.preprocess import DEFAULTS, PreprocessError, get_version, preprocess
from suds_exp.store import Store
from suds_exp.testing.synthetic_captures import write_dataset

runner = CliRunner()


def test_gaits_follow_the_design_formula():
    theta = np.linspace(0, 2 * np.pi, 7)
    for gait, k in (("D+", 4), ("D-", 9), ("S+", -4), ("S-", -9)):
        want = np.stack(
            [np.cos(theta) + np.cos(3 * theta) / k, np.sin(theta) - np.sin(3 * theta) / k], -1
        )
        np.testing.assert_array_equal(robot.gait_shape(gait, theta), want)
    o = robot.gait_shape("O", [0.0, np.pi / 2])
    np.testing.assert_allclose(o, [[1, 0], [0, 1]], atol=1e-15)
    # the rate is the derivative of the shape
    h = 1e-6
    for gait in robot.GAITS:
        num = (robot.gait_shape(gait, theta + h) - robot.gait_shape(gait, theta - h)) / (2 * h)
        np.testing.assert_allclose(robot.gait_shape_rate(gait, theta), num, atol=1e-8)
    with pytest.raises(ConfigError, match="gait 'Q': expected one of S\\+, S-, O, D-, D\\+"):
        robot.gait_shape("Q", theta)


def test_one_id_parser_for_preprocess_and_discrepancy():
    assert robot.parse_ids("1-3,8") == [1, 2, 3, 8]
    assert robot.parse_ids(None) is None and robot.parse_ids(" ") is None
    for bad in ("a,b", "3-1", "0"):
        # the library names its parameter; the CLI names the flag (next test)
        with pytest.raises(ConfigError, match=f"^trials '{bad}'") as caught:
            robot.parse_ids(bad)
        assert caught.value.param == "trials"


def test_marker_roles_have_one_home():
    from suds_exp.ingest.layout import ROLES as ingest_roles
    from suds_exp.preprocess.shape import PASSIVE_ROLES
    from suds_exp.sim import MARKER_NAMES

    assert ingest_roles is robot.ROLES and MARKER_NAMES is robot.ROLES
    assert PASSIVE_ROLES is robot.PASSIVE_ROLES
    assert {seg for _, seg in robot.PASSIVE_ROLES} == {"head", "tail"}
    assert len(robot.ROLES) == 11 and robot.MAX_K == 12


# -- versions ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def two_versions(tmp_path_factory) -> Path:
    """Five synthetic trials (one per gait, 0.5 Hz, 4 cycles), preprocessed twice: ``v1``
    with the defaults and ``wide`` with a longer differentiator window."""
    folder = tmp_path_factory.mktemp("versions")
    manifest = write_dataset(folder / "data", frequencies=(0.5,), n_cycles=4)
    db = folder / "db.duckdb"
    store = Store(db)
    ingest_paths(store, [], manifest, progress=False)
    preprocess(store, progress=False)
    preprocess(store, name="wide", params={"sg_window_cycles": 0.3}, progress=False)
    return db


def test_get_version_finds_by_id_name_and_hash(two_versions, tmp_path):
    store = Store(two_versions)
    v1, wide = get_version(store, 1), get_version(store, "wide")
    assert (v1.name, wide.id) == ("v1", 2)
    assert get_version(store, wide.params_hash[:8]).id == 2
    assert wide.params["sg_window_cycles"] == 0.3 and wide.k == 4
    assert wide.pca is not None and wide.pca.n_components == 4 and wide.phasers
    samples = wide.samples(trials=[2, 3])
    assert sorted(samples.trial_id.unique()) == [2, 3]
    assert list(samples.columns[: len(robot.sample_columns(4))]) == robot.sample_columns(4)
    with pytest.raises(PreprocessError, match="name the preprocessing version to use"):
        get_version(store)
    with pytest.raises(PreprocessError, match="'nope' not found"):
        get_version(store, "nope")


def test_only_preprocess_reads_its_tables():
    """Every other package goes through `get_version` / `load_samples`, so a change of
    how a version is stored has one place to change."""
    import re

    root = Path(__file__).resolve().parents[1] / "suds_exp"
    table = re.compile(r"\bprep_(?:pca|fits|versions|trials)\b")
    # the reliability probe checks every table's unique keys in SQL, as a user could: it
    # reads the whole database, not a version
    whole_database = {"testing/reliability_probe.py"}
    readers = [
        str(p.relative_to(root))
        for p in root.rglob("*.py")
        if p.parent.name != "preprocess" and table.search(p.read_text())
    ]
    assert sorted(set(readers) - whole_database) == []


def test_unnamed_runs_started_in_the_same_second_get_names_of_their_own(
    two_versions, tmp_path, monkeypatch
):
    """The default name has a resolution of one second and names are unique (migration
    016): a second unnamed run in that second takes the next free name, not a refusal."""
    from suds_exp.discrepancy import workflow

    db = tmp_path / "db.duckdb"
    shutil.copyfile(two_versions, db)
    monkeypatch.setattr(workflow, "default_name", lambda when=None: "discrepancy-same-second")
    opts = DiscrepancyOptions(max_effects=0, refine=False)
    names = [run_discrepancy(Store(db), prep="v1", options=opts).name for _ in range(3)]
    assert names == [
        "discrepancy-same-second",
        "discrepancy-same-second-2",
        "discrepancy-same-second-3",
    ]


def test_replay_uses_the_versions_own_differentiator(two_versions, tmp_path):
    db = tmp_path / "db.duckdb"
    shutil.copyfile(two_versions, db)
    store = Store(db)
    opts = DiscrepancyOptions(max_effects=0, refine=False)
    frames = {}
    for ref in ("v1", "wide"):
        version = get_version(store, ref)
        diff = version.differentiator()
        result = run_discrepancy(store, prep=ref, options=opts)
        assert result.differentiator == diff
        windows = make_windows(version.samples(), differentiator=diff)
        frames[ref] = {g.diff_frames for g in windows.groups}
        assert frames[ref] == {diff.window(100.0, 0.5, 800)}
    # the window changed with the version, and the replay followed it
    assert frames["wide"] != frames["v1"]
    # samples without a store: the default parameters' differentiator, as preprocessing's
    alone = run_discrepancy(samples=get_version(store, "v1").samples(), options=opts)
    assert alone.differentiator == get_version(store, "v1").differentiator()
    assert alone.differentiator.kernel == DEFAULTS["sg_kernel"]


def test_campaign_and_discrepancy_name_the_version_they_lack(two_versions, tmp_path):
    db = tmp_path / "db.duckdb"
    shutil.copyfile(two_versions, db)
    for args in (["run", "c"], ["discrepancy", "--max-effects", "0"]):
        res = runner.invoke(app, [*args, "--db", str(db), "--prep", "nope"])
        assert res.exit_code == 2, res.output
        assert "'nope' not found; known versions: 1 (v1), 2 (wide)" in res.stderr
    for command in ("preprocess", "discrepancy"):
        res = runner.invoke(app, [command, "--db", str(db), "--trials", "2-x"])
        assert res.exit_code == 2, res.output
        want = "error: --trials '2-x': expected ids and ranges such as 1,2,5-8"
        assert res.stderr.strip() == want


def test_a_campaign_resolves_its_version_once_and_rewrites_no_option(
    two_versions, tmp_path, monkeypatch
):
    """`run_campaign` turns ``prep`` into a `Version` once, at the top, and passes its name
    and samples down: the version is looked up once and the caller's options stay as given."""
    import dataclasses

    from suds_exp.campaign import CampaignOptions, run_campaign
    from suds_exp.preprocess import version as version_module

    db = tmp_path / "db.duckdb"
    shutil.copyfile(two_versions, db)
    looked_up = []
    find = version_module.find_version_row
    monkeypatch.setattr(
        version_module,
        "find_version_row",
        lambda conn, ref: looked_up.append(ref) or find(conn, ref),
    )
    options = CampaignOptions(
        prep="wide",
        models=["phase-only"],
        boots=1,
        train_cycles=2,
        train_conditions="O@0.5",
        test_conditions="D+@0.5",
    )
    given = dataclasses.replace(options)
    summary = run_campaign(Store(db), "c", options, progress=False)
    assert summary.done_now == summary.total_jobs > 0
    assert looked_up == ["wide"]
    assert options == given
    stored = Store(db).query_df("SELECT prep_version FROM campaigns WHERE name = 'c'")
    assert stored.prep_version.tolist() == ["wide"]
