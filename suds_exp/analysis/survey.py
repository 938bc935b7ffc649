"""The learner survey: how much data each learner needs, and how fast it is.

Answers the paper's Future Work question ("GMR requires x10 less data than a Multi-Layer
Perceptron ... How do they compare in practice?") from a campaign's sample-efficiency
sweep (same-condition pairs at several training sizes):

- `cycles_to_target`: per learner and test frequency, the error curve is the median RMS
  error of vx over the draws (and gaits) at each training size; the cycles needed to reach
  a target are where that curve first falls to it, interpolated linearly in
  (log cycles, log error) between the two sweep sizes around the crossing (NaN when it
  never does within the sweep). Targets: x1.25 of the learner's own error at the largest
  sweep size (48 cycles in the paper's sweep), and the reference learner's (GMR's) error
  at the main grid size (30 cycles).
- `efficiency_ratio`: cycles a learner needs to reach GMR's 30-cycle error over the
  cycles GMR needs, all frequencies pooled, with a percentile bootstrap interval that
  resamples the draws (boot indices, paired across learners, within each condition and
  size). Above 1: the learner needs that many times GMR's data. A learner that never
  reaches the target within the sweep gives inf.
- `timing_table`: median fit and predict seconds per learner and training size.
- `seed_tolerance`, `within_seed_tolerance`: a learner's own randomness at each training
  size (the spread over seeds of the survey's statistic, the median error over draws),
  and whether another recipe of it stays within that spread: the rule by which a faster
  setting of a survey baseline may replace the old one (`benchmarks/survey_tolerance.py`).
- `learner_glm`: generalisation across frequency and gait with the learner as a factor:
  100 ln(RMS error of vx) on learner (reference GMR), period relation and gait
  similarity (the paper's references), and the learner x similarity interactions, on the
  main grid's cross pairs (ordinary least squares, as `glm.glm_table`).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from suds_exp.analysis.categories import learner_order
from suds_exp.campaign.grid import KEY_COLUMNS
from suds_exp.errors import AnalysisError
from suds_exp.models.registry import GMR, MLP

REFERENCE = GMR
OWN_FACTOR = 1.25


def sweep_rows(results: pd.DataFrame) -> pd.DataFrame:
    """Same-condition rows (train gait and frequency = test's), the sweep's pairs."""
    same = (results["train_gait"] == results["test_gait"]) & (
        (results["train_frequency_hz"] - results["test_frequency_hz"]).abs() < 1e-9
    )
    rows = results[same]
    if rows["n_cycles"].nunique() < 2:
        raise AnalysisError(
            "survey: no sample-efficiency results (same-condition pairs at two or more "
            "training sizes); run the campaign with sweep, e.g. 1,2,4,8,16,30,48",
            param="sweep",
        )
    return rows


def _curves(rows: pd.DataFrame, by: list[str], metric: str) -> pd.Series:
    """Median error per (by..., n_cycles)."""
    return rows.groupby([*by, "n_cycles"])[metric].median()


def crossing(curve: pd.Series, target: float) -> float:
    """Cycles at which a (n_cycles -> error) curve first reaches ``target``; NaN if never.

    Interpolated linearly in (log n, log error) between the last size above the target
    and the first at or below it.
    """
    n = curve.index.to_numpy(dtype=float)
    e = curve.to_numpy(dtype=float)
    hit = np.flatnonzero(e <= target)
    if hit.size == 0 or not np.isfinite(target) or target <= 0:
        return float("nan")
    i = int(hit[0])
    if i == 0:
        return float(n[0])
    ln0, ln1 = np.log(n[i - 1]), np.log(n[i])
    le0, le1 = np.log(e[i - 1]), np.log(e[i])
    w = (np.log(target) - le0) / (le1 - le0) if le1 != le0 else 1.0
    return float(np.exp(ln0 + w * (ln1 - ln0)))


def cycles_to_target(
    results: pd.DataFrame,
    main_cycles: int = 30,
    metric: str = "rmse_vx",
    reference: str = REFERENCE,
    factor: float = OWN_FACTOR,
) -> pd.DataFrame:
    """Per learner and test frequency: errors at the largest and main sizes and cycles to
    the two targets.

    Columns: ``model``, ``frequency_hz``, ``err_max`` (median error at the largest sweep
    size, mm/s for vx), ``max_cycles``, ``cycles_own`` (to reach ``factor`` x err_max),
    ``target_ref`` (the reference learner's median error at ``main_cycles``, same
    frequency), ``cycles_ref`` (to reach it; NaN: not within the sweep).
    """
    rows = sweep_rows(results)
    curves = _curves(rows, ["model", "test_frequency_hz"], metric)
    top = int(rows["n_cycles"].max())
    out = []
    for (model, freq), curve in curves.groupby(level=[0, 1]):
        c = curve.droplevel([0, 1])
        ref = curves.get((reference, freq, main_cycles), np.nan)
        err_max = float(c.get(top, np.nan))
        out.append(
            {
                "model": model,
                "frequency_hz": float(freq),
                "max_cycles": top,
                "err_max": err_max,
                "cycles_own": crossing(c, factor * err_max),
                "target_ref": float(ref),
                "cycles_ref": crossing(c, float(ref)),
            }
        )
    frame = pd.DataFrame(out)
    order = {m: i for i, m in enumerate(learner_order(frame["model"].unique()))}
    return frame.sort_values(
        ["model", "frequency_hz"], key=lambda s: s.map(order) if s.name == "model" else s
    ).reset_index(drop=True)


def _pooled_cycles(rows, model, reference, main_cycles, metric) -> tuple[float, float]:
    curves = _curves(rows, ["model"], metric)
    target = curves.get((reference, main_cycles), np.nan)
    c_model = crossing(curves.loc[model], float(target)) if model in curves.index else np.nan
    c_ref = crossing(curves.loc[reference], float(target))
    return c_model, c_ref


def efficiency_ratio(
    results: pd.DataFrame,
    model: str = MLP,
    reference: str = REFERENCE,
    main_cycles: int = 30,
    metric: str = "rmse_vx",
    n_boot: int = 1000,
    level: float = 0.95,
    seed: int = 0,
) -> dict:
    """How many times the reference's data ``model`` needs to reach the reference's error
    at ``main_cycles`` (all frequencies pooled), with a bootstrap interval.

    Returns {"model", "reference", "target", "cycles_model", "cycles_reference", "ratio",
    "low", "high", "level", "n_boot", "unreached"} (unreached: share of bootstrap
    resamples in which ``model`` never reached the target; those count as inf).
    """
    rows = sweep_rows(results)
    for m in (model, reference):
        if m not in set(rows["model"]):
            raise AnalysisError(f"survey: learner {m!r} is not in the campaign's sweep")
    rows = rows[rows["model"].isin([model, reference])]
    if main_cycles not in set(rows["n_cycles"]):
        raise AnalysisError(f"survey: no sweep results at {main_cycles} cycles")
    cm, cr = _pooled_cycles(rows, model, reference, main_cycles, metric)
    target = float(_curves(rows, ["model"], metric).get((reference, main_cycles), np.nan))
    # Paired bootstrap: resample boot indices once per (condition, size), for both learners.
    wide = rows.pivot_table(
        index=["train_gait", "train_frequency_hz", "n_cycles", "boot"],
        columns="model",
        values=metric,
    ).dropna()
    sizes = wide.index.get_level_values("n_cycles").to_numpy()
    cells = wide.index.droplevel("boot").to_flat_index()
    blocks = [np.flatnonzero(cells == c) for c in dict.fromkeys(cells)]
    values = wide[[model, reference]].to_numpy()
    rng = np.random.default_rng(seed)
    ratios = np.empty(n_boot)
    for b in range(n_boot):
        idx = np.concatenate([rng.choice(blk, size=len(blk)) for blk in blocks])
        curve = pd.DataFrame(values[idx], columns=["m", "r"]).groupby(sizes[idx]).median()
        tgt = curve["r"].get(main_cycles, np.nan)
        m_b, r_b = crossing(curve["m"], tgt), crossing(curve["r"], tgt)
        ratios[b] = np.inf if not np.isfinite(m_b) else m_b / r_b
    alpha = (1 - level) / 2
    # percentiles of the resamples themselves (no interpolation: some may be inf)
    low, high = np.quantile(ratios, [alpha, 1 - alpha], method="inverted_cdf")
    return {
        "model": model,
        "reference": reference,
        "target": target,
        "cycles_model": cm,
        "cycles_reference": cr,
        "ratio": cm / cr if np.isfinite(cm) else float("inf"),
        "low": float(low),
        "high": float(high),
        "level": level,
        "n_boot": n_boot,
        "unreached": float(np.mean(~np.isfinite(ratios))),
    }


def timing_table(results: pd.DataFrame) -> pd.DataFrame:
    """Median fit and predict seconds per learner and training size (needs the
    ``fit_seconds``, ``predict_seconds`` columns)."""
    missing = {"fit_seconds", "predict_seconds"} - set(results.columns)
    if missing:
        raise AnalysisError(f"survey: results lack {', '.join(sorted(missing))}")
    t = (
        results.groupby(["model", "n_cycles"])[["fit_seconds", "predict_seconds"]]
        .median()
        .reset_index()
    )
    order = {m: i for i, m in enumerate(learner_order(t["model"].unique()))}
    return t.sort_values(
        ["model", "n_cycles"], key=lambda s: s.map(order) if s.name == "model" else s
    ).reset_index(drop=True)


def learner_glm(
    results: pd.DataFrame, main_cycles: int = 30, reference: str = REFERENCE, alpha: float = 0.05
) -> pd.DataFrame:
    """Coefficients of 100 ln(rmse_vx) ~ learner + period_rel + gait_sim ("direct") and
    ~ learner x (period_rel + gait_sim) ("interactions") at ``main_cycles``.

    ``results`` are labelled rows (`load_results`). Learner reference ``reference``,
    period reference ``>`` (trained slower than tested), gait reference ``near``; a factor
    with one level in the data is left out. Columns: ``model`` (direct / interactions),
    ``term`` (patsy's name), ``coef``, ``ci_low``, ``ci_high`` (response units: ~percent
    change of the error; NaN for a term the data cannot separate from earlier ones),
    ``p_value``; ``attrs["n_rows"]``. A learner coefficient is how
    much larger (in 100 ln units) its error is than GMR's in the reference category; an
    interaction is how much more (or less) than GMR it loses in that category.
    """
    from suds_exp.analysis.glm import REFERENCE as SIMILARITY_REFERENCE
    from suds_exp.analysis.glm import fit_formula

    rows = results[results["n_cycles"] == main_cycles]
    frame = pd.DataFrame(
        {
            "y": 100.0 * np.log(rows["rmse_vx"].to_numpy(dtype=float)),
            "learner": rows["model"].astype(str).to_numpy(),
            "period_rel": rows["period_rel"].astype(str).to_numpy(),
            "gait_sim": rows["gait_sim"].astype(str).to_numpy(),
        }
    )
    frame = frame[np.isfinite(frame["y"])]
    if reference not in set(frame["learner"]):
        raise AnalysisError(f"survey GLM: no {reference} results at {main_cycles} cycles")
    terms, similarity = [f"C(learner, Treatment(reference='{reference}'))"], []
    for name, ref in SIMILARITY_REFERENCE.items():
        levels = sorted(frame[name].unique())
        if len(levels) > 1:
            ref = ref if ref in levels else levels[0]
            similarity.append(f"C({name}, Treatment(reference='{ref}'))")
    if not similarity:
        raise AnalysisError(
            "survey GLM: the results have one period relation and one gait similarity; "
            "it needs a main grid with cross pairs (several train and test conditions)"
        )
    formulas = {
        "direct": "y ~ " + " + ".join(terms + similarity),
        "interactions": f"y ~ {terms[0]} * ({' + '.join(similarity)})",
    }
    # terms the data cannot tell apart (e.g. same gait = same period when every condition
    # has one frequency) are NaN, as R's lm reports NA (glm.py does too)
    tables = []
    for label, formula in formulas.items():
        fit = fit_formula(formula, frame, alpha)
        term = fit.pop("column").map(_short_term)
        tables.append(pd.concat([pd.DataFrame({"model": label, "term": term}), fit], axis=1))
    out = pd.concat(tables, ignore_index=True)
    out.attrs["n_rows"] = len(frame)
    out.attrs["formulas"] = formulas
    return out


def _short_term(term: str) -> str:
    """``C(learner, Treatment(reference='GMR'))[T.MLP]`` -> ``learner[MLP]``."""
    return re.sub(r"C\((\w+), Treatment\(reference='[^']*'\)\)\[T\.([^\]]+)\]", r"\1[\2]", term)


def seed_tolerance(rows: pd.DataFrame, metric: str = "rmse_vx", k: float = 2.0) -> pd.DataFrame:
    """A recipe's own randomness per training size.

    ``rows``: one learner, one recipe, the same draws fitted with several seeds; columns
    ``n_cycles``, ``seed`` and ``metric`` (mm/s for rmse_vx). m_s(n) is the median of
    ``metric`` over the draws of size n with seed s (the survey's statistic with one seed).

    Returns a frame indexed by ``n_cycles``: ``median`` (over draws and seeds), ``seed_sd``
    (standard deviation of m_s(n) over the seeds, ddof 1), ``tol`` (= k x seed_sd) and
    ``seeds`` (how many). AnalysisError with fewer than two seeds at a size.
    """
    per_seed = rows.groupby(["n_cycles", "seed"])[metric].median().unstack("seed")
    seeds = per_seed.notna().sum(axis=1)
    if len(per_seed) == 0 or int(seeds.min()) < 2:
        raise AnalysisError("seed tolerance: needs at least two seeds at every training size")
    sd = per_seed.std(axis=1, ddof=1)
    return pd.DataFrame(
        {
            "median": rows.groupby("n_cycles")[metric].median(),
            "seed_sd": sd,
            "tol": k * sd,
            "seeds": seeds,
        }
    )


def within_seed_tolerance(
    candidate: pd.DataFrame, tolerance: pd.DataFrame, metric: str = "rmse_vx"
) -> tuple[pd.Series, bool]:
    """(median of ``metric`` over draws and seeds minus the reference's, per size; whether
    every size is within ``tolerance["tol"]``). ``tolerance`` is `seed_tolerance` of the
    reference recipe; a size the candidate lacks counts as outside."""
    diff = candidate.groupby("n_cycles")[metric].median().reindex(tolerance.index)
    diff = diff - tolerance["median"]
    ok = bool(diff.notna().all() and (diff.abs() <= tolerance["tol"]).all())
    return diff, ok


SURVEY_COLUMNS = KEY_COLUMNS + (
    "rmse_vx",
    "rmse_vy",
    "rmse_wz",
    "fit_seconds",
    "predict_seconds",
    "period_rel",
    "gait_sim",
)


def survey_tables(
    store, campaign: str, main_cycles: int = 30, n_boot: int = 1000, model: str = MLP
) -> dict:
    """Everything `suds-exp survey` prints: ``timing`` (`timing_table`); with a sweep,
    ``cycles`` (`cycles_to_target`) and ``ratio`` (`efficiency_ratio` of ``model`` against
    GMR); with cross pairs, ``glm`` (`learner_glm`); ``missing``: why a part is left out
    (see `survey_from_results`)."""
    from suds_exp.analysis.queries import load_results

    results = load_results(store, campaign, columns=SURVEY_COLUMNS)
    return survey_from_results(results, main_cycles, n_boot, model)


def survey_from_results(
    results: pd.DataFrame, main_cycles: int = 30, n_boot: int = 1000, model: str = MLP
) -> dict:
    """`survey_tables` of results already loaded (e.g. several campaigns pooled).

    ``cycles`` and ``ratio`` need a sweep, ``glm`` (`learner_glm`) cross pairs at
    ``main_cycles``; a campaign with one of the two gets what it supports and, under
    ``missing``, the `AnalysisError` that left the rest out. With neither, one
    `AnalysisError` says both.
    """
    out: dict = {"timing": timing_table(results)}
    missing = []
    try:
        sweep_rows(results)
    except AnalysisError as no_sweep:
        missing.append(no_sweep)
    else:
        out["cycles"] = cycles_to_target(results, main_cycles)
        out["ratio"] = efficiency_ratio(results, model, main_cycles=main_cycles, n_boot=n_boot)
    try:
        out["glm"] = learner_glm(results, main_cycles)
    except AnalysisError as no_grid:
        missing.append(no_grid)
    if "cycles" not in out and "glm" not in out:
        raise AnalysisError("; ".join(map(str, missing)), param="sweep")
    if missing:
        out["missing"] = missing
    return out


def survey_json(tables: dict) -> dict:
    """`survey_tables` as one JSON-safe document (NaN and inf -> null)."""

    def clean(v):
        if isinstance(v, float | np.floating) and not np.isfinite(v):
            return None
        return v.item() if isinstance(v, np.generic) else v

    out = {}
    for key, value in tables.items():
        if isinstance(value, pd.DataFrame):
            out[key] = [{k: clean(v) for k, v in r.items()} for r in value.to_dict("records")]
        elif isinstance(value, list):
            out[key] = [str(v) for v in value]
        else:
            out[key] = {k: clean(v) for k, v in value.items()}
    return out


def ratio_sentence(r: dict, cycles: int) -> str:
    """One line stating `efficiency_ratio`'s result."""
    head = f"{r['model']} against {r['reference']}, target {r['reference']}'s {cycles}-cycle error"
    head += f" ({r['target']:.2f} mm/s): "
    if np.isfinite(r["ratio"]):
        head += (
            f"{r['model']} needs {r['ratio']:.2f}x the data ({r['cycles_model']:.1f} against "
            f"{r['cycles_reference']:.1f} cycles)"
        )
    else:
        head += (
            f"{r['model']} does not reach it within the sweep ({r['reference']}: "
            f"{r['cycles_reference']:.1f} cycles)"
        )
    return head + (
        f"; {100 * r['level']:.0f} % interval {r['low']:.2f}-{r['high']:.2f} "
        f"({r['n_boot']} paired bootstrap resamples, {100 * r['unreached']:.0f} % in which "
        f"{r['model']} never reached it)"
    )
