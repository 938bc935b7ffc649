"""The results analyses on any declared experiment design (`suds_exp.experiment`).

With the paper's design the report keeps its own tables (`categories`, `glm`, `spread`),
which these reproduce in substance under the design's names; with a user's design these
are the tables: each result's train/test pair classified along every declared axis
(column ``<axis>_pair``: same / near / far, same / lower / higher, same / different), the
box-plot numbers by axis and category, a GLM whose terms are the declared axes' pair
categories, and the IQR and sample-efficiency tables grouped by the test condition.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from suds_exp.analysis.categories import at_cycles, learner_order
from suds_exp.analysis.glm import RESPONSES, fit_formula, formulas, term_parts
from suds_exp.analysis.spread import fit_slopes
from suds_exp.errors import AnalysisError
from suds_exp.experiment import ExperimentDesign, classify_pair, pair_column

#: The reference category of each axis kind in the GLM: a pair that differs by the least,
#: as the paper's reference (near gait, trained at the lower frequency).
REFERENCE = {"ordered": "near", "numeric": "lower", "unordered": "different"}


def label_pairs(results: pd.DataFrame, design: ExperimentDesign) -> pd.DataFrame:
    """``results`` with one column ``<axis>_pair`` per declared axis: the pair's category
    along it (`suds_exp.experiment.classify`), and ``test_condition`` (the test
    condition's label, with its frequency when that is an axis)."""
    keys = ["train_gait", "train_frequency_hz", "test_gait", "test_frequency_hz"]
    pairs = results[keys].drop_duplicates()
    rows = []
    for tg, tf, dg, df in pairs.itertuples(index=False):
        try:
            cats = classify_pair(design, (tg, tf), (dg, df))
        except (ValueError, KeyError) as exc:
            raise AnalysisError(
                f"condition {tg!r} or {dg!r} is not one of the experiment's "
                f"({design.source}: {', '.join(design.names)}): {exc}",
                param="experiment",
            ) from None
        rows.append({**dict(zip(keys, (tg, tf, dg, df), strict=True)), **_named(cats)})
    labels = pd.DataFrame(rows, columns=[*keys, *(pair_column(a) for a in design.axes)])
    out = results.merge(labels, on=keys, how="left", validate="many_to_one")
    out.index = results.index
    return out


def _named(cats: dict[str, str]) -> dict[str, str]:
    return {pair_column(k): v for k, v in cats.items()}


def axis_category_table(
    results: pd.DataFrame, design: ExperimentDesign, n_cycles: int | None = None
) -> pd.DataFrame:
    """Numbers behind the box plots: ln RMS error of vx by learner, axis and category.

    Returns a DataFrame with columns ``axis``, ``category``, ``model``, ``n``, ``q1``,
    ``median``, ``q3`` (ln of mm/s) and ``median_rmse_vx`` (mm/s), axes in declared
    order, categories in their kind's order, learners in display order.
    """
    rows, _ = at_cycles(label_pairs(results, design), n_cycles)
    models = learner_order(rows["model"])
    out = []
    for axis in design.axes:
        col = pair_column(axis)
        for cat in axis.categories:
            for model in models:
                sel = rows[(rows[col] == cat) & (rows["model"] == model)]
                if sel.empty:
                    continue
                q1, med, q3 = np.quantile(sel["ln_rmse_vx"].to_numpy(float), [0.25, 0.5, 0.75])
                out.append(
                    {
                        "axis": axis.name,
                        "category": cat,
                        "model": model,
                        "n": len(sel),
                        "q1": q1,
                        "median": med,
                        "q3": q3,
                        "median_rmse_vx": float(sel["rmse_vx"].median()),
                    }
                )
    return pd.DataFrame(
        out, columns=["axis", "category", "model", "n", "q1", "median", "q3", "median_rmse_vx"]
    )


def design_glm_frame(
    results: pd.DataFrame, design: ExperimentDesign, response: str = "log"
) -> pd.DataFrame:
    """The GLM's data on a design: ``y``, ``suds``, ``gmr`` (0/1) and one column
    ``<axis>_pair`` per declared axis, without phase-only rows."""
    if response not in RESPONSES:
        raise AnalysisError(f"response {response!r}: expected one of {', '.join(RESPONSES)}")
    rows = label_pairs(results[~results["phase_only"].astype(bool)], design)
    frame = pd.DataFrame(
        {
            "y": RESPONSES[response][1](rows["rmse_vx"].to_numpy(dtype=float)),
            "suds": rows["suds"].astype(int).to_numpy(),
            "gmr": rows["gmr"].astype(int).to_numpy(),
        },
        index=rows.index,
    )
    for axis in design.axes:
        frame[pair_column(axis)] = rows[pair_column(axis)].astype(str).to_numpy()
    return frame[np.isfinite(frame["y"])]


def design_formulas(
    frame: pd.DataFrame, design: ExperimentDesign
) -> tuple[str, str, dict[str, str]]:
    """Direct and first-order-interaction formulas whose terms are SUDS, GMR and each
    declared axis's pair category, and the reference category of each axis. A term with
    one level in the data is left out (it cannot be estimated)."""
    terms, refs = [], {}
    for flag in ("suds", "gmr"):
        if frame[flag].nunique() > 1:
            terms.append(flag)
    for axis in design.axes:
        col = pair_column(axis)
        present = [c for c in axis.categories if c in set(frame[col])]
        if len(present) < 2:
            continue
        ref = REFERENCE[axis.kind] if REFERENCE[axis.kind] in present else present[0]
        refs[axis.name] = ref
        terms.append(f"C({col}, Treatment(reference='{ref}'))")
    return (*formulas(terms), refs)


def design_term_name(column: str) -> str:
    """A design column's name: ``SUDS``, ``GMR``, ``gait=same``, joined by ``:``."""
    if column == "Intercept":
        return column
    return ":".join(
        {"suds": "SUDS", "gmr": "GMR"}.get(factor, factor)
        if level is None
        else f"{factor.removesuffix('_pair')}={level}"
        for factor, level, _ in term_parts(column)
    )


def design_glm_table(
    results: pd.DataFrame,
    design: ExperimentDesign,
    n_cycles: int | None = None,
    response: str = "log",
    alpha: float = 0.05,
) -> pd.DataFrame:
    """Coefficients of the direct and interaction GLMs whose terms are the declared axes.

    Returns a DataFrame with columns ``model`` (direct / interactions), ``term``
    (``SUDS``, ``GMR``, ``<axis>=<category>`` and their ``:`` products), ``coef``,
    ``ci_low``, ``ci_high`` (response units, see `suds_exp.analysis.glm`) and
    ``p_value``; ``attrs`` holds the ``formulas``, ``reference`` categories,
    ``response``, ``n_cycles`` and ``n_rows``.
    """
    rows, size = at_cycles(results, n_cycles)
    frame = design_glm_frame(rows, design, response)
    if len(frame) < 10:
        raise AnalysisError(f"GLM: only {len(frame)} learner results at {size} cycles; need 10+")
    direct, interactions, refs = design_formulas(frame, design)
    parts = []
    for formula, label in ((direct, "direct"), (interactions, "interactions")):
        fit = fit_formula(formula, frame, alpha, method="qr")
        fit.insert(0, "model", label)
        fit.insert(1, "term", [design_term_name(c) for c in fit["column"]])
        parts.append(fit.drop(columns="column"))
    table = pd.concat(parts, ignore_index=True)
    table.attrs = {
        "formulas": {"direct": direct, "interactions": interactions},
        "reference": refs,
        "response": RESPONSES[response][0],
        "n_cycles": size,
        "n_rows": len(frame),
    }
    return table


def design_iqr_table(results: pd.DataFrame, design: ExperimentDesign) -> pd.DataFrame:
    """Quartiles of the RMS error of vx over same-condition pairs (same category along
    every axis: the sample-efficiency sweep's pairs), by test condition, learner and
    training size.

    Returns a DataFrame with columns ``condition`` (the test condition's label),
    ``frequency_hz``, ``model``, ``n_cycles``, ``n``, ``q1``, ``median``, ``q3``, ``iqr``
    (mm/s; linear-interpolated quartiles).
    """
    rows = _same_condition(results, design)
    grouped = rows.groupby(["condition", "frequency_hz", "model", "n_cycles"])["rmse_vx"]
    table = grouped.quantile([0.25, 0.5, 0.75]).unstack()
    table.columns = ["q1", "median", "q3"]
    table.insert(0, "n", grouped.count())
    table["iqr"] = table["q3"] - table["q1"]
    return _ordered(table.reset_index())


def design_slope_table(
    results: pd.DataFrame, design: ExperimentDesign, upper_from: int | None = None
) -> pd.DataFrame:
    """Each learner's log-log slope of RMS error of vx against training cycles over the
    same-condition pairs, per test condition (`suds_exp.analysis.spread.slope_table`'s
    fit): columns ``condition``, ``frequency_hz``, ``model``, ``slope``, ``ci_low``,
    ``ci_high``, ``cycles_from``, ``cycles_to``, ``n``."""
    rows = _same_condition(results, design)
    return _ordered(fit_slopes(rows, ["condition", "frequency_hz", "model"], upper_from))


def _ordered(table: pd.DataFrame) -> pd.DataFrame:
    order = {m: i for i, m in enumerate(learner_order(table["model"]))}
    keys = ["condition", "frequency_hz", "model", "n_cycles"]
    return table.sort_values(
        [k for k in keys if k in table],
        key=lambda s: s.map(order) if s.name == "model" else s,
    ).reset_index(drop=True)


def _same_condition(results: pd.DataFrame, design: ExperimentDesign) -> pd.DataFrame:
    """Results of same-condition pairs, with the test ``condition`` and ``frequency_hz``."""
    labelled = label_pairs(results, design)
    same = np.ones(len(labelled), dtype=bool)
    for axis in design.axes:
        same &= (labelled[pair_column(axis)] == "same").to_numpy()
    # conditions that differ only in a frequency the design does not declare are not the
    # same condition either
    same &= (labelled["train_gait"] == labelled["test_gait"]).to_numpy()
    same &= (
        labelled["train_frequency_hz"].round(6) == labelled["test_frequency_hz"].round(6)
    ).to_numpy()
    rows = labelled[same]
    if rows.empty:
        raise AnalysisError(
            "no same-condition results (trained and tested on the same condition); the "
            "IQR table and sample-efficiency figure need them"
        )
    return rows.assign(condition=rows["test_gait"], frequency_hz=rows["test_frequency_hz"].round(6))
