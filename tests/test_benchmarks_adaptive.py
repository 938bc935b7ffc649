"""The adaptive benchmark's comparison of the gait goal with its black-box peers: several
runs a dataset seed, summarised by medians that count a run that never reached a level as
beyond any budget, and the plan loop's ratio of medians to each peer's."""

from benchmarks.studies.adaptive import job_seed, over_runs, ratios, run_stats


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
