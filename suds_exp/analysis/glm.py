"""GLM tables: log RMS error of vx on SUDS, GMR, period relation and gait similarity.

Two models, as in the paper's GLM table: direct effects only, and all first-order
interactions. Reference levels are the paper's: a TLS learner (SUDS = GMR = 0) whose
model-period is longer than the data-period (``period_rel`` ``>``, i.e. trained slower than
tested) on a gait one step from the training gait (``near``). Each coefficient is the
change from that reference.

The response is ``100 ln(rmse_vx)`` by default. The paper calls its response "log RMS
error", but an intercept of 68.72 (91.36 with interactions) cannot be a plain natural or
decimal log of an RMS error whose inter-quartile ranges it gives as 3-57 units (that would
be an error of e^68); its magnitudes fit a log scaled by 100, or a response linear in the
error. On ``100 ln``, a coefficient reads as roughly a percentage change of the RMS error
(-10 ~ 10 % lower) and does not depend on the error's unit, so signs, orderings and effect
sizes can be set beside the paper's. The paper's own reading of its coefficients (SUDS
-47.53 against intercept 91.36 called a "52 % error reduction") treats them as linear in
RMS error, so that scale (``response="rmse"``, mm/s) is fitted too; its coefficients depend
on the unit. The model is a Gaussian GLM with identity link, i.e. ordinary least squares.
Phase-only rows are left out: with neither SUDS nor GMR they would be counted as TLS.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd
import statsmodels.api as sm
import statsmodels.formula.api as smf
from scipy import stats
from threadpoolctl import threadpool_limits

from suds_exp.analysis.categories import at_cycles
from suds_exp.errors import AnalysisError

#: Response scales: name -> (description, transform of rmse_vx in mm/s).
RESPONSES: dict[str, tuple[str, Callable[[np.ndarray], np.ndarray]]] = {
    "log": ("100 ln(RMS error of vx / (mm/s))", lambda r: 100.0 * np.log(r)),
    "rmse": ("RMS error of vx (mm/s)", lambda r: r),
}

#: Reference levels, the paper's: model-period > data-period, near gait.
REFERENCE = {"period_rel": ">", "gait_sim": "near"}

#: Paper names of each factor level (the table's term names).
LEVEL_NAMES = {
    "suds": "SUDS",
    "gmr": "GMR",
    ("period_rel", "<"): "model-period<data-period",
    ("period_rel", "="): "model-period=data-period",
    ("period_rel", ">"): "model-period>data-period",
    ("gait_sim", "same"): "model-gait=data-gait",
    ("gait_sim", "far"): "model-gait far from data-gait",
    ("gait_sim", "near"): "model-gait near data-gait",
}
_FACTOR_ORDER = ("suds", "gmr", "period_rel", "gait_sim")
_PART = re.compile(r"^C\((\w+), Treatment\(reference='[^']*'\)\)\[T\.(.+)\]$")


def glm_frame(results: pd.DataFrame, response: str = "log") -> pd.DataFrame:
    """The GLM's data: ``y`` on the ``response`` scale, ``suds``, ``gmr`` (0/1), ``period_rel``,
    ``gait_sim``, from labelled results without phase-only rows."""
    if response not in RESPONSES:
        raise AnalysisError(f"response {response!r}: expected one of {', '.join(RESPONSES)}")
    # Only the five columns are taken, and the two labels as categories: a copy of every
    # column and a Python string per label and row raised the findings' peak by 312 MB
    # per million results (measured at 1M), for the same design.
    learner = ~results["phase_only"].astype(bool).to_numpy()
    # the rows' index is kept, so a caller can tie each GLM row back to its result
    frame = pd.DataFrame(
        {
            "y": RESPONSES[response][1](results["rmse_vx"].to_numpy(dtype=float)[learner]),
            "suds": results["suds"].to_numpy()[learner].astype(int),
            "gmr": results["gmr"].to_numpy()[learner].astype(int),
            "period_rel": _labels(results["period_rel"], learner),
            "gait_sim": _labels(results["gait_sim"], learner),
        },
        index=results.index[learner],
    )
    frame = frame[np.isfinite(frame["y"]) & (frame["gait_sim"] != "<NA>")]
    for name in ("period_rel", "gait_sim"):
        frame[name] = frame[name].cat.remove_unused_categories()
    return frame


def _labels(column: pd.Series, rows: np.ndarray) -> pd.Categorical:
    """``column``'s values at ``rows`` as text categories in sorted order, a missing value
    missing."""
    codes, levels = pd.factorize(column.to_numpy()[rows], use_na_sentinel=True)
    labels = pd.Categorical.from_codes(codes, [str(v) for v in levels])
    return labels.reorder_categories(sorted(labels.categories))


def glm_formulas(frame: pd.DataFrame) -> tuple[str, str, dict[str, str]]:
    """Direct and interaction formulas for ``frame``, and the reference level of each factor.

    A factor with a single level in the data is left out (it cannot be estimated); a
    categorical whose paper reference level is absent uses its first present level.
    """
    terms, refs = [], {}
    for name in _FACTOR_ORDER:
        levels = sorted(frame[name].unique())
        if len(levels) < 2:
            continue
        if name in REFERENCE:
            ref = REFERENCE[name] if REFERENCE[name] in levels else levels[0]
            refs[name] = ref
            terms.append(f"C({name}, Treatment(reference='{ref}'))")
        else:
            terms.append(name)
    return (*formulas(terms), refs)


def formulas(terms: list[str]) -> tuple[str, str]:
    """The formula of the main effects of ``terms`` (patsy terms) and the one with their
    two-way interactions (the same when there is one term)."""
    if not terms:
        raise AnalysisError("GLM: every predictor is constant in these results; nothing to fit")
    direct = "y ~ " + " + ".join(terms)
    interactions = direct if len(terms) == 1 else f"y ~ ({' + '.join(terms)})**2"
    return direct, interactions


def term_parts(column: str) -> list[tuple[str, str | None, str]]:
    """The factors of a patsy design column (not ``Intercept``), in its order, as
    ``(factor, level, piece)``: ``level`` of a treatment-coded factor
    (``C(f, Treatment(...))[T.level]``), None for a plain 0/1 column such as ``suds``;
    ``piece`` the column's text for that factor."""
    parts: list[tuple[str, str | None, str]] = []
    for piece in column.split(":"):
        m = _PART.match(piece)
        parts.append((m.group(1), m.group(2), piece) if m else (piece, None, piece))
    return parts


def term_name(column: str) -> str:
    """The paper's name of a design column, e.g. ``SUDS:(model-period<data-period)``."""
    if column == "Intercept":
        return column
    parts = []
    for factor, level, piece in term_parts(column):
        key = factor if level is None else (factor, level)
        parts.append((_FACTOR_ORDER.index(factor), LEVEL_NAMES.get(key, piece)))
    parts.sort()
    if len(parts) == 1:
        return parts[0][1]
    return ":".join(n if n in ("SUDS", "GMR") else f"({n})" for _, n in parts)


def identifiable_columns(
    exog: np.ndarray, tol: float = 1e-9, weights: np.ndarray | None = None
) -> list[int]:
    """Indices of the design columns kept, in order: each one kept unless it is (nearly) a
    linear combination of the columns kept before it, as R's ``lm`` drops aliased terms.

    Works on the column-normalised Gram matrix (n_params x n_params), so its cost does not
    grow with the number of results beyond one matrix product. ``weights`` (shape (n,)):
    each row of ``exog`` stands for that many rows (the distinct rows of a design and
    their counts give the design's own columns).
    """
    w = np.ones(len(exog)) if weights is None else np.asarray(weights, dtype=float)
    norms = np.sqrt(np.einsum("ij,ij,i->j", exog, exog, w))
    gram = (exog.T * w) @ exog
    kept: list[int] = []
    for j in range(exog.shape[1]):
        if norms[j] == 0:
            continue
        trial = [*kept, j]
        sub = gram[np.ix_(trial, trial)] / np.outer(norms[trial], norms[trial])
        if np.linalg.eigvalsh(sub)[0] > tol:
            kept.append(j)
    return kept


@dataclass(frozen=True)
class Design:
    """A formula's design on a data frame: ``endog`` (n,), the distinct design rows
    ``patterns`` (k, p) and each row's pattern ``pattern`` (n,), the column ``names`` (p)
    and the indices ``keep`` of the identifiable columns (`identifiable_columns`).

    The paper's predictors are categories, so a design of millions of rows has a few
    dozen distinct rows; ``exog`` (n, p) is built only when asked for."""

    endog: np.ndarray
    patterns: np.ndarray
    pattern: np.ndarray
    names: list[str]
    keep: list[int]

    @property
    def exog(self) -> np.ndarray:
        return self.patterns[self.pattern]

    @property
    def counts(self) -> np.ndarray:
        """Rows of each pattern, shape (k,)."""
        return np.bincount(self.pattern, minlength=len(self.patterns)).astype(float)


def formula_design(formula: str, frame: pd.DataFrame) -> Design:
    """The design matrices of a patsy ``formula`` on ``frame`` and its identifiable
    columns: terms the data cannot tell apart are dropped, as R's ``lm`` reports NA.

    patsy builds the design of the distinct predictor rows only (its per-value checks
    cost seconds per million rows); each row then points at its pattern."""
    response = formula.split("~", 1)[0].strip()
    predictors = [c for c in frame.columns if c != response]
    # patsy drops rows with a missing value: such a frame gets the plain, row-wise design
    plain = (
        response not in frame.columns
        or not predictors
        or frame.isna().to_numpy().any()
        or len(frame) == 0
    )
    if plain:
        pattern = np.arange(len(frame))
        distinct = frame
    else:
        pattern = frame.groupby(predictors, sort=False).ngroup().to_numpy()
        first = np.unique(pattern, return_index=True)[1]
        distinct = frame.iloc[first].assign(**{response: 0.0})
    # One BLAS thread: these matrices are small, and on a busy machine OpenBLAS's thread
    # pool made one QR of a 3600 x 20 design take 0.3 s instead of 3 ms (measured).
    with threadpool_limits(limits=1, user_api="blas"):
        design = smf.ols(formula, distinct)
        patterns = np.asarray(design.exog)
        if plain:
            pattern = np.arange(len(patterns))
        counts = np.bincount(pattern, minlength=len(patterns)).astype(float)
        keep = identifiable_columns(patterns, weights=counts)
    endog = np.asarray(design.endog) if plain else frame[response].to_numpy(dtype=float)
    return Design(endog, patterns, pattern, list(design.exog_names), keep)


def fit_design(design: Design, alpha: float = 0.05) -> pd.DataFrame:
    """Ordinary least squares of a `Design` from each pattern's count, mean and spread of
    the response, as `fit_formula` returns it (same estimates, Student-t intervals and
    p-values to rounding), in memory that does not grow with the rows beyond one pass."""
    keep, n = design.keep, len(design.endog)
    u = design.patterns[:, keep]
    counts = design.counts
    sums = np.bincount(design.pattern, weights=design.endog, minlength=len(counts))
    means = np.divide(sums, counts, out=np.zeros_like(sums), where=counts > 0)
    within = float(np.sum((design.endog - means[design.pattern]) ** 2))
    root = np.sqrt(counts)
    with threadpool_limits(limits=1, user_api="blas"):
        beta = np.linalg.lstsq(u * root[:, None], means * root, rcond=None)[0]
        rss = within + float(counts @ (means - u @ beta) ** 2)
        df = n - len(keep)
        cov = rss / df * np.linalg.inv((u.T * counts) @ u)
    se = np.sqrt(np.diag(cov))
    t = beta / se
    q = stats.t.ppf(1 - alpha / 2, df)
    full = len(design.names)
    coef, low, high, pval = (np.full(full, np.nan) for _ in range(4))
    coef[keep], low[keep], high[keep] = beta, beta - q * se, beta + q * se
    pval[keep] = 2 * stats.t.sf(np.abs(t), df)
    table = pd.DataFrame(
        {"column": design.names, "coef": coef, "ci_low": low, "ci_high": high, "p_value": pval}
    )
    table.attrs["keep"] = keep
    return table


def fit_formula(
    formula: str, frame: pd.DataFrame, alpha: float = 0.05, method: str = "pinv"
) -> pd.DataFrame:
    """Ordinary least squares of a patsy ``formula`` on ``frame``, the one GLM fit of the
    package (a Gaussian GLM with identity link is OLS).

    Returns one row per design column, in the design's order: ``column`` (patsy's name),
    ``coef``, ``ci_low``, ``ci_high`` ((1 - alpha) Student-t interval, response units)
    and ``p_value``; NaN for a column the data cannot separate from earlier ones
    (`identifiable_columns`), as R's ``lm`` reports NA. ``method`` is statsmodels' OLS
    solver (``"qr"`` is several times faster than the SVD-based ``"pinv"`` and gives the
    same estimates to rounding). ``attrs["keep"]``: indices of the identifiable columns.
    """
    design = formula_design(formula, frame)
    keep = design.keep
    with threadpool_limits(limits=1, user_api="blas"):
        fit = sm.OLS(design.endog, design.exog[:, keep]).fit(method=method)
    n = len(design.names)
    coef, low, high, pval = (np.full(n, np.nan) for _ in range(4))
    ci = np.asarray(fit.conf_int(alpha=alpha))
    coef[keep], low[keep], high[keep], pval[keep] = fit.params, ci[:, 0], ci[:, 1], fit.pvalues
    table = pd.DataFrame(
        {"column": design.names, "coef": coef, "ci_low": low, "ci_high": high, "p_value": pval}
    )
    table.attrs["keep"] = keep
    return table


def _fit_table(formula: str, frame: pd.DataFrame, label: str, alpha: float) -> pd.DataFrame:
    fit = fit_design(formula_design(formula, frame), alpha)
    names, coef, keep = fit["column"].tolist(), fit["coef"].to_numpy(), fit.attrs["keep"]
    table = pd.DataFrame(
        {
            "model": label,
            "term": [term_name(c) for c in names],
            "coef": coef,
            "ci_low": fit["ci_low"].to_numpy(),
            "ci_high": fit["ci_high"].to_numpy(),
            "p_value": fit["p_value"].to_numpy(),
        }
    )
    # The paper lists the intercept first, then terms by decreasing magnitude; terms the
    # data cannot separate from earlier ones (NaN) come last.
    order = np.argsort(-np.nan_to_num(np.abs(coef), nan=-1.0), kind="stable")
    table = table.iloc[order]
    table = pd.concat([table[table.term == "Intercept"], table[table.term != "Intercept"]])
    table.attrs["aliased"] = [term_name(c) for j, c in enumerate(names) if j not in set(keep)]
    return table.reset_index(drop=True)


def glm_table(
    results: pd.DataFrame,
    n_cycles: int | None = None,
    response: str = "log",
    alpha: float = 0.05,
) -> pd.DataFrame:
    """Coefficients of the direct-effects and first-order-interactions GLMs.

    Parameters
    ----------
    results : DataFrame
        Rows of ``results_labelled`` (see `load_results`).
    n_cycles : int, optional
        Training size to fit on; default the campaign's most common one.
    response : {"log", "rmse"}
        ``log``: 100 ln(rmse_vx); ``rmse``: rmse_vx in mm/s (see the module docstring).
    alpha : float
        The intervals are (1 - alpha) confidence intervals (Student t).

    Returns
    -------
    DataFrame with columns ``model`` (``direct`` / ``interactions``), ``term`` (the paper's
    names), ``coef``, ``ci_low``, ``ci_high`` (response units) and ``p_value``; in each model
    the intercept first, then the terms by decreasing magnitude. ``attrs`` holds the
    ``formulas``, ``reference`` levels, ``response`` description, ``n_cycles``, ``n_rows``
    and, per model, the ``aliased`` terms: those the data cannot tell apart from terms
    before them (a category combination absent, two flags always equal); their numbers
    are NaN, as R's ``lm`` reports NA.
    """
    rows, size = at_cycles(results, n_cycles)
    frame = glm_frame(rows, response)
    if len(frame) < 10:
        raise AnalysisError(f"GLM: only {len(frame)} learner results at {size} cycles; need 10+")
    direct, interactions, refs = glm_formulas(frame)
    tables = [
        _fit_table(f, frame, label, alpha)
        for f, label in ((direct, "direct"), (interactions, "interactions"))
    ]
    table = pd.concat(tables, ignore_index=True)
    table.attrs = {
        "formulas": {"direct": direct, "interactions": interactions},
        "reference": {k: LEVEL_NAMES[(k, v)] for k, v in refs.items()},
        "response": RESPONSES[response][0],
        "n_cycles": size,
        "n_rows": len(frame),
        "aliased": {t["model"].iloc[0]: t.attrs["aliased"] for t in tables},
    }
    return table
