"""The report of a campaign on a user's experiment design (`suds_exp.experiment`).

`write_report` hands over here when given a design other than the paper's: the paper's
findings and its comparison tables are about its gait and frequency axes, so this report
holds what any design supports: box plots per declared axis, the category numbers, the
GLM on the declared axes and the IQR table of the same-condition pairs.
"""

from __future__ import annotations

import html
from pathlib import Path

from suds_exp.analysis import plots
from suds_exp.analysis.categories import at_cycles
from suds_exp.analysis.design_tables import (
    axis_category_table,
    design_glm_table,
    design_iqr_table,
    design_slope_table,
    label_pairs,
)
from suds_exp.analysis.formatting import (
    ReportTables,
    not_computed_html,
    to_html,
    write_missing,
    write_table,
)
from suds_exp.analysis.queries import load_results
from suds_exp.experiment import ExperimentDesign
from suds_exp.store import Store

#: What a campaign on recordings without conditions measures (the report says it).
BY_TRIAL_MEANING = (
    "These recordings carry no condition (no axis but perhaps the gait frequency), so the "
    "campaign ran by trial: each draw tests on one trial and trains on cycles of the "
    "others (leave-one-trial-out). Every result is a same-condition result: it measures "
    "how well a map learned from some recordings predicts another recording of the same "
    "behaviour (repeatability across trials), not how it transfers to other gaits or "
    "conditions; there are no similarity categories, and the GLM has no condition terms."
)


def write_design_report(
    store: Store,
    campaign: str,
    design: ExperimentDesign,
    out: Path,
    n_cycles: int | None = None,
) -> Path:
    """Write ``boxplot_<axis>.png`` per axis, ``sample_efficiency.png`` (a panel per
    condition), ``categories``, ``glm``, ``glm_rmse``, ``iqr`` and ``slopes`` as ``.csv``
    and ``.md``, and ``index.html`` into ``out``; returns the page.
    A design without axes (recordings without conditions, run by trial) has only the IQR
    table, and the page says what the analysis then means (`BY_TRIAL_MEANING`). A table
    the results cannot support (too few for a GLM, no same-condition pairs) is written as
    a Markdown note saying why (`write_missing`), and the page says it in its place."""
    results = load_results(store, campaign)
    _, size = at_cycles(results, n_cycles)
    out.mkdir(parents=True, exist_ok=True)
    tables = ReportTables()
    if design.axes:
        tables.attempt("categories", lambda: axis_category_table(results, design, size))
        tables.attempt("glm", lambda: design_glm_table(results, design, size))
        tables.attempt("glm_rmse", lambda: design_glm_table(results, design, size, response="rmse"))
    tables.attempt(
        ("iqr", "slopes"),
        lambda: (design_iqr_table(results, design), design_slope_table(results, design)),
    )
    figures = plots.axis_boxplots(label_pairs(results, design), design, out, size)
    if "iqr" in tables:
        iqr, slopes = (
            t.assign(
                panel=[f"{c} @ {f:g} Hz" for c, f in zip(t.condition, t.frequency_hz, strict=True)]
            )
            for t in (tables["iqr"], tables["slopes"])
        )
        figures["sample_efficiency"] = plots.efficiency_figure(
            iqr, slopes, out / "sample_efficiency.png", panel="panel"
        )
    files = {name: write_table(frame, out, name, 3) for name, frame in tables.items()}
    files.update(write_missing(tables.missing, out))
    axes = ", ".join(f"{a.name} ({a.kind})" for a in design.axes) or "none"
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'>",
        f"<title>suds-exp report: {html.escape(campaign)}</title></head><body>",
        f"<h1>Campaign {html.escape(campaign)}</h1>",
        f"<p>Experiment {html.escape(design.source)}: axes {html.escape(axes)}; "
        f"{len(results)} results; box plots and GLMs at {size} training cycles.</p>",
        _added_html(design),
        skipped_html(store, campaign),
    ]
    if design.by_trial:
        parts.append(f"<p>{html.escape(BY_TRIAL_MEANING)}</p>")
    for name, path in figures.items():
        parts.append(f"<h2>{html.escape(name)}</h2><img src='{path.name}' alt='{name}'>")
    for name in files:
        if name in tables.missing:
            parts.append(f"<h2>{name}</h2>{not_computed_html(tables.missing[name], files[name])}")
            continue
        frame = tables[name]
        links = " ".join(f"<a href='{p.name}'>{p.suffix[1:]}</a>" for p in files[name].values())
        note = ""
        if name.startswith("glm"):
            formulas = frame.attrs["formulas"]
            note = (
                f"<p>{html.escape(frame.attrs['response'])}; direct: "
                f"<code>{html.escape(formulas['direct'])}</code>; reference categories: "
                f"{html.escape(str(frame.attrs['reference']))}</p>"
            )
        parts.append(f"<h2>{name}</h2>{note}<p>{links}</p>{to_html(frame, 3)}")
    parts.append("</body></html>")
    index = out / "index.html"
    index.write_text("\n".join(parts), encoding="utf-8")
    return index


def _added_html(design: ExperimentDesign) -> str:
    """Names the levels code added to the design after its declaration, if any."""
    added = [(a.name, v) for a in design.axes for v in a.added]
    if not added:
        return ""
    text = ", ".join(f"{name}={level}" for name, level in added)
    return (
        "<p>Levels added after the declaration (by the code that added their trials, e.g. "
        f"a gait design's verify step; on an ordered axis a pair with one is same or far): "
        f"{html.escape(text)}.</p>"
    )


def skipped_html(store: Store, campaign: str) -> str:
    """The page's note of the (condition, training cycles) cells the campaign left out,
    or nothing."""
    from suds_exp.campaign.definition import skipped_cells_text
    from suds_exp.campaign.resume import load_stored_definition

    # Results without a campaign row (e.g. inserted by hand) have nothing left out.
    text = skipped_cells_text(load_stored_definition(store, campaign) or {})
    if not text:
        return ""
    return (
        "<p><b>Cells left out</b> (its data cannot supply them: the campaign was run with "
        "<code>--skip-infeasible</code>, or the condition was added to the design by a loop "
        f"with too few trials): {html.escape(text)}.</p>"
    )
