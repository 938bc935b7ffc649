"""Your experiment's own conditions: a declared design (TOML), a manifest with user gaits
and two numeric axes, a campaign on it that resumes, and its report; the paper's design
as the default; bad input refused in one line with the database unchanged."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from suds_exp.analysis import load_results, write_report
from suds_exp.analysis.design_tables import (
    axis_category_table,
    design_glm_table,
    design_iqr_table,
    label_pairs,
)
from suds_exp.campaign import KEY_COLUMNS, TIMING_COLUMNS, CampaignOptions, run_campaign
from suds_exp.errors import ConfigError, IngestError
from suds_exp.experiment import PAPER_DESIGN, classify, load_design, pair_column
from suds_exp.ingest import ingest_paths, read_manifest
from suds_exp.preprocess import get_version, preprocess
from suds_exp.store import Store

#: The user's gaits (none of the paper's), the simulated gait each is run with, and a
#: second numeric axis beside the frequency (an amplitude, here a property of the gait).
USER_GAITS = {"wave-1": ("O", 1.0), "wave-2": ("D+", 2.0), "turn": ("S-", 1.0)}
EXPERIMENT = """
[[axis]]
name = "gait"
kind = "ordered"
levels = ["wave-1", "wave-2", "turn"]

[[axis]]
name = "frequency_hz"
kind = "numeric"

[[axis]]
name = "amplitude"
kind = "numeric"
"""
OPTIONS = dict(models=["phase-only", "TLS"], boots=2, train_cycles=3, sweep=[1, 2])


def user_manifest(data: Path, extra: dict | None = None) -> Path:
    """The simulator's manifest rewritten with the user's gait names and an amplitude."""
    by_sim = {sim: (name, amp) for name, (sim, amp) in USER_GAITS.items()}
    with open(data / "manifest.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    out = data / "user_manifest.csv"
    with open(out, "w", newline="") as fh:
        fields = ["file", "gait", "frequency_hz", "amplitude", "repeat", "notes", *(extra or {})]
        writer = csv.DictWriter(fh, fields)
        writer.writeheader()
        for row in rows:
            name, amp = by_sim[row["gait"]]
            writer.writerow({**row, "gait": name, "amplitude": amp, **(extra or {})})
    return out


@pytest.fixture(scope="module")
def experiment(tmp_path_factory):
    """A simulated dataset (3 gaits x 2 frequencies x 2 repeats, 6-8 cycles) ingested as
    the user's experiment and preprocessed: (store, design, samples, folder)."""
    from suds_exp.sim import simulate_dataset

    work = tmp_path_factory.mktemp("experiment")
    sims = tuple(sim for sim, _ in USER_GAITS.values())
    simulate_dataset(work, gaits=sims, frequencies_hz=(0.5, 1.0), repeats=2, cycles=(6, 8), seed=3)
    (work / "experiment.toml").write_text(EXPERIMENT)
    design = load_design(work / "experiment.toml")
    store = Store(work / "user.duckdb")
    ingest_paths(store, [], user_manifest(work), progress=False, design=design)
    samples = get_version(store, preprocess(store, progress=False).name).samples()
    return store, design, samples, work


def results(store: Store, campaign: str) -> pd.DataFrame:
    frame = store.query_df("SELECT * FROM results WHERE campaign = ?", [campaign])
    return frame.drop(columns=list(TIMING_COLUMNS)).sort_values(
        list(KEY_COLUMNS), ignore_index=True
    )


def test_the_manifest_stores_user_gaits_and_axis_values(experiment):
    store, design, samples, _ = experiment
    labels = sorted(samples["gait"].unique())
    assert labels == sorted(f"gait={g};amplitude={a:g}" for g, (_, a) in USER_GAITS.items())
    values = store.query_df("SELECT label, axis, kind, value FROM condition_values ORDER BY ALL")
    assert set(values.axis) == {"gait", "frequency_hz", "amplitude"}
    assert set(values[values.axis == "gait"].value) == set(USER_GAITS)
    assert set(values[values.axis == "frequency_hz"].value) == {"0.5", "1"}
    axes = store.query_df("SELECT axis, kind, levels FROM experiment_axes ORDER BY position")
    assert axes.axis.tolist() == ["gait", "frequency_hz", "amplitude"]
    assert json.loads(axes.levels[0]) == ["wave-1", "wave-2", "turn"]


def test_a_user_design_campaign_runs_resumes_and_reports(experiment, tmp_path):
    store, design, samples, _ = experiment
    first = run_campaign(store, "user", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    # 6 conditions: 36 pairs x 2 boots + 6 same-condition pairs x 2 boots x 2 sweep sizes
    assert first.total_jobs == (36 * 2 + 6 * 2 * 2) * 2 and first.failed_now == 0
    full = results(store, "user")
    # an interrupted run: some finished rows only, then the run resumes
    with store.write() as conn:
        conn.exec_driver_sql("DELETE FROM results WHERE campaign = 'user' AND boot = 1")
    again = run_campaign(store, "user", samples=samples, progress=False)
    assert again.done_before == len(full) // 2 and again.done_now == len(full) // 2
    pd.testing.assert_frame_equal(results(store, "user"), full, check_exact=True)

    labelled = label_pairs(load_results(store, "user"), design)
    # the SQL view gives every result's category along each axis, as Python does
    sql = store.query_df("SELECT * FROM results_axis_pairs WHERE campaign = 'user'")
    assert len(sql) == 3 * len(full)
    merged = sql.merge(labelled, on=list(KEY_COLUMNS))
    for axis in design.axes:
        part = merged[merged.axis == axis.name]
        assert (part["category"] == part[pair_column(axis)]).all()
    assert set(labelled.gait_pair) == {"same", "near", "far"}
    assert set(labelled.amplitude_pair) == {"same", "lower", "higher"}

    out = tmp_path / "report"
    index = write_report(store, "user", out, design=design)
    assert index.is_file()
    for axis in ("gait", "frequency_hz", "amplitude"):
        assert (out / f"boxplot_{axis}.png").stat().st_size > 1000
    glm = pd.read_csv(out / "glm.csv")
    terms = set(glm.term)
    assert {"gait=same", "gait=far", "frequency_hz=same", "frequency_hz=higher"} <= terms
    assert any(t.startswith("amplitude=") for t in terms)
    assert "model-gait near data-gait" not in index.read_text()
    assert (out / "sample_efficiency.png").stat().st_size > 1000
    slopes = pd.read_csv(out / "slopes.csv")
    assert len(slopes) == 6 * 2 and set(slopes.cycles_to) == {3}
    iqr = pd.read_csv(out / "iqr.csv")
    assert set(iqr.n_cycles) == {1, 2, 3} and (iqr.iqr >= 0).all()
    assert len(iqr[["condition", "frequency_hz"]].drop_duplicates()) == 6


def test_design_tables_group_by_the_declared_axes(experiment):
    store, design, samples, _ = experiment
    run_campaign(store, "user", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    res = load_results(store, "user")
    cats = axis_category_table(res, design)
    assert cats.axis.unique().tolist() == ["gait", "frequency_hz", "amplitude"]
    assert cats[cats.axis == "gait"].category.unique().tolist() == ["same", "near", "far"]
    glm = design_glm_table(res, design)
    assert glm.attrs["reference"] == {"gait": "near", "frequency_hz": "lower", "amplitude": "lower"}
    assert "C(gait_pair, Treatment(reference='near'))" in glm.attrs["formulas"]["direct"]
    iqr = design_iqr_table(res, design)
    one = res[(res.train_gait == res.test_gait) & (res.model == "TLS") & (res.n_cycles == 3)]
    one = one[one.train_frequency_hz == one.test_frequency_hz]
    cond = one.iloc[0]
    rows = one[
        (one.test_gait == cond.test_gait) & (one.test_frequency_hz == cond.test_frequency_hz)
    ]
    got = iqr[
        (iqr.condition == cond.test_gait)
        & (iqr.frequency_hz == round(cond.test_frequency_hz, 6))
        & (iqr.model == "TLS")
        & (iqr.n_cycles == 3)
    ]
    assert got["median"].item() == pytest.approx(np.median(rows.rmse_vx), rel=1e-12)


def test_conditions_of_a_user_design_are_named_by_their_labels(experiment):
    store, design, samples, _ = experiment
    spec = "gait=wave-1;amplitude=1@0.5,gait=turn;amplitude=1"
    options = CampaignOptions(**{**OPTIONS, "train_conditions": spec, "test_conditions": spec})
    summary = run_campaign(store, "some", options, samples=samples, progress=False)
    assert summary.failed_now == 0
    got = set(results(store, "some").train_gait)
    assert got == {"gait=wave-1;amplitude=1", "gait=turn;amplitude=1"}


# -- the paper's design is the default -------------------------------------------------


def test_the_paper_design_classifies_pairs_as_results_labelled(db):
    from suds_exp.testing.synthetic_samples import synthetic_samples

    store = Store(db)
    run_campaign(
        store, "p", CampaignOptions(**OPTIONS), samples=synthetic_samples(), progress=False
    )
    res = label_pairs(load_results(store, "p"), PAPER_DESIGN)
    assert (res["gait_pair"] == res["gait_sim"]).all()
    period = res["frequency_hz_pair"].map({"same": "=", "lower": ">", "higher": "<"})
    assert (period == res["period_rel"]).all()
    assert load_design(None) is PAPER_DESIGN
    assert [a.name for a in PAPER_DESIGN.axes] == ["gait", "frequency_hz"]
    assert PAPER_DESIGN.axis("gait").levels == ("S+", "S-", "O", "D-", "D+")
    assert PAPER_DESIGN.label({"gait": "D-", "frequency_hz": 0.5}) == "D-"


def test_classify_along_each_kind():
    from suds_exp.experiment import Axis

    ordered = Axis("g", "ordered", ("a", "b", "c"))
    assert [classify(ordered, "a", x) for x in "abc"] == ["same", "near", "far"]
    numeric = Axis("f", "numeric")
    assert [classify(numeric, 1 / 3, x) for x in (0.333333, 0.5, 0.25)] == [
        "same",
        "lower",
        "higher",
    ]
    unordered = Axis("u", "unordered", ("x", "y"))
    assert [classify(unordered, "x", v) for v in "xy"] == ["same", "different"]


# -- bad input ---------------------------------------------------------------------------


def _tables(store: Store) -> dict[str, int]:
    names = ("trials", "markers", "trial_conditions", "experiment_axes", "experiment_levels")
    return {t: int(store.query_df(f"SELECT count(*) AS n FROM {t}").n[0]) for t in names}


def test_an_unknown_axis_in_a_manifest_is_one_line_and_changes_nothing(experiment):
    store, design, _, work = experiment
    before = _tables(store)
    manifest = user_manifest(work, extra={"temperature": "20"})
    with pytest.raises(IngestError) as err:
        ingest_paths(store, [], manifest, progress=False, design=design)
    message = str(err.value)
    assert "\n" not in message
    assert str(manifest) in message and "'temperature'" in message
    assert "gait, frequency_hz, amplitude" in message
    assert _tables(store) == before


def test_a_level_not_declared_is_refused_naming_line_and_axis(experiment, tmp_path):
    _, design, _, work = experiment
    manifest = user_manifest(work)
    text = manifest.read_text().replace(",turn,", ",crawl,", 1)
    bad = work / "bad_level.csv"
    bad.write_text(text)
    with pytest.raises(
        IngestError,
        match=r"bad_level\.csv: line \d+: gait 'crawl' is not a "
        r"declared level; expected one of wave-1, wave-2, turn$",
    ):
        read_manifest(bad, design)
    text = manifest.read_text().replace(",1.0,", ",big,", 1)
    (work / "bad_number.csv").write_text(text)
    with pytest.raises(IngestError, match=r"amplitude 'big': expected a number$"):
        read_manifest(work / "bad_number.csv", design)


@pytest.mark.parametrize(
    ("toml", "message"),
    [
        (
            '[[axis]]\nname = "gait"\nkind = "sorted"\nlevels = ["a", "b"]\n',
            r"axis 'gait': kind 'sorted'; expected one of ordered, numeric, unordered$",
        ),
        (
            '[[axis]]\nname = "gait"\nkind = "ordered"\n',
            r"axis 'gait': levels: expected a list of at least two names$",
        ),
        (
            '[[axis]]\nname = "speed"\nkind = "numeric"\nlevels = ["a"]\n',
            r"axis 'speed': a numeric axis has no levels$",
        ),
        ('[[axis]]\nname = "file"\nkind = "numeric"\n', r"'file' is a manifest column"),
        (
            '[[axis]]\nname = "g"\nkind = "unordered"\nlevels = ["a;b", "c"]\n',
            r"level 'a;b' contains one of",
        ),
        ('[[axes]]\nname = "g"\n', r"unknown entry 'axes'"),
        (
            '[[axis]]\nname = "g"\nkind = "ordered"\nlevels = ["a", "b"]\nstep = 1\n',
            r"axis 1: unknown key 'step'",
        ),
        ("[[axis]\n", r"not valid TOML"),
    ],
)
def test_bad_experiment_descriptions_are_one_line_naming_file_and_entry(tmp_path, toml, message):
    path = tmp_path / "exp.toml"
    path.write_text(toml)
    with pytest.raises(ConfigError, match=message) as err:
        load_design(path)
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)


# -- recordings without conditions ---------------------------------------------------------


def test_recordings_without_conditions_run_leave_one_trial_out(tmp_path):
    from suds_exp.sim import simulate_dataset

    ds = simulate_dataset(tmp_path, gaits=("O",), frequencies_hz=(0.5,), repeats=3, cycles=(6, 7))
    manifest = tmp_path / "plain.csv"
    table = pd.read_csv(ds.manifest)[["file", "frequency_hz", "repeat"]]
    table.to_csv(manifest, index=False)
    (tmp_path / "none.toml").write_text("# no condition axes\n")
    design = load_design(tmp_path / "none.toml")
    assert design.axes == () and design.by_trial
    store = Store(tmp_path / "plain.duckdb")
    ingest_paths(store, [], manifest, progress=False, design=design)
    samples = get_version(store, preprocess(store, progress=False).name).samples()
    assert set(samples.gait) == {"all"}
    options = CampaignOptions(models=["phase-only", "TLS"], boots=3, train_cycles=3, sweep=[2])
    run_campaign(store, "loto", options, samples=samples, progress=False)
    rows = results(store, "loto")
    trials = sorted(store.query_df("SELECT id FROM trials").id)
    for _, draw in rows.groupby(["boot", "n_cycles"]):
        assert draw.test_trial.nunique() == 1
    # each boot tests on its own trial: all three trials are left out once per size
    for _, size in rows[rows.model == "TLS"].groupby("n_cycles"):
        assert sorted(size.test_trial) == trials
    for row in rows.itertuples():
        assert row.test_trial not in json.loads(row.train_trials)
    index = write_report(store, "loto", tmp_path / "report", design=design)
    assert "leave-one-trial-out" in index.read_text()
    iqr = pd.read_csv(tmp_path / "report" / "iqr.csv")
    assert set(iqr.n_cycles) == {2, 3} and set(iqr.condition) == {"all"}


def test_the_cli_takes_an_experiment_on_ingest_and_report(experiment, tmp_path):
    from typer.testing import CliRunner

    import cli

    store, design, samples, work = experiment
    run_campaign(store, "user", CampaignOptions(**OPTIONS), samples=samples, progress=False)
    db = str(store.path)
    runner = CliRunner()
    before = _tables(store)
    bad = user_manifest(work, extra={"temperature": "20"})
    args = ["ingest", "--manifest", str(bad), "--experiment", str(work / "experiment.toml")]
    got = runner.invoke(cli.app, [*args, "--db", db])
    assert got.exit_code == 2 and len(got.output.strip().splitlines()) == 1
    assert "'temperature'" in got.output
    assert _tables(store) == before
    (work / "bad.toml").write_text('[[axis]]\nname = "gait"\nkind = "sorted"\n')
    got = runner.invoke(
        cli.app, ["report", "user", "--experiment", str(work / "bad.toml"), "--db", db]
    )
    assert got.exit_code == 2 and "kind 'sorted'" in got.output
    out = tmp_path / "cli_report"
    got = runner.invoke(
        cli.app,
        [
            "report",
            "user",
            "--experiment",
            str(work / "experiment.toml"),
            "--out",
            str(out),
            "--db",
            db,
        ],
    )
    assert got.exit_code == 0, got.output
    assert (out / "boxplot_amplitude.png").is_file() and (out / "glm.csv").is_file()
