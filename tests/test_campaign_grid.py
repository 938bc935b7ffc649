"""Campaign grid, seeds from keys, bootstrap sampling and decimation (library faces)."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.campaign import CampaignError, Draw, SampleBank, enumerate_draws, parse_int_list
from suds_exp.campaign.conditions import select_conditions
from suds_exp.campaign.sampling import draw_sample
from suds_exp.testing.synthetic_samples import synthetic_samples


@pytest.fixture(scope="module")
def bank() -> SampleBank:
    return SampleBank.build(synthetic_samples(conditions=(("O", 1 / 3), ("O", 0.5), ("O", 1.0))))


def test_every_frequency_is_decimated_to_the_same_samples_per_cycle(bank):
    assert bank.samples_per_cycle == 20
    assert bank.decimation == {0.333333: 3, 0.5: 2, 1.0: 1}
    col = bank.columns.index("cycle")
    for i in range(len(bank.trial_ids)):
        a, b = bank.runs[i][0]
        counts = [
            np.sum(bank.values[bank.row_start[i] : bank.row_stop[i], col] == c)
            for c in range(a, b + 1)
        ]
        assert all(19 <= c <= 21 for c in counts), counts
    # plain decimation: every k-th raw sample, unfiltered values
    raw = synthetic_samples(conditions=(("O", 1 / 3), ("O", 0.5), ("O", 1.0)))
    first = raw[raw.trial_id == bank.trial_ids[0]]
    block = bank.values[bank.row_start[0] : bank.row_stop[0]]
    np.testing.assert_array_equal(block[:, bank.columns.index("vx")], first["vx"].to_numpy()[::3])


def test_only_complete_cycles_are_used(bank):
    raw = synthetic_samples(conditions=(("O", 1 / 3), ("O", 0.5), ("O", 1.0)))
    n_partial = 0
    for i, tid in enumerate(bank.trial_ids):
        trial = raw[raw.trial_id == tid]
        step = np.median(np.diff(trial.phase))
        span = trial.groupby("cycle").phase.agg(lambda p: p.max() - p.min())
        used = {c for a, b in bank.runs[i] for c in range(a, b + 1)}
        complete = set(span.index[span >= 2 * np.pi - 2.5 * step])
        assert used == complete
        n_partial += len(span) - len(used)
    assert n_partial > len(bank.trial_ids)  # most trials start and end mid-cycle


def test_a_draw_is_the_same_whenever_it_is_made_and_differs_between_keys(bank):
    d = Draw("c", ("O", 0.5), ("O", 0.5), 3, 5)
    first = draw_sample(bank, d, 5)
    again = draw_sample(bank, Draw("c", ("O", 0.5), ("O", 0.5), 3, 5), 5)
    assert first == again
    others = {str(draw_sample(bank, Draw("c", ("O", 0.5), ("O", 0.5), b, 5), 5)) for b in range(12)}
    assert len(others) > 6


def test_training_cycles_come_from_other_trials_and_add_up(bank):
    for boot in range(30):
        for n in (1, 5, 12, 20):
            d = Draw("c", ("O", 1.0), ("O", 1.0), boot, n)
            s = draw_sample(bank, d, 5)
            assert sum(b - a + 1 for _, a, b in s.train) == n
            assert s.test[0] not in {i for i, _, _ in s.train}
            assert s.test[2] - s.test[1] + 1 == min(5, bank.n_cycles(s.test[0]))
            for i, a, b in s.train:
                assert any(ra <= a and b <= rb for ra, rb in bank.runs[i])
                assert bank.trial_condition[i] == ("O", 1.0)


def test_too_many_cycles_is_refused_naming_the_condition(bank):
    with pytest.raises(CampaignError, match="O@1"):
        draw_sample(bank, Draw("c", ("O", 1.0), ("O", 1.0), 0, 500), 5)


def test_grid_has_the_main_pairs_and_the_same_condition_sweep():
    conds = [("O", 0.5), ("D+", 1.0)]
    draws = enumerate_draws("c", conds, conds, 3, 30, [1, 2, 30])
    main = [d for d in draws if d.n_cycles == 30]
    assert len(main) == 2 * 2 * 3
    sweep = [d for d in draws if d.n_cycles != 30]
    assert len(sweep) == 2 * 3 * 2 and all(d.train == d.test for d in sweep)
    assert len({(d.train, d.test, d.boot, d.n_cycles) for d in draws}) == len(draws)


def test_option_strings():
    have = [("O", 0.333333), ("O", 1.0), ("D+", 1.0)]
    assert select_conditions("O@1/3", have, "--x") == [("O", 0.333333)]
    assert select_conditions("@1", have, "--x") == [("O", 1.0), ("D+", 1.0)]
    assert select_conditions("D+, O", have, "--x") == [("O", 0.333333), ("O", 1.0), ("D+", 1.0)]
    with pytest.raises(CampaignError, match="S-@0.5"):
        select_conditions("S-@0.5", have, "--train-conditions")
    with pytest.raises(CampaignError, match="gait 'Q'"):
        select_conditions("Q@1", have, "train_conditions")
    assert parse_int_list("1-3,10", "sweep") == [1, 2, 3, 10]
    assert parse_int_list("paper", "sweep") == [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 21, 30, 39, 48]
    with pytest.raises(CampaignError, match="sweep"):
        parse_int_list("1,x", "sweep")
