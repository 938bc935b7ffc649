"""The campaign box's user error."""

from suds_exp.errors import SudsError


class CampaignError(SudsError):
    """A campaign cannot be created, continued or run as asked."""
