"""Which candidates the held-out test calls significant (`adjust_in_training_order`), and
which named ones are only partial because their fit is pinned at a range edge
(`CandidateResult.at_range_edge`).

The raw p-values come from the held-out trials; the order in which they are tested comes
from the training trials alone. These tests build candidate results by hand, so they run
in milliseconds and say exactly what the decision does with given numbers.
"""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.discrepancy.effects import Candidate
from suds_exp.discrepancy.fit_candidates import CandidateResult, adjust_in_training_order


def _result(label: str, train_after: float, p: float) -> CandidateResult:
    r = CandidateResult(Candidate(effect=label, param=None, label=label))
    r.train_before, r.train_after, r.p_value = 1.0, train_after, p
    return r


def test_the_candidate_best_on_training_is_tested_at_the_full_level():
    # nine candidates, the best on training has held-out p 0.002: Bonferroni would make
    # it 0.018 and name nothing at 0.01 (the spoke case of the slow hit-rate test)
    results = [_result("spokes", 0.3, 0.002)] + [
        _result(f"other{k}", 0.99 + k * 1e-3, 1.0) for k in range(8)
    ]
    adjust_in_training_order(results, alpha=0.01)
    assert results[0].significant and results[0].p_adjusted == pytest.approx(0.002)
    assert not any(r.significant for r in results[1:])


def test_testing_stops_at_the_first_candidate_that_fails():
    # the best on training fails its held-out test: a later candidate with a tiny p is
    # not significant, its adjusted p is the larger one before it
    results = [_result("a", 0.2, 0.4), _result("b", 0.5, 1e-6), _result("c", 0.1, 0.001)]
    adjust_in_training_order(results, alpha=0.01)
    by = {r.candidate.label: r for r in results}
    assert by["c"].significant  # first in training order
    assert not by["a"].significant and not by["b"].significant
    assert by["b"].p_adjusted == pytest.approx(0.4)


def test_a_candidate_without_a_training_loss_goes_last():
    results = [_result("nan", np.nan, 1e-9), _result("fit", 0.9, 0.5)]
    adjust_in_training_order(results, alpha=0.01)
    assert not results[0].significant
    assert results[0].p_adjusted == pytest.approx(0.5)


def test_family_wise_error_stays_at_alpha_under_the_null():
    # held-out p-values uniform and independent of the training order (disjoint trials):
    # the chance that anything is called significant is alpha, whatever the family size
    rng = np.random.default_rng(0)
    alpha, n_families, hits = 0.05, 4000, 0
    for _ in range(n_families):
        results = [_result(f"c{k}", rng.uniform(), rng.uniform()) for k in range(9)]
        adjust_in_training_order(results, alpha=alpha)
        hits += any(r.significant for r in results)
    rate = hits / n_families
    # binomial standard error at 4000 families is 0.0034
    assert abs(rate - alpha) < 0.012, rate


def _fitted(value: float | None, bounds=(0.0, 200.0), param: str | None = "damping"):
    r = CandidateResult(Candidate("hinge_damping", "hinge_damping", param, bounds))
    r.value = value
    return r


def test_a_fit_pinned_at_either_edge_of_its_realistic_range_is_at_the_edge():
    # locked flippers mimicked by hinge damping (seed 102) and a drag scale (seed 103)
    assert _fitted(200.0).at_range_edge
    assert _fitted(0.5, bounds=(0.5, 2.0)).at_range_edge
    # hidden true effects near the top of their range (hit-rate runs) are not
    assert not _fitted(189.5).at_range_edge
    assert not _fitted(58.06, bounds=(0.0, 60.0)).at_range_edge
    assert not _fitted(None, param=None).at_range_edge


def test_a_named_effect_prints_rounded(capsys):
    from types import SimpleNamespace

    from suds_exp.commands.discrepancy import print_discrepancy

    named = {
        "step": 0,
        "candidate": "body_inertia",
        "parameter": "tau_s",
        "value": 0.302375,
        "unit": "s",
        "ci": [0.293375, 0.31187499999999996],
        "p_adjusted": 7.1e-37,
        "gap_before": 1.346,
        "gap_after": 0.00175,
    }
    result = SimpleNamespace(named=[named], discovery=None, outcome="named", report_dir="r")
    print_discrepancy(result)
    out = capsys.readouterr().out
    assert "tau_s = 0.3024 s [0.2934, 0.3119] (p_adj 7.1e-37)" in out, out
