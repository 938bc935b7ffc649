"""Bootstrap campaigns: the job grid, seeds from job keys, sampling, runner and resume.

`run_campaign(store, name, CampaignOptions(...))` creates or continues a campaign and
fills `results`; `campaign_status(store, name)` reports its progress (the small campaign of
`suds-exp demo` is `suds_exp.workflows.demo_campaign`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from suds_exp.lazy import exports

if TYPE_CHECKING:  # what the names are, for readers and static tools; loaded on first use
    from suds_exp.campaign.bank import SampleBank
    from suds_exp.campaign.conditions import PAPER_SWEEP, parse_int_list
    from suds_exp.campaign.definition import CampaignOptions
    from suds_exp.campaign.grid import KEY_COLUMNS, Draw, enumerate_draws
    from suds_exp.campaign.job import RESULT_COLUMNS, TIMING_COLUMNS
    from suds_exp.campaign.runner import RunSummary, run_campaign
    from suds_exp.campaign.status import campaign_status
    from suds_exp.errors import CampaignError

#: Where each public name lives. Loaded on first use (PEP 562), so `suds-exp status`
#: imports the status module, not the learners and scikit-learn behind a definition.
_HOMES = {
    "SampleBank": "suds_exp.campaign.bank",
    "PAPER_SWEEP": "suds_exp.campaign.conditions",
    "parse_int_list": "suds_exp.campaign.conditions",
    "CampaignOptions": "suds_exp.campaign.definition",
    "KEY_COLUMNS": "suds_exp.campaign.grid",
    "Draw": "suds_exp.campaign.grid",
    "enumerate_draws": "suds_exp.campaign.grid",
    "RESULT_COLUMNS": "suds_exp.campaign.job",
    "TIMING_COLUMNS": "suds_exp.campaign.job",
    "RunSummary": "suds_exp.campaign.runner",
    "run_campaign": "suds_exp.campaign.runner",
    "campaign_status": "suds_exp.campaign.status",
    "CampaignError": "suds_exp.errors",
}


__all__ = [
    "KEY_COLUMNS",
    "PAPER_SWEEP",
    "RESULT_COLUMNS",
    "TIMING_COLUMNS",
    "CampaignError",
    "CampaignOptions",
    "Draw",
    "RunSummary",
    "SampleBank",
    "campaign_status",
    "enumerate_draws",
    "parse_int_list",
    "run_campaign",
]

__getattr__, __dir__ = exports(__name__, _HOMES, __all__)
