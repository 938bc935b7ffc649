"""Comparing gait-finding runs by the cycles they need (`suds_exp.plan.compare`, used by
the adaptive benchmark): medians over runs that count a run that never reached a level as
beyond any budget, and the plan loop's ratio of medians to each peer's."""

import pandas as pd
import pytest

from suds_exp.plan.compare import (
    job_seed,
    over_runs,
    ratios,
    read_curves,
    run_entry,
    run_stats,
    summary_from_curves,
)


def _runs(to80, to90):
    return over_runs(
        [
            {"cycles_to_80": a, "cycles_to_90": b, "share_of_ceiling": 1.0}
            for a, b in zip(to80, to90, strict=True)
        ]
    )


def test_a_run_that_never_reached_a_level_counts_beyond_the_budget():
    one_missed = run_stats([25, 35, None])
    assert (one_missed["median"], one_missed["min"], one_missed["max"]) == (35, 25, None)
    assert one_missed["missed"] == 1
    # two of three runs missed: the median run missed, so there is no median count
    assert run_stats([None, 10, None])["median"] is None
    assert run_stats([10, 20])["median"] == 15


def test_the_ratio_is_of_medians_and_a_bound_where_the_peer_missed():
    arms = {
        "plan": {"0": _runs([25, 30, 35], [35, 40, 45]), "1": _runs([20, 20, 20], [20, 20, 20])},
        "bo": {
            "0": _runs([15, 80, None, 50, 60], [80, None, None, 95, 100]),
            "1": _runs([None] * 5, [None] * 5),
        },
    }
    out = ratios(arms, budget=50, peer_budget=150)
    assert out["bo"]["0"]["80"] == {"ratio": round(30 / 60, 3), "peer_missed": False}
    assert out["bo"]["0"]["90"] == {"ratio": round(40 / 100, 3), "peer_missed": False}
    # BO's median run never reached 90 %: it needs more than 150, the ratio is at most 20/150
    assert out["bo"]["1"]["90"] == {"ratio": round(20 / 150, 3), "peer_missed": True}


def test_repeat_zero_is_the_dataset_seed_and_later_runs_draw_their_own():
    assert job_seed("plan", 1, 0) == 1
    seeds = {job_seed(arm, s, r) for arm in ("plan", "bo") for s in (0, 1) for r in (1, 2)}
    assert len(seeds) == 8 and seeds.isdisjoint({0, 1})
    assert job_seed("bo", 1, 2) == job_seed("bo", 1, 2)


def _curve(arm, seed, repeat, cycles, best):
    return [
        {"goal": "gait", "arm": arm, "seed": seed, "repeat": repeat, "cycles": c,
         "best_forward_mm": b}
        for c, b in zip(cycles, best, strict=True)
    ]  # fmt: skip


def test_the_summary_is_recomputed_from_stored_curves_against_another_ceiling():
    frame = pd.DataFrame(
        _curve("plan", 0, 0, [5, 10, 15], [40.0, 58.0, 66.0])
        + _curve("plan", 0, 1, [5, 10, 15], [30.0, 50.0, 52.0])
        + _curve("plan", 0, 2, [5, 10, 15], [61.0, 61.0, 61.0])
        + _curve("bo", 0, 0, [5, 10, 15, 20], [10.0, 20.0, 55.0, 70.0])
    )
    low = summary_from_curves(frame, ceiling=64.0, budget=15, peer_budget=20)
    # 80 % of 64 is 51.2, 90 % 57.6: the runs reach them at 10, 15, 5 and 10, never, 5
    assert low["arms"]["plan"]["0"]["cycles_to_80"]["runs"] == [10, 15, 5]
    assert low["arms"]["plan"]["0"]["cycles_to_90"]["runs"] == [10, None, 5]
    high = summary_from_curves(frame, ceiling=80.0, budget=15, peer_budget=20)
    # 80 % of 80 is 64: only run 0 reaches it; 90 % (72) nobody: the median is beyond
    assert high["arms"]["plan"]["0"]["cycles_to_80"]["runs"] == [15, None, None]
    assert high["arms"]["plan"]["0"]["cycles_to_90"]["median"] is None
    # BO is read at the loop's budget too: its best within 15 cycles is 55 of 80
    assert high["arms"]["bo"]["0"]["median_share_at_budget"] == round(55 / 80, 3)
    assert high["arms"]["bo"]["0"]["median_share_of_ceiling"] == round(70 / 80, 3)
    # the loop's median run never reached 80 % of 80 (BO did, at 20): no ratio
    assert high["arms"]["bo"]["0"]["cycles_to_80"]["median"] == 20
    assert high["ratios"]["bo"]["0"]["80"] == {"ratio": None, "peer_missed": False}


def test_a_later_curves_file_replaces_an_earlier_ones_runs_of_the_same_arm_and_seed(tmp_path):
    first, second = tmp_path / "a.csv", tmp_path / "b.csv"
    pd.DataFrame(_curve("bo", 1, 0, [5], [10.0]) + _curve("plan", 1, 0, [5], [20.0])).to_csv(
        first, index=False
    )
    pd.DataFrame(_curve("bo", 1, 0, [5, 300], [10.0, 80.0])).to_csv(second, index=False)
    frame = read_curves([first, second])
    assert sorted(frame.loc[frame["arm"] == "bo", "cycles"]) == [5, 300]
    assert list(frame.loc[frame["arm"] == "plan", "cycles"]) == [5]


def test_a_run_with_no_count_within_the_budget_has_no_share_there():
    # the designer's one run starts beyond the learning arms' budget (the full grid)
    runs = [run_entry([{"cycles": 1222, "best_forward_mm": 76.2}], ceiling=146.3, budget=50)]
    assert runs[0]["share_at_budget"] is None
    out = over_runs(runs)
    assert "median_share_at_budget" not in out
    assert out["median_share_of_ceiling"] == pytest.approx(0.521)
