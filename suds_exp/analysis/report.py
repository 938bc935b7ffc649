"""The campaign report: figures, tables (CSV + Markdown) and one ``index.html`` page.

`write_report` is the whole of ``suds-exp report``; `report_tables` gives a notebook user
the same tables as DataFrames without writing files.
"""

from __future__ import annotations

import html
import re
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from suds_exp.analysis import plots
from suds_exp.analysis.categories import at_cycles, category_table, learner_order
from suds_exp.analysis.design_report import skipped_html, write_design_report
from suds_exp.analysis.findings import (
    FINDINGS_COLUMNS,
    findings_display,
    findings_headline,
    findings_table,
)
from suds_exp.analysis.formatting import (
    ReportTables,
    not_computed_html,
    to_html,
    to_markdown,
    write_missing,
    write_table,
)
from suds_exp.analysis.glm import LEVEL_NAMES, REFERENCE, glm_table
from suds_exp.analysis.momentum_info import momentum_section
from suds_exp.analysis.paper import agreement_summary, compare_glm, compare_iqr, paper_table
from suds_exp.analysis.passive import (
    PASSIVE_EXPLANATION,
    campaign_passive_information,
    passive_display,
    passive_reason,
)
from suds_exp.analysis.queries import load_results
from suds_exp.analysis.spread import PAIRS, iqr_table, slope_table
from suds_exp.errors import AnalysisError
from suds_exp.experiment import ExperimentDesign, is_paper
from suds_exp.ingest import design_for
from suds_exp.store import Store
from suds_exp.store.files import check_writable

_SAFE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._+-]*$")
#: The columns of ``results_labelled`` the report's tables and figures read: the findings'
#: (`FINDINGS_COLUMNS`, but the campaign's name, which is given) and the categories' and
#: spread's two more. `write_report` loads no others (at 10M results a column of numbers
#: or of label references is 80 MB).
REPORT_COLUMNS = tuple(c for c in FINDINGS_COLUMNS if c != "campaign") + ("freq_sim", "ln_rmse_vx")


def report_tables(
    results: pd.DataFrame,
    n_cycles: int | None = None,
    paper_dir: Path | None = None,
    upper_from: int | None = None,
    pairs: str = "same-condition",
    findings_boot: int = 400,
    campaign: str | None = None,
) -> ReportTables:
    """Every table of the report, from labelled results (see `load_results`; the
    columns `REPORT_COLUMNS` are enough, with ``campaign`` given).

    Keys: ``findings`` (the paper's findings F1-F10, see `findings_table`, with
    ``findings_boot`` bootstrap replicates), ``categories``, ``glm`` (100 ln scale),
    ``glm_rmse`` (mm/s), ``iqr``, ``slopes``,
    and, when the paper's tables are found (in ``paper_dir``, which must hold them, or
    else in the default folder, which may not), ``compare_glm``
    (both scales, column ``scale``), ``compare_iqr`` and ``agreement``. A part that the
    results cannot support (no same-condition pairs, too few results for a GLM) is left
    out, and ``missing`` says why. ``pairs``: see `iqr_table`. ``campaign``: the name
    the findings' seed mixes in (default the ``campaign`` column's first value).
    """
    if pairs not in PAIRS:
        raise AnalysisError(f"pairs {pairs}: expected one of {', '.join(PAIRS)}", param="pairs")
    tables = ReportTables()
    tables.attempt(
        "findings",
        lambda: findings_table(
            results, n_boot=findings_boot, upper_from=upper_from, campaign=campaign
        ),
    )
    tables.attempt("categories", lambda: category_table(results, n_cycles))
    tables.attempt("glm", lambda: glm_table(results, n_cycles, response="log"))
    tables.attempt("glm_rmse", lambda: glm_table(results, n_cycles, response="rmse"))
    tables.attempt(
        ("iqr", "slopes"),
        lambda: (iqr_table(results, pairs), slope_table(results, upper_from, pairs)),
    )
    if "glm" not in tables:  # the comparison is of GLM terms and IQRs: nothing to compare
        tables.missing["compare_glm"] = tables.missing["agreement"] = tables.missing["glm"]
        return tables
    try:
        paper_glm, paper_iqr = paper_table("glm", paper_dir), paper_table("iqr", paper_dir)
    except AnalysisError:
        if paper_dir is not None:  # asked for by name: say it is not there
            raise
        return tables
    tables["compare_glm"] = pd.concat(
        [
            compare_glm(tables["glm"], paper_glm).assign(scale="100 ln"),
            compare_glm(tables["glm_rmse"], paper_glm).assign(scale="mm/s"),
        ],
        ignore_index=True,
    )
    iqr = tables.get("iqr", pd.DataFrame(columns=["frequency_hz", "model", "n_cycles", "iqr"]))
    tables["compare_iqr"] = compare_iqr(iqr, paper_iqr)
    log_part = tables["compare_glm"][tables["compare_glm"]["scale"] == "100 ln"]
    rmse_part = tables["compare_glm"][tables["compare_glm"]["scale"] == "mm/s"]
    summary = agreement_summary(log_part, tables["compare_iqr"])
    rmse_summary = agreement_summary(rmse_part, tables["compare_iqr"].iloc[:0])
    rmse_summary["table"] += " (mm/s scale)"
    tables["agreement"] = pd.concat([summary, rmse_summary], ignore_index=True)
    return tables


def iqr_wide(iqr: pd.DataFrame) -> dict[float, pd.DataFrame]:
    """The spread table as the paper prints it: per frequency, learners by training size."""
    out = {}
    for freq, g in iqr.groupby("frequency_hz"):
        wide = g.pivot(index="model", columns="n_cycles", values="iqr")
        wide = wide.loc[learner_order(wide.index)]
        wide.columns = [str(c) for c in wide.columns]
        out[freq] = wide.reset_index()
    return out


_PAIRS_TEXT = {
    "same-condition": "Results trained and tested on the same condition (gait and frequency)",
    "same-frequency": "Results trained and tested at the same frequency, gait pairings pooled",
}

_NAV = (
    '<p><a href="#findings">findings</a> | <a href="#categories">box plots</a> | '
    '<a href="#glm">GLM</a> | '
    '<a href="#spread">spread</a> | <a href="#efficiency">sample efficiency</a> | '
    '<a href="#paper">beside the paper</a></p>'
)

_CSS = """
body { font-family: sans-serif; max-width: 1400px; margin: 1em auto; padding: 0 1em; color: #222; }
img { max-width: 100%; border: 1px solid #ddd; margin: 0.5em 0; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 2px 6px; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
th { background: #f0f0f0; }
code { background: #f4f4f4; padding: 0 3px; }
.note { color: #555; }
"""


def _files(links: dict[str, Path]) -> str:
    return " ".join(
        f'<a href="{html.escape(p.name)}">{html.escape(p.name)}</a>' for p in links.values()
    )


def write_report(
    store: Store,
    campaign: str,
    out_dir: str | Path | None = None,
    *,
    paper_dir: Path | None = None,
    n_cycles: int | None = None,
    upper_from: int | None = None,
    pairs: str = "same-condition",
    design: ExperimentDesign | None = None,
    n_boot: int = 400,
) -> Path:
    """Write the report of ``campaign`` into ``out_dir`` (default ``reports/<campaign>``).

    Files: ``boxplot_frequency.png``, ``boxplot_gait.png``, ``boxplot_combined.png``,
    ``sample_efficiency.png``; ``findings``, ``categories``, ``glm``, ``glm_rmse``, ``iqr``,
    ``slopes``,
    ``compare_glm``, ``compare_iqr``, ``agreement`` as ``.csv`` and ``.md``; and
    ``index.html``, which shows them all and loads nothing from the network.

    Parameters
    ----------
    store : Store
    campaign : str
    out_dir : path, optional
    paper_dir : path, optional
        Folder of the paper's ``glm_table.csv`` / ``iqr_table.csv`` (default: see
        `suds_exp.analysis.paper.default_paper_dir`); without them the comparison is skipped.
    n_cycles : int, optional
        Training size of the box plots and GLMs (default the campaign's most common).
    upper_from : int, optional
        First training size of the slope fits (default the median size).
    pairs : {"same-condition", "same-frequency"}
        Train/test pairs of the spread table and sample-efficiency figure (see `iqr_table`).
    design : ExperimentDesign, optional
        The experiment's axes (`suds_exp.experiment`); None: the design stored with the
        data at ingest (`suds_exp.ingest.stored_design`), which a design given here
        overrides (keeping the levels code added to it, `suds_exp.ingest.design_for`).
        The paper's: this report; another writes
        `suds_exp.analysis.design_report.write_design_report`.
    n_boot : int
        Bootstrap replicates of the findings' intervals and of what the passive shape
        adds (`findings_table`, `passive_information`); 0: no intervals.

    Returns
    -------
    Path of ``index.html``.
    """
    if not isinstance(n_boot, int) or n_boot < 0:
        raise AnalysisError(f"n_boot {n_boot!r}: expected an integer >= 0", param="n_boot")
    out = _report_folder(campaign, out_dir)
    design = design_for(store, design)
    if not is_paper(design):
        return write_design_report(store, campaign, design, out, n_cycles)
    results = load_results(store, campaign, columns=REPORT_COLUMNS)
    _, size = at_cycles(results, n_cycles)
    out.mkdir(parents=True, exist_ok=True)
    tables = report_tables(results, size, paper_dir, upper_from, pairs, n_boot, campaign)

    figures = plots.category_boxplots(results, out, size)
    if "iqr" in tables:
        figures["sample_efficiency"] = plots.efficiency_figure(
            tables["iqr"], tables["slopes"], out / "sample_efficiency.png"
        )

    files = _write_tables(tables, out)
    page = _page(campaign, store, results, size, tables, figures, files, pairs)
    passive = campaign_passive_information(store, campaign, n_boot=n_boot)
    passive_files = (
        write_table(passive, out, "passive_information", 3, to_markdown(passive_display(passive)))
        if not passive.empty
        else {}
    )
    findings = (
        _findings_html(tables["findings"], files["findings"])
        if "findings" in tables
        else '<h2 id="findings">The paper\'s findings</h2>\n'
        + not_computed_html(tables.missing["findings"], files["findings"])
    )
    findings += _passive_html(passive, passive_files) + momentum_section(store, campaign, out)
    page = page.replace(_FINDINGS_SLOT, findings, 1)
    page = page.replace(_SKIPPED_SLOT, skipped_html(store, campaign), 1)
    index = out / "index.html"
    index.write_text(page, encoding="utf-8")
    return index


def _report_folder(campaign: str, out_dir: str | Path | None) -> Path:
    """``out_dir``, or ``reports/<campaign>`` when the name is a safe folder name; checked
    writable before anything is computed."""
    if out_dir is None:
        if not _SAFE_NAME.match(campaign):
            raise AnalysisError(
                f"campaign {campaign!r} is not a safe folder name; pass out DIR", param="out"
            )
        out_dir = Path("reports") / campaign
    out = Path(out_dir)
    check_writable(out, "out: report folder", AnalysisError, param="out")
    return out


def _write_tables(tables: ReportTables, out: Path) -> dict[str, dict[str, Path]]:
    """Each report table as CSV and Markdown in ``out`` (the IQR table one Markdown
    table per frequency), and a Markdown note for each missing one (`write_missing`);
    returns each table's files by name."""
    files: dict[str, dict[str, Path]] = write_missing(tables.missing, out)
    digits = {"compare_iqr": 2, "iqr": 3, "slopes": 3, "agreement": 2}
    for name, frame in tables.items():
        md = to_markdown(findings_display(frame)) if name == "findings" else None
        if name == "iqr":
            md = "".join(
                f"### IQR of RMS error of vx (mm/s) at {plots.frequency_name(f)} Hz\n\n"
                f"{to_markdown(w)}\n"
                for f, w in iqr_wide(frame).items()
            )
        files[name] = write_table(frame, out, name, digits.get(name, 2), md)
    return files


_FINDINGS_SLOT = "<!-- findings -->"
_SKIPPED_SLOT = "<!-- skipped cells -->"


def _findings_html(table: pd.DataFrame, files: dict[str, Path]) -> str:
    a = table.attrs
    return "\n".join(
        [
            '<h2 id="findings">The paper\'s findings</h2>',
            f"<p><b>{html.escape(findings_headline(table))}.</b></p>",
            '<p class="note">Each of the paper\'s findings (F1-F10; F8 and F9 in parts) as '
            "one statistic of these results with a 95 % bootstrap interval (draws resampled "
            f"with every learner paired, seed {a['seed']}). holds: the whole interval is on "
            "the paper's side of the threshold; unclear: the value is, the interval is not "
            "all; fails: the value is on the other side; not measurable: the campaign lacks "
            "the data (reason given). Ratios are of median RMS errors of vx; same-condition "
            f"pairs at the main size ({a['main_cycles']} cycles) unless said. The "
            "documentation (docs/explanation/findings.md) defines every statistic.</p>",
            to_html(findings_display(table)),
            f"<p>Files (with each statistic's definition): {_files(files)}</p>",
        ]
    )


def _passive_html(table: pd.DataFrame, files: dict[str, Path]) -> str:
    """The passive-information section (`passive_information`) beside the findings."""
    head = '<h3 id="passive-information">What the passive shape adds</h3>'
    if table.empty:
        return f"\n{head}\n<p>Not measurable: {html.escape(passive_reason(table))}.</p>"
    return "\n".join(
        [
            "",
            head,
            f'<p class="note">{html.escape(PASSIVE_EXPLANATION)}</p>',
            to_html(passive_display(table)),
            f"<p>Files: {_files(files)}</p>",
        ]
    )


def _reference_note(refs: dict[str, str]) -> str:
    """Says whether the reference levels are the paper's, and why not when they are not."""
    paper = {k: LEVEL_NAMES[(k, v)] for k, v in REFERENCE.items()}
    if refs == paper:
        return "These are the paper's reference levels."
    notes = []
    for key, name in paper.items():
        if key not in refs:
            notes.append(f"{key} has one level in these results and is left out")
        elif refs[key] != name:
            notes.append(f"{name} is absent from these results, so {refs[key]} is the reference")
    return (
        "<b>Not the paper's references:</b> "
        + _esc_join(notes)
        + "; terms of that factor are not comparable with the paper's."
    )


def _esc_join(items: list[str]) -> str:
    return "; ".join(html.escape(i) for i in items)


def _page(campaign, store, results, size, tables, figures, files, pairs) -> str:
    parts = _head(campaign, store, results, size)
    parts += _categories_section(tables, figures, files)
    parts += _glm_section(tables, files, size)
    parts += _spread_section(tables, figures, files, pairs)
    parts += _paper_section(tables, files)
    parts.append("</body></html>")
    return "\n".join(parts)


def _head(campaign, store, results, size) -> list[str]:
    esc = html.escape
    models = ", ".join(learner_order(results["model"]))
    sizes = ", ".join(str(v) for v in sorted(results["n_cycles"].unique()))
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>suds-exp report: {esc(campaign)}</title><style>{_CSS}</style></head><body>",
        f"<h1>Campaign <code>{esc(campaign)}</code></h1>",
        f"<p>{len(results)} results from <code>{esc(str(store.path))}</code>; "
        f"learners {esc(models)}; "
        f"training sizes (cycles) {esc(sizes)}. Box plots and GLMs use the {size}-cycle results. "
        f"Written {datetime.now(UTC):%Y-%m-%d %H:%M} UTC.</p>",
        _SKIPPED_SLOT,
        _NAV,
        _FINDINGS_SLOT,
        '<h2 id="categories">1. Log RMS error by similarity category</h2>',
        '<p class="note">Gait similarity: steps between training and test gait on the axis '
        "S+, S-, O, D-, D+ (same 0, near 1, far more than 1). Frequency: same or different "
        "training and test frequency. Box plots with matplotlib's default parameters.</p>",
    ]
    return parts


def _categories_section(tables, figures, files) -> list[str]:
    esc = html.escape
    parts = []
    for key in ("boxplot_frequency", "boxplot_gait", "boxplot_combined"):
        parts.append(f'<img src="{esc(figures[key].name)}" alt="{esc(key)}">')
    parts.append("<h3>Numbers behind the box plots (ln of mm/s)</h3>")
    if "categories" not in tables:
        return [*parts, not_computed_html(tables.missing["categories"], files["categories"])]
    parts += [
        f"<p>Files: {_files(files['categories'])}</p>",
        to_html(tables["categories"], 3),
    ]
    return parts


def _glm_section(tables, files, size) -> list[str]:
    esc = html.escape
    if "glm" not in tables:
        return [
            '<h2 id="glm">2. GLM of log RMS error</h2>',
            not_computed_html(tables.missing["glm"], files["glm"]),
        ]
    glm = tables["glm"]
    refs = glm.attrs["reference"]
    parts = [
        '<h2 id="glm">2. GLM of log RMS error</h2>',
        f"<p>Response: <code>y = {esc(glm.attrs['response'])}</code> (a coefficient of -10 is "
        "about 10 % less error; independent of the error's unit). Gaussian GLM, identity link, "
        f"{glm.attrs['n_rows']} learner results at {size} cycles, phase-only left out "
        "(it has neither SUDS nor GMR and would count as TLS). 95 % confidence intervals; "
        "terms sorted by magnitude after the intercept.</p>",
        f"<p>Reference levels: TLS (SUDS = GMR = 0), {esc(', '.join(refs.values()))}. "
        + _reference_note(refs)
        + "</p>",
    ]
    aliased = sorted({t for terms in glm.attrs["aliased"].values() for t in terms})
    if aliased:
        parts.append(
            '<p class="note"><b>Not estimable from these results</b> (a category combination '
            "is missing, or two predictors are always equal), left blank: "
            + ", ".join(esc(t) for t in aliased)
            + ".</p>"
        )
    for label in ("direct", "interactions"):
        parts += [
            f"<h3>{'Direct effects' if label == 'direct' else 'First-order interactions'}</h3>",
            f"<p><code>{esc(glm.attrs['formulas'][label])}</code></p>",
            to_html(glm[glm["model"] == label].drop(columns="model"), 2),
        ]
    parts += [f"<p>Files: {_files(files['glm'])}</p>"]
    raw = tables["glm_rmse"]
    parts += [
        "<h3>The same GLMs on the RMS error itself (mm/s)</h3>",
        '<p class="note">The paper reads its coefficients as fractions of the intercept '
        "(e.g. -47.53 / 91.36 as a 52 % reduction), i.e. as linear in RMS error; these fits "
        "let that reading be checked. Their size depends on the unit.</p>",
    ]
    for label in ("direct", "interactions"):
        parts.append(to_html(raw[raw["model"] == label].drop(columns="model"), 2))
    parts.append(f"<p>Files: {_files(files['glm_rmse'])}</p>")

    return parts


def _spread_section(tables, figures, files, pairs) -> list[str]:
    esc = html.escape
    parts = []
    parts.append('<h2 id="spread">3. Spread: IQR of RMS error of vx</h2>')
    if "iqr" in tables:
        parts.append(
            f'<p class="note">{_PAIRS_TEXT[pairs]}, by learner (rows) and training cycles '
            "(columns); mm/s.</p>"
        )
        for freq, wide in iqr_wide(tables["iqr"]).items():
            parts += [f"<h3>{plots.frequency_name(freq)} Hz</h3>", to_html(wide, 2)]
        parts.append(f"<p>Files (long form, with quartiles and counts): {_files(files['iqr'])}</p>")
        parts += [
            '<h2 id="efficiency">4. Sample efficiency</h2>',
            f'<img src="{esc(figures["sample_efficiency"].name)}" alt="sample_efficiency">',
            '<p class="note">Median (line) and IQR (band) of the RMS error against training '
            "cycles, log-log. Slope: least squares of ln RMS error on ln cycles over the "
            "upper range of training sizes, with 95 % interval (-0.5 is the rate of averaging "
            "white noise).</p>",
            to_html(tables["slopes"], 3),
            f"<p>Files: {_files(files['slopes'])}</p>",
        ]
    else:
        parts.append(
            f"<p>No spread table and no sample-efficiency figure ({esc(pairs)} pairs).</p>"
            + not_computed_html(tables.missing["iqr"], files["iqr"])
        )

    return parts


def _paper_section(tables, files) -> list[str]:
    parts = []
    parts.append('<h2 id="paper">5. Beside the paper</h2>')
    if "compare_glm" in tables:
        parts += [
            '<p class="note">The paper\'s rows with our numbers beside them. Sign agreement per '
            "term; rank = place by magnitude within its model (GLM, intercept not ranked) or "
            "by IQR among the learners at one frequency and training size (1 = smallest). "
            "Kendall's tau compares the two orderings. Magnitudes are not comparable across "
            "units; signs and orderings are.</p>",
            to_html(tables["agreement"], 2),
            f"<p>Files: {_files(files['agreement'])}</p>",
            "<h3>GLM</h3>",
            to_html(tables["compare_glm"], 2),
            f"<p>Files: {_files(files['compare_glm'])}</p>",
            "<h3>IQR</h3>",
            to_html(tables["compare_iqr"], 2),
            f"<p>Files: {_files(files['compare_iqr'])}</p>",
        ]
    elif "compare_glm" in tables.missing:
        parts.append(not_computed_html(tables.missing["compare_glm"], files["compare_glm"]))
    else:
        parts.append(
            "<p>The paper's tables were not found (pass <code>--paper DIR</code>); "
            "no comparison.</p>"
        )
    return parts
