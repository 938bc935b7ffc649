"""Bootstrap campaigns: the job grid, seeds from job keys, sampling, runner and resume.

`run_campaign(store, name, CampaignOptions(...))` creates or continues a campaign and
fills `results`; `campaign_status(store, name)` reports its progress (the small campaign of
`suds-exp demo` is `suds_exp.testing.demo_campaign`).
"""

from suds_exp.campaign.bank import SampleBank
from suds_exp.campaign.conditions import PAPER_SWEEP, parse_int_list
from suds_exp.campaign.definition import CampaignOptions
from suds_exp.campaign.grid import KEY_COLUMNS, Draw, enumerate_draws
from suds_exp.campaign.job import RESULT_COLUMNS, TIMING_COLUMNS
from suds_exp.campaign.runner import RunSummary, run_campaign
from suds_exp.campaign.status import campaign_status
from suds_exp.errors import CampaignError

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
