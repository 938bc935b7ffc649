"""GLM and slope fits on synthetic results with effects of known size planted in them.

Why these tests are reliable and not seed-shopped: a single 95 % interval misses its true
value 5 % of the time, so the chance that all 20 intervals of the interaction model cover
is only about 0.95**20 = 36 % for an arbitrary seed. The recovery and null tests
therefore ask for Bonferroni intervals (alpha = 0.001 / number of terms, which
`glm_table` exposes as ``alpha``): for ANY seed all of them cover with probability at
least 99.9 %, and the fixed seed only makes the run repeatable. They still have teeth:
the planted values are 8 apart and the intervals are asserted narrower than that, so a
wrong reference level, a swapped term name or a wrong response scale falls outside. The
95 % intervals the report prints are checked separately for calibration: over many seeds
they must cover about 95 % of the planted values.
"""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.analysis import glm_table, load_results, slope_table
from suds_exp.store import Store
from suds_exp.testing.synthetic_results import synthetic_results

DIRECT_TERMS = [
    "SUDS",
    "GMR",
    "model-period<data-period",
    "model-period=data-period",
    "model-gait=data-gait",
    "model-gait far from data-gait",
]
INTERACTION_TERMS = DIRECT_TERMS + [
    "SUDS:GMR",
    "SUDS:(model-period<data-period)",
    "SUDS:(model-period=data-period)",
    "GMR:(model-period<data-period)",
    "GMR:(model-period=data-period)",
    "SUDS:(model-gait=data-gait)",
    "SUDS:(model-gait far from data-gait)",
    "GMR:(model-gait=data-gait)",
    "GMR:(model-gait far from data-gait)",
    "(model-period<data-period):(model-gait=data-gait)",
    "(model-period<data-period):(model-gait far from data-gait)",
    "(model-period=data-period):(model-gait=data-gait)",
    "(model-period=data-period):(model-gait far from data-gait)",
]
# 19 distinct values 8 apart (-72 .. 72), dealt to the terms in a fixed shuffled order, so
# no two terms share a size and a mix-up between any two of them is 8+ units off.
_values = np.random.default_rng(11).permutation(np.arange(-72, 73, 8))
PLANTED = {"Intercept": 100.0, **dict(zip(INTERACTION_TERMS, _values.tolist(), strict=True))}
PLANTED_DIRECT = {
    "Intercept": 100.0,
    **dict(zip(DIRECT_TERMS, [-40, -24, -8, 16, -32, 8], strict=True)),
}
NOISE = 10.0  # sd on the 100 ln scale: RMS errors scattered by about x/÷ 1.1
N_BOOT = 6  # 4 learners x 225 condition pairs x 6 = 5400 rows per fit
LEARNERS = ("TLS", "TLS+SUDS", "GMR", "GMR+SUDS")


@pytest.fixture(scope="module")
def store(tmp_path_factory) -> Store:
    store = Store(tmp_path_factory.mktemp("glm") / "glm.duckdb")
    frames = [
        synthetic_results("planted", PLANTED, n_boot=N_BOOT, noise=NOISE, models=LEARNERS, seed=1),
        synthetic_results(
            "direct", PLANTED_DIRECT, n_boot=N_BOOT, noise=NOISE, models=LEARNERS, seed=2
        ),
        synthetic_results(
            "null", {"Intercept": 100.0}, n_boot=N_BOOT, noise=NOISE, models=LEARNERS, seed=3
        ),
        *[
            synthetic_results(
                f"calib{s}", PLANTED, n_boot=1, noise=NOISE, models=LEARNERS, seed=100 + s
            )
            for s in range(CALIBRATION_SEEDS)
        ],
    ]
    with store.write() as conn:
        for frame in frames:
            store.insert_df(conn, "results", frame)
    return store


CALIBRATION_SEEDS = 20


def _bonferroni(n_terms: int) -> float:
    return 0.001 / n_terms


def test_interaction_model_recovers_every_planted_coefficient(store):
    table = glm_table(load_results(store, "planted"), alpha=_bonferroni(len(PLANTED)))
    got = table[table["model"] == "interactions"].set_index("term")
    assert sorted(got.index) == sorted(PLANTED)
    for term, value in PLANTED.items():
        row = got.loc[term]
        assert row.ci_low <= value <= row.ci_high, (term, value, row.coef, row.ci_low, row.ci_high)
        assert row.ci_high - row.ci_low < 8.0, (
            term
        )  # narrower than the spacing of the planted values


def test_direct_model_recovers_planted_direct_effects(store):
    table = glm_table(load_results(store, "direct"), alpha=_bonferroni(len(PLANTED_DIRECT)))
    got = table[table["model"] == "direct"].set_index("term")
    assert sorted(got.index) == sorted(PLANTED_DIRECT)
    for term, value in PLANTED_DIRECT.items():
        assert got.loc[term, "ci_low"] <= value <= got.loc[term, "ci_high"], term
        assert got.loc[term, "ci_high"] - got.loc[term, "ci_low"] < 4.0, term


def test_with_no_effects_every_interval_covers_zero(store):
    results = load_results(store, "null")
    for model, n in (("direct", 7), ("interactions", 20)):
        table = glm_table(results, alpha=_bonferroni(n))
        got = table[(table["model"] == model) & (table["term"] != "Intercept")]
        assert len(got) == n - 1
        assert (got["ci_low"] <= 0).all() and (got["ci_high"] >= 0).all(), got
        assert ((got["ci_high"] - got["ci_low"]) < 8.0).all()


def test_report_intervals_are_calibrated_95_percent(store):
    covered = total = 0
    for s in range(CALIBRATION_SEEDS):
        table = glm_table(load_results(store, f"calib{s}"))  # the report's 95 % intervals
        got = table[table["model"] == "interactions"].set_index("term")
        for term, value in PLANTED.items():
            covered += got.loc[term, "ci_low"] <= value <= got.loc[term, "ci_high"]
            total += 1
    # 400 intervals: the covered fraction has sd 1.1 %; 90-99 % is -4.6 to +3.7 sd.
    assert 0.90 <= covered / total <= 0.99, covered / total


def test_reference_levels_and_order_are_the_papers(store):
    table = glm_table(load_results(store, "planted"))
    assert table.attrs["reference"] == {
        "period_rel": "model-period>data-period",
        "gait_sim": "model-gait near data-gait",
    }
    assert "Treatment(reference='>')" in table.attrs["formulas"]["direct"]
    assert "Treatment(reference='near')" in table.attrs["formulas"]["interactions"]
    for _, part in table.groupby("model"):
        assert part["term"].iloc[0] == "Intercept"
        mags = part["coef"].abs().to_numpy()[1:]
        assert (np.diff(mags) <= 0).all()


def test_phase_only_is_left_out_and_does_not_bias_the_fit(tmp_path):
    store = Store(tmp_path / "po.duckdb")
    rows = synthetic_results(
        "po", PLANTED_DIRECT, n_boot=N_BOOT, noise=NOISE, seed=5, phase_only_offset=500.0
    )
    with store.write() as conn:
        store.insert_df(conn, "results", rows)
    table = glm_table(load_results(store, "po"), alpha=_bonferroni(7))
    got = table[table["model"] == "direct"].set_index("term")
    assert table.attrs["n_rows"] == 4 * 225 * N_BOOT
    assert got.loc["Intercept", "ci_low"] <= 100.0 <= got.loc["Intercept", "ci_high"]


def test_sample_efficiency_slopes_recover_planted_power_laws(tmp_path):
    slopes = {"phase-only": 0.0, "TLS": -0.1, "TLS+SUDS": -0.2, "GMR": -0.35, "GMR+SUDS": -0.5}
    store = Store(tmp_path / "eff.duckdb")
    rows = synthetic_results(
        "eff",
        {"Intercept": 100.0},
        n_boot=2,
        n_cycles=(1, 2, 4, 8, 16, 32),
        slopes=slopes,
        noise=NOISE,
        seed=6,
    )
    with store.write() as conn:
        store.insert_df(conn, "results", rows)
    table = slope_table(load_results(store, "eff"))
    assert len(table) == 3 * 5
    assert (table["cycles_from"] == 8).all() and (table["cycles_to"] == 32).all()
    for r in table.itertuples():
        half = (r.ci_high - r.ci_low) / 2
        # Twice the 95 % half-width is ~3.9 standard errors: P(miss) ~1e-4 per slope.
        assert abs(r.slope - slopes[r.model]) <= 2 * half, r
        assert half < 0.1, r


def test_fit_formula_is_ols_with_aliased_columns_nan():
    """The one GLM fit: OLS estimates, and NaN for a column equal to an earlier one."""
    import pandas as pd

    from suds_exp.analysis.glm import fit_formula

    rng = np.random.default_rng(0)
    x = rng.normal(size=50)
    frame = pd.DataFrame({"y": 2.0 + 3.0 * x + rng.normal(0, 0.01, 50), "x": x, "x2": x})
    fit = fit_formula("y ~ x + x2", frame)
    assert fit["column"].tolist() == ["Intercept", "x", "x2"]
    assert fit["coef"].iloc[:2].to_numpy() == pytest.approx([2.0, 3.0], abs=0.01)
    assert np.isnan(fit["coef"].iloc[2]) and fit.attrs["keep"] == [0, 1]
    assert (fit["ci_low"].iloc[:2] < fit["coef"].iloc[:2]).all()


def test_the_glm_from_pattern_counts_is_the_row_by_row_ols(store):
    """The report's GLM (fitted from each distinct design row's count, mean and spread)
    gives statsmodels' OLS on every row: estimates, intervals and p-values to rounding,
    aliased terms included."""
    import statsmodels.formula.api as smf

    from suds_exp.analysis.glm import (
        fit_design,
        fit_formula,
        formula_design,
        glm_formulas,
        glm_frame,
    )

    frame = glm_frame(load_results(store, "planted"))
    # one category combination left out: its interaction term cannot be separated
    frame = frame[~((frame["gmr"] == 1) & (frame["gait_sim"] == "same"))]
    direct, interactions, _ = glm_formulas(frame)
    for formula in (direct, interactions):
        design = formula_design(formula, frame)
        assert len(design.patterns) <= 36 < len(frame)
        np.testing.assert_array_equal(design.exog, smf.ols(formula, frame).exog)
        grouped, rows = fit_design(design), fit_formula(formula, frame, method="qr")
        assert grouped.attrs["keep"] == rows.attrs["keep"]
        for col in ("coef", "ci_low", "ci_high", "p_value"):
            np.testing.assert_allclose(grouped[col], rows[col], rtol=1e-9, atol=1e-12)
    assert grouped["coef"].isna().any()
