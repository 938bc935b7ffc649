"""`suds-exp report` end to end on a synthetic campaign: files, figures, HTML, errors."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.image import imread
from typer.testing import CliRunner

from cli import app
from suds_exp.store import Store
from suds_exp.testing.synthetic_results import synthetic_results

runner = CliRunner()
FIGURES = ["boxplot_frequency", "boxplot_gait", "boxplot_combined", "sample_efficiency"]
PAPER = Path(__file__).resolve().parents[2] / "shared" / "paper"
#: the comparisons with the paper's tables need its CSVs in ../shared/paper
TABLES = ["categories", "glm", "glm_rmse", "iqr", "slopes"] + (
    ["compare_glm", "compare_iqr", "agreement"] if PAPER.is_dir() else []
)


def cli(*args):
    return runner.invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """A campaign (full grid at 1-30 cycles, the paper's GLM planted) reported through the
    CLI with the default --out, from a scratch working folder."""
    work = tmp_path_factory.mktemp("report")
    db = work / "r.duckdb"
    store = Store(db)
    rows = synthetic_results("demo", n_boot=1, n_cycles=(1, 2, 4, 8, 16, 30), seed=12)
    with store.write() as conn:
        store.insert_df(conn, "results", rows)
    here = Path.cwd()
    os.chdir(work)
    try:
        result = cli("report", "demo", "--db", db, "--json")
    finally:
        os.chdir(here)
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    index = work / doc["index"] if not Path(doc["index"]).is_absolute() else Path(doc["index"])
    assert index == work / "reports" / "demo" / "index.html"
    return {"db": db, "index": index, "files": doc["files"]}


def test_every_figure_and_table_is_written(report):
    names = set(report["files"])
    assert {f"{f}.png" for f in FIGURES} <= names
    assert {f"{t}.{ext}" for t in TABLES for ext in ("csv", "md")} <= names
    for t in TABLES:
        table = pd.read_csv(report["index"].parent / f"{t}.csv")
        assert len(table) > 0, t
        md = (report["index"].parent / f"{t}.md").read_text()
        assert md.lstrip().startswith(("|", "###")) and "|---" in md, t


def test_every_png_opens_and_has_content(report):
    for name in FIGURES:
        image = imread(report["index"].parent / f"{name}.png")
        assert image.ndim == 3 and image.shape[0] > 300 and image.shape[1] > 300, name
        assert image[..., :3].std() > 0.05, name  # not a blank canvas


def test_html_references_only_local_files_that_exist(report):
    page = report["index"].read_text()
    refs = re.findall(r'(?:src|href)="([^"]*)"', page)
    assert {f"{f}.png" for f in FIGURES} <= set(refs)
    for ref in refs:
        if ref.startswith("#"):  # a section of the page itself
            assert f'id="{ref[1:]}"' in page, ref
            continue
        assert "/" not in ref and ":" not in ref, ref  # no network, no paths outside the folder
        assert (report["index"].parent / ref).is_file(), ref
    assert "url(" not in page and "@import" not in page and "<script" not in page
    for term in (
        "model-period&lt;data-period",
        "SUDS:GMR",
        "Treatment(reference=&#x27;near&#x27;)",
    ):
        assert term in page


def test_comparison_with_the_paper_uses_its_rows(report):
    if not PAPER.is_dir():
        pytest.skip("../shared/paper is not present beside the repository")
    out = report["index"].parent
    paper_glm = pd.read_csv(PAPER / "glm_table.csv")
    paper_iqr = pd.read_csv(PAPER / "iqr_table.csv")
    glm = pd.read_csv(out / "compare_glm.csv")
    for _, part in glm.groupby("scale"):
        assert (
            part[["model", "term"]].values.tolist() == paper_glm[["model", "term"]].values.tolist()
        )
        np.testing.assert_array_equal(part["paper_coef"], paper_glm["coef"])
    # The synthetic campaign has the paper's interaction coefficients planted (100 ln
    # scale, noise sd 30, 900 learner results at 30 cycles): every term the paper found
    # larger than 15 must come back with its sign.
    ours = glm[(glm["scale"] == "100 ln") & (glm["model"] == "interactions")]
    big = ours[(ours["paper_coef"].abs() > 15) & (ours["term"] != "Intercept")]
    assert len(big) == 7 and big["sign_agree"].all(), big
    iqr = pd.read_csv(out / "compare_iqr.csv")
    assert len(iqr) == len(paper_iqr)
    have = iqr["iqr"].notna()
    assert set(iqr.loc[have, "n_cycles"]) == {1, 2, 4, 8, 30}  # ours that the paper has too
    assert iqr.loc[have, "rank_agree"].notna().all()


def test_user_errors_exit_2_with_one_line(report, tmp_path):
    db = report["db"]
    cases = [
        (["report", "nope", "--db", db, "--out", tmp_path / "a"], "campaign 'nope'"),
        (["report", "demo", "--db", db, "--out", tmp_path / "b", "--cycles", "7"], "--cycles 7"),
        (["report", "demo", "--db", db, "--out", tmp_path / "c", "--pairs", "x"], "--pairs x"),
        (
            ["report", "demo", "--db", db, "--out", tmp_path / "d", "--paper", tmp_path],
            "pass --paper",
        ),
        (["report", "a/b", "--db", db], "safe folder name"),
        (["report", "demo", "--db", db, "--out", tmp_path / "e", "--boots", "-1"], "--boots -1"),
    ]
    for args, message in cases:
        result = cli(*args)
        assert result.exit_code == 2, (args, result.output)
        assert message in result.output, (message, result.output)
        assert len(result.output.strip().splitlines()) == 1


def test_boots_sets_the_findings_replicates(report, tmp_path):
    """--boots 0: the findings without intervals (the default has them), the rest alike."""
    result = cli("report", "demo", "--db", report["db"], "--out", tmp_path, "--boots", "0")
    assert result.exit_code == 0, result.output
    quick = pd.read_csv(tmp_path / "findings.csv")
    default = pd.read_csv(report["index"].parent / "findings.csv")
    measured = default["low"].notna()
    assert measured.any() and quick.loc[measured, "low"].isna().all()
    pd.testing.assert_series_equal(quick["value"], default["value"])
    for name in ("glm", "categories", "iqr"):
        pd.testing.assert_frame_equal(
            pd.read_csv(tmp_path / f"{name}.csv"),
            pd.read_csv(report["index"].parent / f"{name}.csv"),
        )


def _browser() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        if path := shutil.which(name):
            return path
    return None


def _screenshot(browser: str, page: Path, shot: Path) -> np.ndarray:
    subprocess.run(
        [
            browser,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            f"--screenshot={shot}",
            "--window-size=1400,9000",
            page.as_uri(),
        ],
        check=True,
        capture_output=True,
        timeout=120,
    )
    return (imread(shot)[..., :3] * 255).round().astype(int)


def _pixels_near(image: np.ndarray, rgb: tuple[int, int, int], tol: int = 12) -> int:
    return int((np.abs(image - np.array(rgb)).max(axis=-1) <= tol).sum())


@pytest.mark.slow
def test_headless_browser_screenshot_shows_the_figures(report, tmp_path):
    browser = _browser()
    if browser is None:
        pytest.skip("no chromium / chrome installed (make test-slow installs Debian's chromium)")
    shot = _screenshot(browser, report["index"], tmp_path / "page.png")
    # The figures' own colours: matplotlib's orange box-plot medians (C1) and the purple
    # GMR+SUDS curve of the sample-efficiency figure (C4). The page itself has neither,
    # as the control with every image link broken shows.
    broken = tmp_path / "broken"
    shutil.copytree(report["index"].parent, broken)
    (broken / "index.html").write_text(report["index"].read_text().replace('.png"', '.missing"'))
    control = _screenshot(browser, broken / "index.html", tmp_path / "control.png")
    orange, purple = (255, 127, 14), (148, 103, 189)
    assert _pixels_near(shot, orange) > 500
    assert _pixels_near(shot, purple) > 500
    assert _pixels_near(control, orange) == 0 and _pixels_near(control, purple) == 0


def test_a_sparse_campaign_still_reports_and_says_what_it_could_not_estimate(tmp_path):
    # Two learners whose SUDS and GMR flags always agree, two gaits two steps apart (no
    # 'near' pair, the paper's reference), two frequencies, a small same-condition sweep.
    rows = synthetic_results("small", n_boot=2, models=("TLS", "GMR+SUDS"), n_cycles=(2, 4, 8))
    keep = (
        rows["train_gait"].isin(["O", "D+"])
        & rows["test_gait"].isin(["O", "D+"])
        & rows["train_frequency_hz"].isin([0.5, 1.0])
        & rows["test_frequency_hz"].isin([0.5, 1.0])
    )
    rows = rows[keep]
    same = (rows["train_gait"] == rows["test_gait"]) & (
        rows["train_frequency_hz"] == rows["test_frequency_hz"]
    )
    rows = rows[(rows["n_cycles"] == 8) | same]
    store = Store(tmp_path / "s.duckdb")
    with store.write() as conn:
        store.insert_df(conn, "results", rows)
    result = cli("report", "small", "--db", store.path, "--out", tmp_path / "rep")
    assert result.exit_code == 0, result.output
    glm = pd.read_csv(tmp_path / "rep" / "glm.csv")
    blank = glm[glm["coef"].isna()]
    assert set(blank["term"]) == {
        "GMR",
        "SUDS:GMR",
        "GMR:(model-period<data-period)",
        "GMR:(model-period=data-period)",
        "GMR:(model-gait=data-gait)",
    }
    assert glm.loc[glm["coef"].notna(), "ci_low"].notna().all()
    page = (tmp_path / "rep" / "index.html").read_text()
    assert "Not the paper's references" in page and "Not estimable" in page
    for ref in re.findall(r'(?:src|href)="([^"#]*)"', page):
        assert (tmp_path / "rep" / ref).is_file(), ref


def test_the_report_columns_alone_give_the_tables_of_every_column(report):
    """`write_report` loads `REPORT_COLUMNS` only: every table (findings with their
    seeded intervals included) is the one of the frame with all analysis columns."""
    from suds_exp.analysis import load_results, report_tables
    from suds_exp.analysis.report import REPORT_COLUMNS

    store = Store(report["db"])
    full = report_tables(load_results(store, "demo"), findings_boot=20)
    few = load_results(store, "demo", columns=REPORT_COLUMNS)
    assert "campaign" not in few and "gait_steps" not in few
    lean = report_tables(few, findings_boot=20, campaign="demo")
    assert list(lean) == list(full) and lean.missing == full.missing
    for name in full:
        pd.testing.assert_frame_equal(lean[name], full[name], check_exact=True)
