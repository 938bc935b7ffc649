"""The small campaign of `suds-exp demo`: all five learners on a few conditions."""

from __future__ import annotations

import pandas as pd

from suds_exp.campaign.bank import SampleBank, rounded_conditions
from suds_exp.campaign.conditions import GAITS, format_condition
from suds_exp.campaign.definition import CampaignOptions
from suds_exp.campaign.runner import RunSummary, run_campaign
from suds_exp.errors import CampaignError
from suds_exp.models.registry import LEARNERS
from suds_exp.store import Store

#: Gaits the demo prefers, in order: with them the pairs cover every gait similarity
#: (same, near = one step on S+ S- O D- D+, far = more).
DEMO_GAITS = ("O", "D-", "D+")


def demo_options(samples: pd.DataFrame, prep: str | None = None, n_conditions: int = 6):
    """Options of the demo campaign for these samples.

    Up to ``n_conditions`` conditions: the preferred gaits at the slowest and fastest
    frequency present; 2 bootstrap draws; 5 training cycles (fewer when the trials are
    short) and a 1-2 cycle sample-efficiency sweep; all five learners.
    """
    have = rounded_conditions(samples)
    if not have:
        raise CampaignError("demo: no samples with a (gait, frequency) condition")
    freqs = sorted({f for _, f in have})
    ends = [freqs[0], freqs[-1]] if len(freqs) > 1 else freqs
    gaits = [g for g in (*DEMO_GAITS, *GAITS) if any(c[0] == g for c in have)]
    candidates = [(g, f) for g in dict.fromkeys(gaits) for f in ends if (g, f) in have]
    bank = SampleBank.build(samples, candidates)
    chosen = [c for c in candidates if len(bank.trials_of(c)) >= 2][:n_conditions]
    if not chosen:
        raise CampaignError("demo: no condition has two trials with complete cycles")
    room = min(
        sum(bank.n_cycles(i) for i in bank.trials_of(c))
        - max(bank.n_cycles(i) for i in bank.trials_of(c))
        for c in chosen
    )
    cycles = min(5, room)
    spec = ",".join(format_condition(c) for c in chosen)
    return CampaignOptions(
        prep=prep,
        models=list(LEARNERS),
        boots=2,
        train_cycles=cycles,
        sweep=[n for n in (1, 2) if n < cycles],
        train_conditions=spec,
        test_conditions=spec,
        mode="measured",
    )


def demo_campaign(
    store: Store,
    name: str = "demo",
    prep: str | None = None,
    jobs: int = 2,
    progress: bool = True,
) -> RunSummary:
    """Run (or finish) the demo campaign on preprocessing version ``prep`` (None: the
    only one); about 480 jobs, a minute or two on 2 cores. Returns the `RunSummary`."""
    from suds_exp.preprocess import get_version

    version = get_version(store, prep)
    prep, samples = version.name, version.samples()
    options = demo_options(samples, prep)
    return run_campaign(store, name, options, samples=samples, jobs=jobs, progress=progress)
