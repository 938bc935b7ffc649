"""The paper's findings F1-F10 as statistics of a campaign's results, with bootstrap intervals.

Each finding of the paper's Results and Discussion is turned into one number computed from
the ``results`` rows of a campaign (see `FINDINGS` for the exact definitions, also in the
README), a 95 % percentile bootstrap interval, and a verdict:

- ``holds``: the whole interval is on the paper's side of the threshold (inside the band);
- ``fails``: the value itself is on the other side;
- ``unclear``: the value is on the paper's side but the interval crosses the threshold;
- ``not measurable``: the campaign lacks the data the statistic needs (the reason says
  which), e.g. no sample-efficiency sweep.

Bootstrap: every learner of a campaign sees the same draws (train condition, test
condition, bootstrap index, training cycles), so a replicate resamples whole draws, with
replacement, within strata of (training cycles, train frequency, test frequency, same gait
or not); learners stay paired and every cell keeps its number of draws. The replicates'
random numbers come from the seed and the campaign's name, so a table is reproducible.

Ratios are ratios of median RMS errors of vx (``a / b`` > 1: ``b`` has the smaller error);
"same-condition pairs" are results trained and tested on the same gait and frequency (on
different trials); the "main size" is the campaign's most common training size (30 cycles
in the paper's design).
"""

from __future__ import annotations

import hashlib
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from suds_exp.analysis.categories import main_cycles
from suds_exp.analysis.findings_view import (  # the table as shown; also read from here
    DESIGN_CAVEAT,
    VERDICTS,
    findings_display,
    findings_headline,
    findings_json,
    findings_summary,
    for_design,
)
from suds_exp.analysis.glm import formula_design, glm_formulas, glm_frame
from suds_exp.errors import AnalysisError
from suds_exp.experiment import is_paper
from suds_exp.models.registry import LEARNERS

__all__ = [
    "DESIGN_CAVEAT", "FEW_CYCLES", "FINDINGS", "FINDINGS_COLUMNS", "VERDICTS", "Finding",
    "NotMeasurable", "findings", "findings_display", "findings_headline", "findings_json",
    "findings_summary", "findings_table", "for_design",
]  # fmt: skip

#: The learners' roles in the findings (names as stored in ``results.model``).
PHASE, TLS, TLSS, GMR, GMRS = LEARNERS
#: A training size of at most this many cycles is "a few cycles" (F8).
FEW_CYCLES = 3
#: Verdicts, in the order a summary lists them.
_DRAW = ["train_gait", "train_frequency_hz", "test_gait", "test_frequency_hz", "boot", "n_cycles"]
#: The columns of ``results_labelled`` the findings read (`findings` loads no others: at
#: 10M results every column left out is 40-80 MB less).
FINDINGS_COLUMNS = ("campaign", "model", *_DRAW, "rmse_vx", "suds", "gmr", "phase_only",
                    "period_rel", "gait_sim")  # fmt: skip


class NotMeasurable(Exception):
    """Raised by a statistic whose data the campaign lacks; the message says which."""


@dataclass(frozen=True)
class Finding:
    """One of the paper's findings and the statistic that tests it.

    ``low``/``high``: the statistic holds when it lies in [low, high] (either may be None:
    no bound). ``parts``: a finding is tested by one or more sub-statistics (F8, F9), each
    a row of the table; the finding holds when all of its parts hold.
    """

    id: str
    finding: str
    paper: str
    statistic: str
    low: float | None
    high: float | None
    compute: Callable[[_Data], float]


@dataclass
class _Data:
    """Draw-level view of a campaign's results (one row per draw, one column per learner)."""

    rmse: np.ndarray  # (n_draws, n_models) RMS error of vx, mm/s; NaN where absent
    models: list[str]
    n_cycles: np.ndarray
    freq: np.ndarray  # test frequency, Hz
    same: np.ndarray  # same-condition pair (gait and frequency)
    main: int
    upper_from: int
    glm: _GlmDesign | None
    stratum: np.ndarray  # bootstrap stratum of each draw
    weights: np.ndarray | None = None  # bootstrap multiplicity of each draw (GLM only)
    fits: dict = field(default_factory=dict)  # GLM coefficients by model, once per replicate

    def col(self, model: str) -> np.ndarray:
        if model not in self.models:
            raise NotMeasurable(f"the campaign has no {model} results")
        return self.rmse[:, self.models.index(model)]

    def take(self, idx: np.ndarray) -> _Data:
        return _Data(
            self.rmse[idx],
            self.models,
            self.n_cycles[idx],
            self.freq[idx],
            self.same[idx],
            self.main,
            self.upper_from,
            self.glm,
            self.stratum[idx],
            np.bincount(idx, minlength=len(self.n_cycles)).astype(float),
        )


def _median(values: np.ndarray) -> float:
    values = values[np.isfinite(values)]
    return float(np.median(values)) if len(values) else np.nan


def _ratio(d: _Data, mask: np.ndarray, num: str, den: str) -> float:
    """median(num) / median(den) over the draws in ``mask``."""
    return _median(d.col(num)[mask]) / _median(d.col(den)[mask])


def _same_main(d: _Data) -> np.ndarray:
    mask = d.same & (d.n_cycles == d.main)
    if not mask.any():
        raise NotMeasurable(f"no same-condition pairs at the main size ({d.main} cycles)")
    return mask


def _frequencies(d: _Data, mask: np.ndarray, at_least: int = 1) -> np.ndarray:
    freqs = np.unique(d.freq[mask])
    if len(freqs) < at_least:
        raise NotMeasurable(
            f"needs at least {at_least} test frequencies; the campaign has {len(freqs)}"
        )
    return freqs


def _per_frequency(d: _Data, mask: np.ndarray, num: str, den: str) -> np.ndarray:
    return np.array(
        [_ratio(d, mask & (d.freq == f), num, den) for f in _frequencies(d, mask)], dtype=float
    )


def _gmean(values: np.ndarray) -> float:
    return float(np.exp(np.mean(np.log(values))))


def _f1(d: _Data) -> float:
    mask = _same_main(d)
    others = [m for m in (TLS, TLSS, GMR, GMRS) if m in d.models]
    if not others:
        raise NotMeasurable("the campaign has no learner besides phase-only")
    d.col(PHASE)
    worst = [
        min(_ratio(d, mask & (d.freq == f), PHASE, m) for m in others)
        for f in _frequencies(d, mask)
    ]
    return float(min(worst))


def _f2(d: _Data) -> float:
    return _gmean(_per_frequency(d, _same_main(d), PHASE, TLS))


def _sizes(d: _Data, at_least: int, mask: np.ndarray | None = None) -> np.ndarray:
    sizes = np.unique(d.n_cycles[d.same if mask is None else mask])
    if len(sizes) < at_least:
        raise NotMeasurable(
            f"needs same-condition pairs at {at_least}+ training sizes (a sample-efficiency "
            f"sweep); the campaign has {len(sizes)}"
        )
    return sizes


def _f3(d: _Data) -> float:
    if not d.same.any():
        raise NotMeasurable("no same-condition pairs")
    return float(
        min(_per_frequency(d, d.same & (d.n_cycles == n), TLS, TLSS).min() for n in _sizes(d, 1))
    )


def _f4(d: _Data) -> float:
    return float(_per_frequency(d, _same_main(d), TLS, GMR).min())


def _upper(d: _Data) -> np.ndarray:
    _sizes(d, 3)
    mask = d.same & (d.n_cycles >= d.upper_from)
    _sizes(d, 2, mask)
    return mask


def _f5(d: _Data) -> float:
    return float(_per_frequency(d, _upper(d), GMR, GMRS).min())


def _slope(n: np.ndarray, rmse: np.ndarray) -> float:
    ok = np.isfinite(rmse) & (rmse > 0)
    x, y = np.log(n[ok]), np.log(rmse[ok])
    if len(np.unique(x)) < 2:
        return np.nan
    x = x - x.mean()
    return float(x @ (y - y.mean()) / (x @ x))


def _f6(d: _Data) -> float:
    mask = _upper(d)
    col = d.col(GMRS)
    return float(
        np.mean(
            [
                _slope(d.n_cycles[m], col[m])
                for f in _frequencies(d, mask)
                for m in [mask & (d.freq == f)]
            ]
        )
    )


def _f7(d: _Data) -> float:
    mask = _same_main(d)
    freqs = _frequencies(d, mask, at_least=2)
    ratios = [
        _median(d.col(m)[mask & (d.freq == hi)]) / _median(d.col(m)[mask & (d.freq == lo)])
        for m in d.models
        for lo, hi in zip(freqs[:-1], freqs[1:], strict=True)
    ]
    return float(min(ratios))


def _few(d: _Data) -> np.ndarray:
    mask = d.same & (d.n_cycles <= FEW_CYCLES)
    if not mask.any():
        raise NotMeasurable(
            f"no same-condition pairs trained on {FEW_CYCLES} cycles or fewer (a sweep such "
            "as 1-10)"
        )
    return mask


def _f8a(d: _Data) -> float:
    mask = _few(d)
    return float(
        min(_per_frequency(d, mask, TLSS, GMR).min(), _per_frequency(d, mask, GMRS, GMR).min())
    )


def _f8b(d: _Data) -> float:
    return float(_per_frequency(d, _few(d), GMRS, TLSS).min())


def _f10(d: _Data) -> float:
    mask = ~d.same & (d.n_cycles == d.main)
    if not mask.any():
        raise NotMeasurable(f"no cross-condition pairs at the main size ({d.main} cycles)")
    return _ratio(d, mask, GMRS, GMR)


@dataclass
class _GlmDesign:
    """The GLM's designs (direct, interactions) as distinct rows and each row's pattern
    (`formula_design`), rows tied to draws."""

    draw: np.ndarray  # draw index of each row
    y: np.ndarray
    patterns: dict[str, np.ndarray]  # (k, q) distinct rows of the identifiable columns
    pattern: dict[str, np.ndarray]  # (n,) each row's pattern
    columns: dict[str, list[str]]


def _glm_design(labelled: pd.DataFrame, draw_index: pd.Series, main: int) -> _GlmDesign | None:
    # the GLM's inputs alone: a copy of every column costs 140 MB per million results
    inputs = ["rmse_vx", "suds", "gmr", "period_rel", "gait_sim", "phase_only"]
    frame = glm_frame(
        labelled.loc[(labelled["n_cycles"] == main) & labelled["gait_sim"].notna(), inputs]
    )
    if len(frame) < 10 or frame["suds"].nunique() < 2 or frame["gmr"].nunique() < 2:
        return None
    direct, interactions, _ = glm_formulas(frame)
    patterns, pattern, columns = {}, {}, {}
    for label, formula in (("direct", direct), ("interactions", interactions)):
        design = formula_design(formula, frame)
        patterns[label] = design.patterns[:, design.keep]
        pattern[label] = design.pattern
        columns[label] = [design.names[j] for j in design.keep]
    draw = draw_index.loc[frame.index].to_numpy()
    return _GlmDesign(draw, frame["y"].to_numpy(), patterns, pattern, columns)


def _glm_coef(label: str, term: str) -> Callable[[_Data], float]:
    def compute(d: _Data) -> float:
        g = d.glm
        if g is None:
            raise NotMeasurable(
                f"the GLM needs 10+ learner results at the main size ({d.main} cycles) with "
                "and without SUDS and GMR"
            )
        if term not in g.columns[label]:
            raise NotMeasurable(f"the {label} GLM cannot separate the {term} term in these results")
        if label not in d.fits:
            # A bootstrap replicate is the full design with each row weighted by how often
            # its draw was drawn: weighted normal equations, identical to refitting on the
            # resampled rows and far cheaper than building their design again.
            # The rows of a pattern share their design row, so the normal equations
            # need only each pattern's total weight and weighted response.
            u, rows = g.patterns[label], g.pattern[label]
            w = np.ones(len(g.y)) if d.weights is None else d.weights[g.draw]
            weight = np.bincount(rows, weights=w, minlength=len(u))
            wy = np.bincount(rows, weights=w * g.y, minlength=len(u))
            d.fits[label] = np.linalg.lstsq((u.T * weight) @ u, u.T @ wy, rcond=None)[0]
        return float(d.fits[label][g.columns[label].index(term)])

    return compute


#: The findings, in the paper's order (ids as in the documentation's findings page).
FINDINGS: tuple[Finding, ...] = (
    Finding(
        "F1",
        "F1",
        "phase-only is the worst learner",
        "min over test frequencies and learners L of median(phase-only) / median(L); "
        "same-condition pairs, main size",
        1.0,
        None,
        _f1,
    ),
    Finding(
        "F2",
        "F2",
        "TLS improves on phase-only about 3x",
        "geometric mean over test frequencies of median(phase-only) / median(TLS); "
        "same-condition pairs, main size",
        2.0,
        4.5,
        _f2,
    ),
    Finding(
        "F3",
        "F3",
        "TLS+SUDS beats TLS 3-10x, at every training size",
        "min over test frequencies and training sizes of median(TLS) / median(TLS+SUDS); "
        "same-condition pairs, every size",
        2.0,
        None,
        _f3,
    ),
    Finding(
        "F4",
        "F4",
        "GMR is far better than TLS (at all frequencies)",
        "min over test frequencies of median(TLS) / median(GMR); same-condition pairs, main size",
        1.5,
        None,
        _f4,
    ),
    Finding(
        "F5",
        "F5",
        "GMR+SUDS beats GMR at high cycle counts",
        "min over test frequencies of median(GMR) / median(GMR+SUDS); same-condition pairs, "
        "training sizes >= the median sweep size",
        1.0,
        None,
        _f5,
    ),
    Finding(
        "F6",
        "F6",
        "GMR+SUDS improves at a log-log slope near -1/2",
        "mean over test frequencies of the least-squares slope of ln RMSE(GMR+SUDS) on "
        "ln cycles; same-condition pairs, sizes >= the median sweep size",
        -0.75,
        -0.25,
        _f6,
    ),
    Finding(
        "F7",
        "F7",
        "error grows with frequency (1/3 < 1/2 < 1 Hz), for every learner",
        "min over learners and adjacent test frequencies of median(higher) / median(lower); "
        "same-condition pairs, main size",
        1.0,
        None,
        _f7,
    ),
    Finding(
        "F8a",
        "F8",
        "with few cycles GMR beats both SUDS learners",
        f"min over test frequencies of median(TLS+SUDS or GMR+SUDS) / median(GMR); "
        f"same-condition pairs, sizes <= {FEW_CYCLES} cycles",
        1.0,
        None,
        _f8a,
    ),
    Finding(
        "F8b",
        "F8",
        "with few cycles TLS+SUDS is as good as (or better than) GMR+SUDS",
        f"min over test frequencies of median(GMR+SUDS) / median(TLS+SUDS); same-condition "
        f"pairs, sizes <= {FEW_CYCLES} cycles (as good: within 10 %)",
        0.9,
        None,
        _f8b,
    ),
    Finding(
        "F9a",
        "F9",
        "GLM: SUDS lowers the error (direct effects: -16.6)",
        "SUDS coefficient of the direct-effects GLM of 100 ln RMSE(vx); all pairs, main size, "
        "phase-only left out",
        None,
        0.0,
        _glm_coef("direct", "suds"),
    ),
    Finding(
        "F9b",
        "F9",
        "GLM: GMR lowers the error (direct effects: -24.3)",
        "GMR coefficient of the direct-effects GLM of 100 ln RMSE(vx); all pairs, main size, "
        "phase-only left out",
        None,
        0.0,
        _glm_coef("direct", "gmr"),
    ),
    Finding(
        "F9c",
        "F9",
        "GLM: the SUDS x GMR interaction is positive (+40.4)",
        "SUDS:GMR coefficient of the first-order-interactions GLM of 100 ln RMSE(vx); all "
        "pairs, main size, phase-only left out",
        0.0,
        None,
        _glm_coef("interactions", "suds:gmr"),
    ),
    Finding(
        "F10",
        "F10",
        "across conditions GMR beats GMR+SUDS",
        "median(GMR+SUDS) / median(GMR) over cross-condition pairs (gait or frequency "
        "differs), main size",
        1.0,
        None,
        _f10,
    ),
)


def _draw_frame(results: pd.DataFrame, upper_from: int | None) -> _Data:
    if results.empty:
        raise AnalysisError("no results: nothing to measure")
    main = main_cycles(results)
    keys = results[_DRAW].copy()
    keys["train_frequency_hz"] = keys["train_frequency_hz"].round(6)
    keys["test_frequency_hz"] = keys["test_frequency_hz"].round(6)
    draw_index = pd.Series(keys.groupby(_DRAW, sort=True).ngroup().to_numpy(), index=results.index)
    wide = (
        pd.DataFrame({"draw": draw_index, "model": results["model"], "rmse": results["rmse_vx"]})
        .pivot_table(index="draw", columns="model", values="rmse", aggfunc="first")
        .sort_index()
    )
    first = keys.assign(draw=draw_index).drop_duplicates("draw").set_index("draw").sort_index()
    same = (first["train_gait"] == first["test_gait"]) & (
        first["train_frequency_hz"] == first["test_frequency_hz"]
    )
    sizes = np.sort(first.loc[same, "n_cycles"].unique())
    # Strata keep every (size, train frequency, test frequency, same gait) cell's number
    # of draws in each replicate, so a statistic of one cell never sees an empty cell.
    stratum = first.groupby(
        [
            first["n_cycles"],
            first["train_frequency_hz"],
            first["test_frequency_hz"],
            first["train_gait"] == first["test_gait"],
        ]
    ).ngroup()
    start = (int(np.median(sizes)) if len(sizes) else main) if upper_from is None else upper_from
    rmse = wide.reindex(first.index).to_numpy(dtype=float)
    models = [str(m) for m in wide.columns]
    # a row of keys per result is not needed past here: freed before the GLM's design
    del keys, wide
    return _Data(
        rmse=rmse,
        models=models,
        n_cycles=first["n_cycles"].to_numpy(dtype=int),
        freq=first["test_frequency_hz"].to_numpy(dtype=float),
        same=same.to_numpy(dtype=bool),
        main=main,
        upper_from=int(start),
        glm=_glm_design(results, draw_index, main) if "phase_only" in results else None,
        stratum=stratum.to_numpy(),
    )


def _strata(d: _Data) -> list[np.ndarray]:
    order = np.argsort(d.stratum, kind="stable")
    bounds = np.flatnonzero(np.diff(d.stratum[order])) + 1
    return np.split(order, bounds)


def _seed(campaign: str, seed: int) -> np.random.SeedSequence:
    digest = hashlib.sha256(f"findings|{campaign}".encode()).digest()[:8]
    return np.random.SeedSequence([int(seed), int.from_bytes(digest, "little")])


def _verdict(f: Finding, value: float, low: float, high: float) -> str:
    def inside(x: float) -> bool:
        return (f.low is None or x > f.low) and (f.high is None or x < f.high)

    if not np.isfinite(value) or not inside(value):
        return "fails"
    if np.isfinite(low) and np.isfinite(high) and inside(low) and inside(high):
        return "holds"
    return "unclear"


def _threshold(f: Finding) -> str:
    if f.low is not None and f.high is not None:
        return f"in ({f.low:g}, {f.high:g})"
    return f"> {f.low:g}" if f.low is not None else f"< {f.high:g}"


def findings_table(
    results: pd.DataFrame,
    *,
    n_boot: int = 400,
    seed: int = 0,
    campaign: str | None = None,
    upper_from: int | None = None,
    confidence: float = 0.95,
) -> pd.DataFrame:
    """The paper's findings measured on labelled results (see `load_results`).

    Parameters
    ----------
    results : DataFrame
        Rows of ``results_labelled`` of one campaign.
    n_boot : int
        Bootstrap replicates (resampled draws, see the module docstring); 0: no interval.
    seed : int
        Seed of the replicates (combined with the campaign's name).
    campaign : str, optional
        Name mixed into the seed; default the ``campaign`` column's first value.
    upper_from : int, optional
        First training size of "high cycle counts" (F5, F6); default the median of the
        same-condition training sizes, as `slope_table`.
    confidence : float
        Coverage of the percentile interval.

    Returns
    -------
    DataFrame, one row per statistic: ``id`` (F1 ... F10, parts F8a/F8b, F9a-c),
    ``finding`` (F1 ... F10), ``paper`` (the paper's statement), ``statistic`` (its
    definition), ``threshold`` (where it must lie for the finding to hold), ``value``,
    ``low``, ``high`` (interval; ratios are unitless, GLM coefficients on 100 ln scale,
    slopes per ln cycle), ``verdict`` (holds / unclear / fails / not measurable),
    ``holds`` (boolean, NA when not measurable) and ``reason`` (why not measurable).
    ``attrs``: ``main_cycles``, ``upper_from``, ``n_results``, ``n_draws``, ``n_boot``,
    ``seed``.
    """
    if not isinstance(n_boot, int) or n_boot < 0:
        raise AnalysisError(f"n_boot {n_boot!r}: expected an integer >= 0", param="n_boot")
    if not 0 < confidence < 1:
        raise AnalysisError(f"confidence {confidence!r}: expected a number in (0, 1)")
    finite = np.isfinite(results["rmse_vx"].to_numpy(float))
    if not finite.all():  # `load_results` gives finite rows only: then no copy of them
        results = results[finite]
    data = _draw_frame(results, upper_from)
    name = campaign if campaign is not None else str(results["campaign"].iloc[0])
    rng = np.random.default_rng(_seed(name, seed))
    alpha = (1 - confidence) / 2
    # One BLAS thread for the GLM fits: the matrices are small (see `glm`); set once, as
    # finding the BLAS libraries costs more than a fit.
    with threadpool_limits(limits=1, user_api="blas"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        values, boots, reasons = _bootstrap(data, rng, n_boot)
    rows = [_row(f, values.get(f.id), boots.get(f.id), reasons.get(f.id), alpha) for f in FINDINGS]
    table = pd.DataFrame(rows)
    table["holds"] = table["holds"].astype("boolean")
    table.attrs = {
        "main_cycles": data.main,
        "upper_from": data.upper_from,
        "n_results": len(results),
        "n_draws": len(data.n_cycles),
        "n_boot": n_boot,
        "seed": seed,
    }
    return table


def _bootstrap(
    data: _Data, rng: np.random.Generator, n_boot: int
) -> tuple[dict[str, float], dict[str, list[float]], dict[str, str]]:
    """Every finding's statistic on the data and on ``n_boot`` replicates (resampled
    within strata), one replicate in memory at a time: (value by id, replicate values by
    id, why not measurable by id). A statistic not measurable on the data or on any
    replicate is not measurable."""
    values: dict[str, float] = {}
    reasons: dict[str, str] = {}
    for f in FINDINGS:
        try:
            values[f.id] = f.compute(data)
        except NotMeasurable as exc:
            reasons[f.id] = str(exc)
    boots: dict[str, list[float]] = {i: [] for i in values}
    strata = _strata(data)
    for _ in range(n_boot):
        idx = np.concatenate([s[rng.integers(len(s), size=len(s))] for s in strata])
        replicate = data.take(idx)
        for f in FINDINGS:
            if f.id in reasons:
                continue
            try:
                boots[f.id].append(f.compute(replicate))
            except NotMeasurable as exc:
                reasons[f.id] = str(exc)
    return values, boots, reasons


def _row(
    f: Finding, value: float | None, boots: list[float] | None, reason: str | None, alpha: float
) -> dict:
    """One row of the findings table from ``f``'s value and replicate values."""
    row = {
        "id": f.id,
        "finding": f.finding,
        "paper": f.paper,
        "statistic": f.statistic,
        "threshold": _threshold(f),
        "value": np.nan,
        "low": np.nan,
        "high": np.nan,
        "verdict": "not measurable",
        "holds": pd.NA,
        "reason": "",
    }
    if reason is not None:
        row["reason"] = reason
        return row
    boots = np.asarray(boots, dtype=float)
    boots = boots[np.isfinite(boots)]
    low, high = np.quantile(boots, [alpha, 1 - alpha]) if len(boots) else (np.nan, np.nan)
    verdict = _verdict(f, value, low, high)
    row.update(value=value, low=low, high=high, verdict=verdict, holds=verdict == "holds")
    return row


#: What the findings say on a design other than the paper's (``{source}``: its file).
def findings(store, campaign: str, design=None, **kwargs) -> pd.DataFrame:
    """`findings_table` of campaign ``campaign`` in ``store`` (keyword options as there,
    except that ``n_boot`` must be >= 1: a verdict needs its interval). ``design``: the
    experiment (default the one stored with the data, `suds_exp.ingest.design_for`); on
    one other than the paper's the table is `for_design`'s."""
    from suds_exp.analysis.queries import load_results
    from suds_exp.ingest import design_for

    n_boot = kwargs.get("n_boot", 1)
    if isinstance(n_boot, bool) or not isinstance(n_boot, int) or n_boot < 1:
        raise AnalysisError(
            f"n_boot {n_boot!r}: expected an integer >= 1 (replicates of the intervals "
            "the verdicts rest on)",
            param="n_boot",
        )
    results = load_results(store, campaign, columns=FINDINGS_COLUMNS)
    table = findings_table(results, campaign=campaign, **kwargs)
    design = design_for(store, design)
    if is_paper(design):
        return table
    source = design.source
    # the paper's, with conditions added after it (gait design --verify, plan loop)
    if is_paper(design.declared()):
        source = f"{source} with {len(design.added_labels)} added level(s)"
    return for_design(table, source)
